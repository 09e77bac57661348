#include <engine/check.h>
#include <engine/sun.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/quaternion.hpp>

namespace engine {

void set_sun(SceneAsset& scene, const Sun& sun) {
  const glm::vec3 d = sun.direction;
  const glm::vec3 e = sun.irradiance;
  GI_EXPECTS(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z) && glm::length(d) > 1e-6f,
             "the sun's direction must be finite and not zero");
  GI_EXPECTS(
      std::isfinite(e.x) && std::isfinite(e.y) && std::isfinite(e.z) && e.x >= 0.0f && e.y >= 0.0f && e.z >= 0.0f,
      "the sun's irradiance must be finite and >= 0");
  GI_EXPECTS(sun.angular_radius_rad >= 0.0f && sun.angular_radius_rad <= 0.25f * std::numbers::pi_v<float>,
             "the sun's angular radius must lie in [0, pi/4]");
  // A directional light shines along its node's local -Z: rotate -Z onto the direction.
  const glm::vec3 to = glm::normalize(d);
  const glm::vec3 from(0.0f, 0.0f, -1.0f);
  const glm::quat q = glm::dot(from, to) < -0.999999f ? glm::angleAxis(std::numbers::pi_v<float>, glm::vec3(1, 0, 0))
                                                      : glm::rotation(from, to);
  NamedLight light;
  light.name = "sun";
  light.light.type = LightType::Directional;
  const float peak = std::max({e.x, e.y, e.z});
  light.light.intensity = peak;  // W/m^2 on a surface facing the sun
  light.light.color = peak > 0.0f ? e / peak : glm::vec3(1.0f);
  light.light.angular_radius_rad = sun.angular_radius_rad;  // the disc
  Node node;
  node.name = "sun";
  node.rotation = glm::normalize(q);

  Environment& env = scene.environment;
  const bool has_sun = env.sun_light >= 0 && env.sun_light < static_cast<int>(scene.lights.size()) &&
                       env.sun_node >= 0 && env.sun_node < static_cast<int>(scene.nodes.size());
  if (has_sun) {
    node.light = env.sun_light;
    scene.lights[static_cast<std::size_t>(env.sun_light)] = std::move(light);
    scene.nodes[static_cast<std::size_t>(env.sun_node)] = std::move(node);
  } else {
    node.light = static_cast<int>(scene.lights.size());
    env.sun_light = node.light;
    env.sun_node = static_cast<int>(scene.nodes.size());
    scene.lights.push_back(std::move(light));
    scene.nodes.push_back(std::move(node));
  }
  env.sun_angular_radius_rad = sun.angular_radius_rad;
}

}  // namespace engine
