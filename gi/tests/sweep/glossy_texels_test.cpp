// The glossy texels the dlm and reflection probes sweeps compare (gi/src/sweep/glossy_texels.h).
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <filesystem>

#include "sweep/glossy_texels.h"
#include "sweep/sweep_scene.h"

namespace fs = std::filesystem;

namespace {

// The cause of the reflection probes' first border error (0.73 against the path tracer on the
// glossy room): the floor's border texels had their raster samples on the line where the
// walls begin, and the reference's lobe rays from there slipped behind the walls (a truth of
// 0 under a lit probe). Placed where a camera sees the floor, no sample lies on a wall.
TEST(GlossyTexels, VisibleSurfaceSamplesStayOffTheWalls) {
  auto scene = gi::load_sweep_scene(fs::path(GI_SOURCE_DIR) / "assets" / "glossy_room.gltf");
  ASSERT_TRUE(scene) << scene.error().to_string();
  const auto on_a_wall = [](const gi::GlossyTexels& g) {  // the room's walls: x = +-4 m, z = +-2.5 m
    int n = 0;
    for (std::size_t t = 0; t < g.glossy.size(); ++t) {
      const glm::vec3 p = g.s.texels.position[t];
      if (g.glossy[t] && (std::abs(std::abs(p.x) - 4.0f) < 1e-3f || std::abs(std::abs(p.z) - 2.5f) < 1e-3f)) ++n;
    }
    return n;
  };
  auto raster = gi::glossy_texels(*scene, 8.0, 0.2, nullptr, gi::TexelPlacement::Raster);
  auto visible = gi::glossy_texels(*scene, 8.0, 0.2, nullptr, gi::TexelPlacement::VisibleSurface);
  ASSERT_TRUE(raster && visible);
  EXPECT_GT(on_a_wall(*raster), 50);
  EXPECT_EQ(on_a_wall(*visible), 0);
}

}  // namespace
