#include <gi/bake_input.h>
#include <gi/light_atlas_uv.h>

#include "uv/atlas_density.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_scene_writer.h"

namespace gi {

engine::Result<LightAtlasUv> with_light_atlas_uv1(const engine::SceneAsset& scene, const LightAtlasUvOptions& options) {
  // The density bake_bundle gives the shared atlas / PRM / DLM layout.
  float density = options.texels_per_metre;
  if (density <= 0.0f) {
    auto preset = atlas_density_preset(options.preset);
    if (!preset) return preset.error();
    density = *preset;
  }
  auto layout = static_world_layout(bake_input_from(scene), density);
  if (!layout) return layout.error();
  auto with_uv1 = with_atlas_uv1(scene, *layout);
  if (!with_uv1) return with_uv1.error();
  return LightAtlasUv{.scene = std::move(with_uv1).value(),
                      .width = layout->width,
                      .height = layout->height,
                      .texels_per_metre = layout->texels_per_metre,
                      .charts = layout->charts.size()};
}

}  // namespace gi
