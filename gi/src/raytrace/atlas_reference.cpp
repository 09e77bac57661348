#include "raytrace/atlas_reference.h"

#include <cmath>
#include <span>

#include "raytrace/texel_samples.h"
#include "uv/atlas_dilation.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace gi {

namespace {

// The unit geometric normal of texel i's triangle on its shading normal's side; zero when
// the triangle is not among `inputs` or is degenerate.
glm::vec3 texel_face(const std::vector<AtlasInputMesh>& inputs, const AtlasTexels& texels, std::size_t i) {
  const auto mesh = static_cast<std::size_t>(texels.mesh[i]), tri = static_cast<std::size_t>(texels.triangle[i]);
  if (texels.mesh[i] < 0 || texels.triangle[i] < 0 || mesh >= inputs.size() ||
      3 * tri + 2 >= inputs[mesh].indices.size())
    return glm::vec3(0.0f);
  const AtlasInputMesh& m = inputs[mesh];
  const glm::vec3 p0 = m.positions[m.indices[3 * tri]], p1 = m.positions[m.indices[3 * tri + 1]],
                  p2 = m.positions[m.indices[3 * tri + 2]];
  const glm::vec3 c = glm::cross(p1 - p0, p2 - p0);
  const float len = glm::length(c);
  if (!(len > 0.0f) || !std::isfinite(len)) return glm::vec3(0.0f);
  return glm::dot(c, texels.normal[i]) < 0.0f ? -c / len : c / len;
}

}  // namespace

std::vector<SurfacePoint> atlas_sample_points(const BakeInput& input, const AtlasTexels& texels) {
  const std::vector<AtlasInputMesh> inputs = atlas_inputs_from(input);
  std::vector<SurfacePoint> points;
  for (std::size_t i = 0; i < texels.valid.size(); ++i)
    if (texels.valid[i]) points.push_back({texels.position[i], texels.normal[i], texel_face(inputs, texels, i)});
  return points;
}

AtlasIrradiance assemble_atlas_irradiance(const AtlasTexels& texels, const IrradianceEstimate& e) {
  AtlasIrradiance out;
  out.width = texels.width;
  out.height = texels.height;
  out.valid = texels.valid;
  out.direct.assign(texels.valid.size(), glm::vec3(0.0f));
  out.indirect.assign(texels.valid.size(), glm::vec3(0.0f));
  out.indirect_variance.assign(texels.valid.size(), glm::vec3(0.0f));
  std::size_t k = 0;
  for (std::size_t i = 0; i < texels.valid.size(); ++i) {
    if (!texels.valid[i]) continue;
    out.direct[i] = e.direct[k];
    out.indirect[i] = e.indirect[k];
    out.indirect_variance[i] = e.indirect_variance[k];
    ++k;
  }
  // Enough rings to cover any padding the layout may use.
  constexpr int kDilationRings = 4;
  dilate<glm::vec3>(out.direct, out.width, out.height, out.valid, kDilationRings);
  dilate<glm::vec3>(out.indirect, out.width, out.height, out.valid, kDilationRings);
  out.total.resize(out.direct.size());
  for (std::size_t i = 0; i < out.total.size(); ++i) out.total[i] = out.direct[i] + out.indirect[i];
  return out;
}

engine::Result<AtlasIrradiance> reference_atlas_irradiance(const BakeInput& input, const AtlasTexels& texels,
                                                           const ReferenceSettings& settings) {
  const std::vector<SurfacePoint> points = atlas_sample_points(input, texels);
  auto e = reference_irradiance(input, points, settings);
  if (!e) return e.error();
  return assemble_atlas_irradiance(texels, *e);
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
