#include "antiradiance/antiradiance_texel_blend.h"

#include <algorithm>
#include <array>
#include <limits>

#include "uv/atlas_dilation.h"
#include "uv/atlas_input.h"
#include "uv/atlas_rasterizer.h"

namespace gi {

namespace {

// The gutter: the light atlas's dilation (atlas_gutter_rings) fills the texels around each
// chart from their filled neighbours, and bilinear reads at chart borders see them. Each texel
// it fills takes the blend of the covered texel its value comes from (dilation_sources), so the
// change reaches the gutter too: without it the corridor's edges kept the open door's light in
// thin bright seams.
void extend_into_gutter(std::vector<AntiradianceTexelBlend>& blends, const std::vector<std::uint8_t>& valid,
                        const AtlasLayout& layout) {
  const int w = static_cast<int>(layout.width), hgt = static_cast<int>(layout.height);
  if (w <= 0 || hgt <= 0 || valid.size() != static_cast<std::size_t>(w) * static_cast<std::size_t>(hgt)) return;
  std::vector<std::int32_t> blend_of(valid.size(), -1);
  for (std::size_t k = 0; k < blends.size(); ++k) blend_of[blends[k].texel] = static_cast<std::int32_t>(k);
  const std::vector<std::int32_t> source = dilation_sources(w, hgt, valid, atlas_gutter_rings(layout.padding_texels));
  const std::size_t covered = blends.size();
  for (std::size_t t = 0; t < source.size(); ++t) {
    if (valid[t] || source[t] < 0) continue;
    const std::int32_t from = blend_of[static_cast<std::size_t>(source[t])];
    if (from < 0 || static_cast<std::size_t>(from) >= covered) continue;
    AntiradianceTexelBlend b = blends[static_cast<std::size_t>(from)];
    b.texel = static_cast<std::uint32_t>(t);
    blends.push_back(b);
  }
  std::sort(blends.begin(), blends.end(),
            [](const AntiradianceTexelBlend& a, const AntiradianceTexelBlend& b) { return a.texel < b.texel; });
}

}  // namespace

std::vector<AntiradianceTexelBlend> antiradiance_texel_blends(const ElementHierarchy& h, const BakeInput& input,
                                                              const AtlasLayout& layout) {
  const std::vector<AtlasInputMesh> inputs = atlas_inputs_from(input);
  const AtlasTexels texels = rasterize_atlas(layout, inputs);
  std::vector<std::int32_t> static_instance;  // atlas input mesh -> BakeInput instance
  for (std::size_t i = 0; i < input.instances.size(); ++i)
    if (input.instances[i].mobility == BakeMobility::Static) static_instance.push_back(static_cast<std::int32_t>(i));
  std::vector<std::vector<std::int32_t>> leaves_of(input.instances.size());
  for (std::size_t l = 0; l < h.leaf_count(); ++l) {
    const std::int32_t inst = h.node_instance[static_cast<std::size_t>(h.leaves[l])];
    if (inst >= 0 && static_cast<std::size_t>(inst) < leaves_of.size())
      leaves_of[static_cast<std::size_t>(inst)].push_back(static_cast<std::int32_t>(l));
  }
  std::vector<AntiradianceTexelBlend> out;
  for (std::size_t t = 0; t < texels.valid.size(); ++t) {
    if (texels.valid[t] == 0 || texels.mesh[t] < 0 ||
        static_cast<std::size_t>(texels.mesh[t]) >= static_instance.size())
      continue;
    const auto inst = static_cast<std::size_t>(static_instance[static_cast<std::size_t>(texels.mesh[t])]);
    const std::vector<std::int32_t>& candidates = leaves_of[inst];
    if (candidates.empty()) continue;
    std::array<std::pair<float, std::int32_t>, 4> best;
    best.fill({std::numeric_limits<float>::infinity(), -1});
    for (std::int32_t l : candidates) {
      const ElementNode& n = h.nodes[static_cast<std::size_t>(h.leaves[static_cast<std::size_t>(l)])];
      if (glm::dot(n.normal, texels.normal[t]) < 0.7f) continue;
      const glm::vec3 d = texels.position[t] - n.center;
      const float d2 = glm::dot(d, d);
      if (d2 >= best[3].first) continue;
      best[3] = {d2, l};
      std::sort(best.begin(), best.end());
    }
    if (best[0].second < 0) continue;
    AntiradianceTexelBlend b;
    b.texel = static_cast<std::uint32_t>(t);
    float total = 0.0f;
    for (int k = 0; k < 4; ++k) {
      if (best[static_cast<std::size_t>(k)].second < 0) continue;
      const ElementNode& n = h.nodes[static_cast<std::size_t>(
          h.leaves[static_cast<std::size_t>(best[static_cast<std::size_t>(k)].second)])];
      const float w = 1.0f / (best[static_cast<std::size_t>(k)].first + 0.25f * n.radius_m * n.radius_m);
      b.leaves[k] = best[static_cast<std::size_t>(k)].second;
      b.weights[k] = w;
      total += w;
    }
    b.weights /= total;
    out.push_back(b);
  }
  extend_into_gutter(out, texels.valid, layout);
  return out;
}

glm::vec3 composite_change(const glm::vec3& atlas, const glm::vec3& change, const glm::vec3& baseline, float share) {
  const float k = std::clamp(share, 0.0f, 1.0f);
  glm::vec3 out;
  for (int c = 0; c < 3; ++c) {
    const float added = std::max(atlas[c] + change[c], 0.0f);
    if (change[c] >= 0.0f || !(baseline[c] > 0.0f)) {
      out[c] = added;
      continue;
    }
    const float kept = atlas[c] * std::clamp(1.0f + change[c] / baseline[c], 0.0f, 1.0f);
    out[c] = (1.0f - k) * added + k * kept;
  }
  return out;
}

glm::vec3 blend_leaves(const AntiradianceTexelBlend& b, std::span<const glm::vec3> per_leaf) {
  glm::vec3 e(0.0f);
  for (int k = 0; k < 4; ++k) {
    const int l = b.leaves[k];
    if (l >= 0 && static_cast<std::size_t>(l) < per_leaf.size())
      e += b.weights[k] * per_leaf[static_cast<std::size_t>(l)];
  }
  return e;
}

namespace {

int heaviest(const AntiradianceTexelBlend& b) {
  int best = -1;
  for (int k = 0; k < 4; ++k)
    if (b.leaves[k] >= 0 && (best < 0 || b.weights[k] > b.weights[best])) best = k;
  return best < 0 ? -1 : b.leaves[best];
}

bool used(const AntiradianceTexelBlend& b, std::span<const glm::vec3> per_texel, std::span<const std::uint8_t> use) {
  return b.texel < per_texel.size() && b.texel < use.size() && use[b.texel] != 0;
}

}  // namespace

std::vector<glm::vec3> project_through_leaves(std::span<const AntiradianceTexelBlend> blends,
                                              std::span<const glm::vec3> per_texel, std::span<const std::uint8_t> use,
                                              std::size_t leaf_count) {
  std::vector<glm::dvec3> sum(leaf_count, glm::dvec3(0.0));
  std::vector<double> count(leaf_count, 0.0);
  for (const AntiradianceTexelBlend& b : blends) {
    const int l = heaviest(b);
    if (l < 0 || static_cast<std::size_t>(l) >= leaf_count || !used(b, per_texel, use)) continue;
    sum[static_cast<std::size_t>(l)] += glm::dvec3(per_texel[b.texel]);
    count[static_cast<std::size_t>(l)] += 1.0;
  }
  std::vector<glm::vec3> out(per_texel.size(), glm::vec3(0.0f));
  for (const AntiradianceTexelBlend& b : blends) {
    if (!used(b, per_texel, use)) continue;
    glm::dvec3 e(0.0);
    double w = 0.0;
    for (int k = 0; k < 4; ++k) {
      const int l = b.leaves[k];
      if (l < 0 || static_cast<std::size_t>(l) >= leaf_count || count[static_cast<std::size_t>(l)] == 0.0) continue;
      e += static_cast<double>(b.weights[k]) * sum[static_cast<std::size_t>(l)] / count[static_cast<std::size_t>(l)];
      w += static_cast<double>(b.weights[k]);
    }
    if (w > 0.0) out[b.texel] = glm::vec3(e / w);
  }
  return out;
}

}  // namespace gi
