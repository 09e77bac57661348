// The emitter sampling of the final gather (texel_emitters.h) draws each texel as often as
// area_pdf says. Its first uniform picks the texel by inverting two CDFs (the receiver
// group's over the clusters, then the cluster's over its members), so with that uniform
// stratified over N draws, texel j comes up N P_j times give or take one, where
// P_j = area_pdf(group, j) x the area of j's atlas square on its triangle's plane: a draw that
// lands one member off its texel, or a texel of no power that is drawn, shows at once.
#include <gtest/gtest.h>
#include <gi/bake_input.h>

#include <cmath>
#include <cstdio>
#include <unordered_map>
#include <vector>

#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/texel_emitters.h"
#include "light_atlas/texel_table.h"
#include "light_atlas_scenes.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace {

// The world area of texel j's atlas square on the plane of its triangle (m^2).
double texel_area(const gi::StaticBakeScene& b, const gi::AtlasLayout& layout, std::uint32_t j) {
  const gi::AtlasTexels& tx = b.texels;
  const auto mesh = static_cast<std::size_t>(tx.mesh[j]);
  const auto tri = static_cast<std::uint32_t>(tx.triangle[j]);
  const gi::ShadingTriangle& st = b.index.triangles[b.index.instance_first[b.static_instance[mesh]] + tri];
  const gi::AtlasMeshUv& mu = layout.meshes[mesh];
  const glm::dvec2 a = mu.uv1[mu.indices[3 * tri]], u = glm::dvec2(mu.uv1[mu.indices[3 * tri + 1]]) - a,
                   v = glm::dvec2(mu.uv1[mu.indices[3 * tri + 2]]) - a;
  const double uv_area = std::fabs(u.x * v.y - u.y * v.x);
  const double world = glm::length(glm::cross(glm::dvec3(st.e1), glm::dvec3(st.e2)));
  return world / uv_area / (static_cast<double>(tx.width) * static_cast<double>(tx.height));
}

}  // namespace

TEST(TexelEmitters, StratifiedDrawsHitEveryTexelAsOftenAsItsAreaDensitySays) {
  const gi::BakeInput input = gi::bake_input_from(latest::closed_box(2.0f, 0.5f));
  auto layout = gi::static_world_layout(input, 8.0f);
  ASSERT_TRUE(layout);
  auto scene = gi::prepare_static_scene(input, *layout, gi::BakeLights::Static);
  ASSERT_TRUE(scene) << scene.error().to_string();
  auto table = gi::texel_table(*scene, *layout);
  ASSERT_TRUE(table);
  // Radiosity of five levels, every fifth texel dark: clusters of unequal members, and
  // members of no power the draw must step over.
  std::vector<glm::vec3> radiosity(scene->texels.valid.size(), glm::vec3(0.0f));
  for (std::uint32_t j : table->work) radiosity[j] = glm::vec3(j % 5 == 0 ? 0.0f : static_cast<float>(j % 7 + 1));
  gi::ThreadPool pool(2);
  const gi::TexelEmitters em(*scene, *layout, table->work, table->face, radiosity, 8.0f, pool);
  ASSERT_GT(em.cluster_count(), 6u);
  // A texel in the middle of the floor.
  std::uint32_t receiver = table->work.front();
  for (std::uint32_t j : table->work)
    if (table->face[j].y > 0.9f &&
        glm::length(glm::vec2(scene->texels.position[j].x, scene->texels.position[j].z)) <
            glm::length(glm::vec2(scene->texels.position[receiver].x, scene->texels.position[receiver].z)))
      receiver = j;
  const std::uint32_t group = em.group_of(receiver);
  constexpr int kDraws = 1 << 20;
  std::unordered_map<std::uint32_t, int> drawn;
  for (int k = 0; k < kDraws; ++k) {
    const gi::TexelEmitters::Sample s = em.sample(group, (static_cast<float>(k) + 0.5f) / kDraws, 0.5f, 0.5f);
    ASSERT_NE(s.texel, gi::TexelEmitters::Sample::kNone);
    ++drawn[s.texel];
  }
  double total = 0.0;
  int worst = 0, dark_drawn = 0;
  for (std::uint32_t j : table->work) {
    const double p = static_cast<double>(em.area_pdf(group, j)) * texel_area(*scene, *layout, j);
    total += p;
    const int n = drawn.count(j) ? drawn[j] : 0;
    worst = std::max(worst, static_cast<int>(std::lround(std::fabs(n - p * kDraws))));
    dark_drawn += j % 5 == 0 ? n : 0;
  }
  std::printf("clusters %zu, probabilities sum to %.6f, worst count off by %d of %d draws\n", em.cluster_count(), total,
              worst, kDraws);
  EXPECT_NEAR(total, 1.0, 1e-4);
  EXPECT_LE(worst, 2);  // float rounding of the CDFs moves a boundary by a draw at most
  EXPECT_EQ(dark_drawn, 0);
}
