#include "raytrace/atlas_reference.h"

#include <span>

#include "raytrace/texel_samples.h"
#include "uv/atlas_dilation.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace gi {

engine::Result<AtlasIrradiance> reference_atlas_irradiance(const BakeInput& input, const AtlasTexels& texels,
                                                           const ReferenceSettings& settings) {
  std::vector<SurfacePoint> points;
  std::vector<std::size_t> texel_of_point;
  for (std::size_t i = 0; i < texels.valid.size(); ++i) {
    if (!texels.valid[i]) continue;
    points.push_back({texels.position[i], texels.normal[i]});
    texel_of_point.push_back(i);
  }
  auto e = reference_irradiance(input, points, settings);
  if (!e) return e.error();

  AtlasIrradiance out;
  out.width = texels.width;
  out.height = texels.height;
  out.valid = texels.valid;
  out.direct.assign(texels.valid.size(), glm::vec3(0.0f));
  out.indirect.assign(texels.valid.size(), glm::vec3(0.0f));
  out.indirect_variance.assign(texels.valid.size(), glm::vec3(0.0f));
  for (std::size_t k = 0; k < points.size(); ++k) {
    out.direct[texel_of_point[k]] = e->direct[k];
    out.indirect[texel_of_point[k]] = e->indirect[k];
    out.indirect_variance[texel_of_point[k]] = e->indirect_variance[k];
  }
  // Enough rings to cover any padding the layout may use.
  constexpr int kDilationRings = 4;
  dilate<glm::vec3>(out.direct, out.width, out.height, out.valid, kDilationRings);
  dilate<glm::vec3>(out.indirect, out.width, out.height, out.valid, kDilationRings);
  out.total.resize(out.direct.size());
  for (std::size_t i = 0; i < out.total.size(); ++i) out.total[i] = out.direct[i] + out.indirect[i];
  return out;
}

engine::Result<AtlasReference> reference_atlas(const BakeInput& input, float texels_per_metre,
                                               const ReferenceSettings& settings, TexelPlacement placement) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  auto layout = static_world_layout(input, texels_per_metre);
  if (!layout) return layout.error();
  auto texels = sample_atlas_texels(input, *layout, placement);
  if (!texels) return texels.error();
  auto truth = reference_atlas_irradiance(input, *texels, settings);
  if (!truth) return truth.error();
  return AtlasReference{.width = truth->width,
                        .height = truth->height,
                        .texels_per_metre = layout->texels_per_metre,
                        .direct = std::move(truth->direct),
                        .indirect = std::move(truth->indirect),
                        .total = std::move(truth->total),
                        .valid = std::move(truth->valid),
                        .indirect_variance = std::move(truth->indirect_variance)};
}

}  // namespace gi
