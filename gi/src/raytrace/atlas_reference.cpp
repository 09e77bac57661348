#include "raytrace/atlas_reference.h"

#include <span>

#include "uv/atlas_dilation.h"

namespace gi {

engine::Result<AtlasIrradiance> reference_atlas_irradiance(const engine::Scene& scene, const AtlasTexels& texels,
                                                           const ReferenceSettings& settings) {
  std::vector<SurfacePoint> points;
  std::vector<std::size_t> texel_of_point;
  for (std::size_t i = 0; i < texels.valid.size(); ++i) {
    if (!texels.valid[i]) continue;
    points.push_back({texels.position[i], texels.normal[i]});
    texel_of_point.push_back(i);
  }
  auto e = reference_irradiance(scene, points, settings);
  if (!e) return e.error();

  AtlasIrradiance out;
  out.width = texels.width;
  out.height = texels.height;
  out.valid = texels.valid;
  out.direct.assign(texels.valid.size(), glm::vec3(0.0f));
  out.indirect.assign(texels.valid.size(), glm::vec3(0.0f));
  for (std::size_t k = 0; k < points.size(); ++k) {
    out.direct[texel_of_point[k]] = e->direct[k];
    out.indirect[texel_of_point[k]] = e->indirect[k];
  }
  // Enough rings to cover any padding the layout may use.
  constexpr int kDilationRings = 4;
  dilate<glm::vec3>(out.direct, out.width, out.height, out.valid, kDilationRings);
  dilate<glm::vec3>(out.indirect, out.width, out.height, out.valid, kDilationRings);
  out.total.resize(out.direct.size());
  for (std::size_t i = 0; i < out.total.size(); ++i) out.total[i] = out.direct[i] + out.indirect[i];
  return out;
}

}  // namespace gi
