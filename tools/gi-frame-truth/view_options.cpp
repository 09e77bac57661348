#include "view_options.h"

#include <cmath>
#include <cstdlib>
#include <numbers>
#include <sstream>

namespace frame_truth_tool {

std::optional<std::vector<float>> parse_numbers(const std::string& text) {
  std::vector<float> out;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) {
    char* end = nullptr;
    const float v = std::strtof(item.c_str(), &end);
    if (item.empty() || end == item.c_str() || *end != '\0' || !std::isfinite(v)) return std::nullopt;
    out.push_back(v);
  }
  if (!text.empty() && text.back() == ',') return std::nullopt;
  return out;
}

std::optional<gi::FrameCamera> parse_camera(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0) return std::nullopt;
  const auto v = parse_numbers(text.substr(eq + 1));
  if (!v || (v->size() != 6 && v->size() != 7)) return std::nullopt;
  gi::FrameCamera c;
  c.name = text.substr(0, eq);
  c.position_m = {(*v)[0], (*v)[1], (*v)[2]};
  c.target_m = {(*v)[3], (*v)[4], (*v)[5]};
  const float fov_deg = v->size() == 7 ? (*v)[6] : 60.0f;
  if (!(fov_deg > 1.0f && fov_deg < 170.0f) || !(glm::length(c.target_m - c.position_m) > 1e-3f)) return std::nullopt;
  c.yfov_rad = fov_deg * std::numbers::pi_v<float> / 180.0f;
  return c;
}

std::optional<gi::WorldRegion> parse_region(const std::string& text) {
  const std::size_t colon = text.find(':');
  if (colon == std::string::npos || colon == 0) return std::nullopt;
  const auto v = parse_numbers(text.substr(colon + 1));
  if (!v || v->size() != 6) return std::nullopt;
  gi::WorldRegion r{
      .name = text.substr(0, colon), .min_m = {(*v)[0], (*v)[1], (*v)[2]}, .max_m = {(*v)[3], (*v)[4], (*v)[5]}};
  if (glm::any(glm::greaterThan(r.min_m, r.max_m)) || r.name == "other" || r.name == "frame") return std::nullopt;
  return r;
}

}  // namespace frame_truth_tool
