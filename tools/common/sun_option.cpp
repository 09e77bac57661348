#include "sun_option.h"

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>
#include <vector>

namespace tools {
namespace {

std::optional<std::vector<float>> numbers(const std::string& text) {
  std::vector<float> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const float v = std::strtof(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v)) return std::nullopt;
    out.push_back(v);
  }
  if (text.empty() || text.back() == ',') return std::nullopt;
  return out;
}

}  // namespace

std::optional<engine::Sun> parse_sun(const std::string& text) {
  engine::Sun sun;
  sun.angular_radius_rad = 0.27f * std::numbers::pi_v<float> / 180.0f;
  bool seen[3] = {false, false, false};
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ';');) {
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) return std::nullopt;
    const std::string key = item.substr(0, colon);
    const auto v = numbers(item.substr(colon + 1));
    const int k = key == "direction" ? 0 : key == "irradiance" ? 1 : key == "angular_radius_deg" ? 2 : -1;
    if (k < 0 || !v || seen[k] || v->size() != (k == 2 ? 1u : 3u)) return std::nullopt;
    seen[k] = true;
    if (k == 0) sun.direction = {(*v)[0], (*v)[1], (*v)[2]};
    if (k == 1) sun.irradiance = {(*v)[0], (*v)[1], (*v)[2]};
    if (k == 2) sun.angular_radius_rad = (*v)[0] * std::numbers::pi_v<float> / 180.0f;
  }
  if (!seen[0] || !seen[1]) return std::nullopt;
  if (!(glm::length(sun.direction) > 1e-6f) || glm::any(glm::lessThan(sun.irradiance, glm::vec3(0.0f))))
    return std::nullopt;
  if (!(sun.angular_radius_rad >= 0.0f && sun.angular_radius_rad <= 0.25f * std::numbers::pi_v<float>))
    return std::nullopt;
  return sun;
}

bool set_sun(engine::SceneAsset& scene, const std::string& text) {
  const std::optional<engine::Sun> sun = parse_sun(text);
  if (!sun) return false;
  engine::set_sun(scene, *sun);
  return true;
}

}  // namespace tools
