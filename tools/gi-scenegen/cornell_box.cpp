// The measured Cornell box (Cornell Program of Computer Graphics data, millimetres, as in
// ../shared/external-assets/README.md), converted to metres. Every listed vertex is used
// as given; the blocks are closed prisms standing on the floor.
#include <glm/gtc/constants.hpp>

#include "scene_builder.h"
#include "scenes.h"

namespace scenegen {
namespace {
// Millimetres to metres, rounded once (0.278 stays 0.278f, not 278 * 0.001f).
float m(double millimetres) { return static_cast<float>(millimetres / 1000.0); }
glm::vec3 mm(double x, double y, double z) { return {m(x), m(y), m(z)}; }
}  // namespace

engine::SceneAsset cornell_box() {
  SceneBuilder b;
  const int white = b.material("cbox_white", {0.886f, 0.699f, 0.666f});
  const int red = b.material("cbox_red", {0.570f, 0.043f, 0.044f});
  const int green = b.material("cbox_green", {0.105f, 0.378f, 0.076f});
  const glm::vec3 radiance(18.387f, 10.987f, 2.754f);
  const int lamp = b.material("cbox_light", {0.78f, 0.78f, 0.78f}, 1.0f, 0.0f, radiance);

  const glm::vec3 inside = mm(278.0, 274.4, 279.6);  // facing hint: towards the box centre
  MeshBuilder walls;
  auto wall = [&](int m, glm::vec3 a, glm::vec3 bb, glm::vec3 c, glm::vec3 d) {
    walls.quad(m, a, bb, c, d, inside - 0.25f * (a + bb + c + d));
  };
  wall(white, mm(552.8, 0, 0), mm(0, 0, 0), mm(0, 0, 559.2), mm(549.6, 0, 559.2));                // floor
  wall(white, mm(556, 548.8, 0), mm(556, 548.8, 559.2), mm(0, 548.8, 559.2), mm(0, 548.8, 0));    // ceiling
  wall(white, mm(549.6, 0, 559.2), mm(0, 0, 559.2), mm(0, 548.8, 559.2), mm(556, 548.8, 559.2));  // back
  wall(green, mm(0, 0, 559.2), mm(0, 0, 0), mm(0, 548.8, 0), mm(0, 548.8, 559.2));                // left
  wall(red, mm(552.8, 0, 0), mm(549.6, 0, 559.2), mm(556, 548.8, 559.2), mm(556, 548.8, 0));      // right
  b.add_mesh_node("walls", walls, engine::Mobility::Static);

  MeshBuilder short_block;
  const glm::vec3 short_top[4] = {mm(130, 165, 65), mm(82, 165, 225), mm(240, 165, 272), mm(290, 165, 114)};
  short_block.prism(white, short_top, 0.0f);
  b.add_mesh_node("short_block", short_block, engine::Mobility::Static);

  MeshBuilder tall_block;
  const glm::vec3 tall_top[4] = {mm(423, 330, 247), mm(265, 330, 296), mm(314, 330, 456), mm(472, 330, 406)};
  tall_block.prism(white, tall_top, 0.0f);
  b.add_mesh_node("tall_block", tall_block, engine::Mobility::Static);

  // The light: 130 x 105 mm centred at (278, 548.8, 279.5) mm, emitting downwards. The
  // emissive quad sits 0.1 mm below the ceiling so path tracers can hit it.
  const float y_quad = m(548.8 - 0.1);
  MeshBuilder light_quad;
  light_quad.quad(lamp, {m(343), y_quad, m(227)}, {m(343), y_quad, m(332)}, {m(213), y_quad, m(332)},
                  {m(213), y_quad, m(227)}, glm::vec3(0, -1, 0));
  b.add_mesh_node("light_quad", light_quad, engine::Mobility::Static);
  b.add_light_node("light", area_light({0.130f, 0.105f}, radiance), mm(278.0, 548.8, 279.5),
                   facing({0, -1, 0}, {1, 0, 0}));

  b.add_camera_node("camera", mm(278, 273, -800), mm(278, 273, 0), glm::radians(39.3077f));
  return b.take();
}

}  // namespace scenegen
