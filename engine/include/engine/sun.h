#pragma once
// The sun of the "gi" scene extras (docs/scene-format.md) as the engine holds it: an
// ordinary directional light named "sun" on a root node of its own, which the renderer, the
// bakers and the path tracer all see, plus its record in SceneAsset::environment. The glTF
// loader makes it from `gi.sun`; tools and tests that light a scene in memory make it here.
//   engine::set_sun(asset, {.direction = {0.3f, -1.0f, 0.2f}, .irradiance = glm::vec3(700.0f)});
//   engine::Scene scene = engine::instantiate(std::move(asset));

#include <engine/scene_asset.h>

#include <glm/glm.hpp>

namespace engine {

/// A sun: light from a distant disc.
struct Sun {
  glm::vec3 direction{0.0f, -1.0f,
                      0.0f};   ///< The way the light travels (from the sun into the scene), world space; not zero.
  glm::vec3 irradiance{0.0f};  ///< W/m^2 per channel on a surface facing the sun; >= 0.
  float angular_radius_rad = 0.0047f;  ///< Radius of its disc (0.27 degrees; 0: a single direction), in [0, pi/4].
};

/// Makes `sun` the scene's sun. The light is Directional with intensity = the largest
/// component of the irradiance and colour = irradiance / intensity (white when dark), its
/// node turns local -Z onto the direction. A scene that has a sun (environment.sun_light and
/// sun_node valid) gets it replaced in place; otherwise the light and its node are appended
/// (after every node: a root) and the environment records them. Preconditions (GI_EXPECTS):
/// a finite, non-zero direction; finite irradiance >= 0; the radius in [0, pi/4].
void set_sun(SceneAsset& scene, const Sun& sun);

}  // namespace engine
