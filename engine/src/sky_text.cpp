// The sky's command-line form (engine/sky.h).
#include <engine/sky.h>

#include <cmath>
#include <cstdlib>
#include <string>

namespace engine {

namespace {

// "R,G,B": three finite radiances >= 0.
std::optional<glm::vec3> parse_rgb(std::string_view text) {
  glm::vec3 out(0.0f);
  for (int i = 0; i < 3; ++i) {
    const std::size_t comma = text.find(',');
    if ((i < 2) != (comma != std::string_view::npos)) return std::nullopt;
    const std::string item(text.substr(0, comma));
    char* end = nullptr;
    out[i] = std::strtof(item.c_str(), &end);
    if (item.empty() || end != item.c_str() + item.size() || !std::isfinite(out[i]) || out[i] < 0.0f)
      return std::nullopt;
    text = i < 2 ? text.substr(comma + 1) : std::string_view();
  }
  return out;
}

}  // namespace

std::optional<SkyText> parse_sky_text(std::string_view text) {
  SkyText sky;
  if (text.find(':') == std::string_view::npos) {
    const std::optional<glm::vec3> uniform = parse_rgb(text);
    if (!uniform) return std::nullopt;
    sky.uniform = *uniform;
    return sky;
  }
  bool seen[3] = {false, false, false};
  while (true) {
    const std::size_t semicolon = text.find(';');
    const std::string_view item = text.substr(0, semicolon);
    const std::size_t colon = item.find(':');
    if (colon == std::string_view::npos) return std::nullopt;
    const std::string_view key = item.substr(0, colon);
    const int k = key == "zenith" ? 0 : key == "horizon" ? 1 : key == "ground" ? 2 : -1;
    const std::optional<glm::vec3> value = parse_rgb(item.substr(colon + 1));
    if (k < 0 || !value || seen[k]) return std::nullopt;
    seen[k] = true;
    (k == 0 ? sky.gradient.zenith : k == 1 ? sky.gradient.horizon : sky.gradient.ground) = *value;
    if (semicolon == std::string_view::npos) break;
    text = text.substr(semicolon + 1);
  }
  if (!seen[0] || !seen[1] || !seen[2]) return std::nullopt;
  return sky;
}

}  // namespace engine
