#include "raytrace/texel_samples.h"

#include <cmath>
#include <memory>
#include <numbers>

#include "core/thread_pool.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/scene_adapter.h"
#include "uv/atlas_input.h"

namespace gi {
namespace {

constexpr int kDirections = 8;
// Rays leave the surface this much (tangent of the tilt): coplanar neighbours of the
// sample's own surface are not hit edge-on, a wall standing on it still is.
constexpr float kTilt = 0.02f;

void tangent_frame(glm::vec3 n, glm::vec3& t, glm::vec3& b) {
  const glm::vec3 a = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
  t = glm::normalize(glm::cross(a, n));
  b = glm::cross(n, t);
}

}  // namespace

RtSceneData static_instances(const RtSceneData& data, std::vector<std::uint32_t>* kept) {
  RtSceneData statics;
  statics.geometries = data.geometries;
  for (std::size_t i = 0; i < data.instances.size(); ++i) {
    if (data.instances[i].dynamic) continue;
    statics.instances.push_back(data.instances[i]);
    if (kept) kept->push_back(static_cast<std::uint32_t>(i));
  }
  return statics;
}

TexelRelocationStats relocate_texel_samples(AtlasTexels& texels, float texels_per_metre, const RayCaster& statics) {
  TexelRelocationStats stats;
  if (!(texels_per_metre > 0.0f)) return stats;
  const float reach = 1.0f / texels_per_metre;
  const float start = 1e-4f * reach;  // the sample's own triangle is not hit at t = 0
  const float push = 1e-2f * reach;   // how far in front of the back face the sample lands
  const std::size_t n = texels.valid.size();
  std::vector<std::uint8_t> moved(n, 0);
  ThreadPool pool;
  pool.parallel_for(
      n,
      [&](std::size_t i) {
        if (!texels.valid[i]) return;
        const glm::vec3 p = texels.position[i];
        const glm::vec3 nrm = texels.normal[i];
        if (!(glm::dot(nrm, nrm) > 0.5f)) return;
        glm::vec3 t, b;
        tangent_frame(nrm, t, b);
        Hit nearest;
        glm::vec3 nearest_dir(0.0f);
        for (int k = 0; k < kDirections; ++k) {
          const float phi = 2.0f * std::numbers::pi_v<float> * static_cast<float>(k) / kDirections;
          const glm::vec3 d = glm::normalize(std::cos(phi) * t + std::sin(phi) * b + kTilt * nrm);
          const Hit h = statics.intersect({.origin = p, .t_min = start, .direction = d, .t_max = reach});
          if (!h.valid() || !(glm::dot(d, h.geometric_normal) > 0.0f)) continue;  // none, or a front face
          if (h.t < nearest.t) nearest = h, nearest_dir = d;
        }
        if (!nearest.valid()) return;
        const glm::vec3 face = glm::normalize(nearest.geometric_normal);
        texels.position[i] = p + nearest.t * nearest_dir + push * face;
        moved[i] = 1;
      },
      64);
  for (std::size_t i = 0; i < n; ++i) {
    stats.checked += texels.valid[i];
    stats.moved += moved[i];
  }
  return stats;
}

engine::Result<AtlasTexels> sample_atlas_texels(const BakeInput& input, const AtlasLayout& layout,
                                                TexelPlacement placement, const RayCaster* statics,
                                                TexelRelocationStats* stats) {
  if (placement == TexelPlacement::Raster) return rasterize_atlas(layout, atlas_inputs_from(input));
  AtlasTexels texels = rasterize_atlas(layout, atlas_inputs_from(input), kVisibleSurfaceInsetTexels);
  std::unique_ptr<RayCaster> own;
  if (statics == nullptr) {
    const RtSceneData data = static_instances(rt_scene_from(input));
    if (data.instances.empty()) return texels;  // nothing to be inside of
    auto caster = make_embree_ray_caster(data);
    if (!caster) return caster.error();
    own = std::move(caster).value();
    statics = own.get();
  }
  const TexelRelocationStats s = relocate_texel_samples(texels, layout.texels_per_metre, *statics);
  if (stats) *stats = s;
  return texels;
}

}  // namespace gi
