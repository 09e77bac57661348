#include "light_atlas/texel_table.h"

#include <engine/gltf_brdf.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>
#include <utility>

#include "raytrace/material_lookup.h"

namespace gi {
namespace {

// Two surfaces facing each other closer than this (in texels) enclose a gap no light enters
// (a slab's underside 2 mm above the next one's top, in Dabrovic Sponza): a ray from one
// that lands on the other reads dark, not the texel there, whose sample lies in the open.
constexpr float kGapTexels = 0.05f;
// A texel's sample this far off its triangle's plane was moved by relocate_texel_samples (at
// least 0.01 texel off its surface): whether it sees a point where a ray lands on its texel
// is checked (Landing::unseen_corners).
constexpr float kOffPlaneTexels = 0.001f;

// TexelTable::moved: the samples relocate_texel_samples moved off their triangle's plane.
void mark_moved_samples(const StaticBakeScene& b, TexelTable& t) {
  const AtlasTexels& tx = b.texels;
  t.moved.assign(tx.valid.size(), 0);
  for (std::uint32_t i : t.work) {
    const std::uint32_t mesh = static_cast<std::uint32_t>(tx.mesh[i]);
    const ShadingTriangle& tri =
        b.index.triangles[b.index.instance_first[b.static_instance[mesh]] + static_cast<std::uint32_t>(tx.triangle[i])];
    t.moved[i] = std::fabs(glm::dot(tx.position[i] - tri.p0, tri.face_normal)) > t.plane_m ? 1 : 0;
  }
}

}  // namespace

engine::Result<TexelTable> texel_table(const StaticBakeScene& b, const AtlasLayout& layout) {
  // Long because it fills one table in one pass over the texels: the layout checks, the
  // per-texel albedo and face, then the gutter redirects that read what that pass wrote.
  const AtlasTexels& tx = b.texels;
  if (tx.width != layout.width || tx.height != layout.height || layout.meshes.size() != b.static_instance.size())
    return engine::Error{.message = "texel gather: the atlas layout does not match the bake scene"};
  for (std::size_t m = 0; m < layout.meshes.size(); ++m) {
    const auto [first, end] = instance_triangles(b.index, b.static_instance[m]);
    if (layout.meshes[m].indices.size() != 3u * (end - first))
      return engine::Error{.message = "texel gather: atlas mesh " + std::to_string(m) +
                                      " has another triangle count than its static instance"};
  }
  TexelTable t;
  t.width = tx.width;
  t.height = tx.height;
  t.gap_m = layout.texels_per_metre > 0.0f ? kGapTexels / layout.texels_per_metre : 0.0f;
  t.plane_m = layout.texels_per_metre > 0.0f ? kOffPlaneTexels / layout.texels_per_metre : 0.0f;
  t.near_m = layout.texels_per_metre > 0.0f ? 1.0f / layout.texels_per_metre : 0.0f;
  const std::size_t n = tx.valid.size();
  t.albedo.assign(n, glm::vec3(0.0f));
  t.face.assign(n, glm::vec3(0.0f));
  t.redirect.assign(n, kDark);
  std::unordered_map<std::uint32_t, glm::vec3> albedo_of;
  for (std::size_t i = 0; i < n; ++i) {
    if (!tx.valid[i]) continue;
    t.work.push_back(static_cast<std::uint32_t>(i));
    t.redirect[i] = static_cast<std::uint32_t>(i);
    const std::uint32_t mesh = static_cast<std::uint32_t>(tx.mesh[i]);
    const ShadingTriangle& tri =
        b.index.triangles[b.index.instance_first[b.static_instance[mesh]] + static_cast<std::uint32_t>(tx.triangle[i])];
    if (b.scene.materials[tri.material].textured()) {
      // The texture's mean over the texel's footprint (material_lookup.h), not one point.
      const TexelFootprint f = texel_footprint(layout, tx.mesh[i], tx.triangle[i], i);
      t.albedo[i] = footprint_albedo(b.scene, tri, f.centre, f.axis_u, f.axis_v);
      t.face[i] = glm::dot(tri.face_normal, tx.normal[i]) < 0.0f ? -tri.face_normal : tri.face_normal;
      continue;
    }
    auto it = albedo_of.find(tri.material);
    if (it == albedo_of.end())
      it =
          albedo_of.emplace(tri.material, engine::gltf_hemispherical_albedo(b.scene.materials[tri.material].brdf).sum())
              .first;
    t.albedo[i] = it->second;
    t.face[i] = glm::dot(tri.face_normal, tx.normal[i]) < 0.0f ? -tri.face_normal : tri.face_normal;
  }
  // Rays landing on an empty texel of a chart (its gutter, a sliver's corner) read the
  // nearest valid one, found ring by ring in a fixed neighbour order.
  for (int ring = 0; ring < std::max(3, layout.padding_texels); ++ring) {
    std::vector<std::pair<std::size_t, std::uint32_t>> found;
    for (int y = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x) {
        const std::size_t i = tx.index(x, y);
        if (t.redirect[i] != kDark) continue;
        for (int k = 0; k < 9; ++k) {
          const int nx = x + k % 3 - 1, ny = y + k / 3 - 1;
          if (nx < 0 || ny < 0 || nx >= t.width || ny >= t.height) continue;
          const std::uint32_t r = t.redirect[tx.index(nx, ny)];
          if (r == kDark) continue;
          found.emplace_back(i, r);
          break;
        }
      }
    if (found.empty()) break;
    for (const auto& [i, r] : found) t.redirect[i] = r;
  }
  mark_moved_samples(b, t);
  return t;
}

}  // namespace gi
