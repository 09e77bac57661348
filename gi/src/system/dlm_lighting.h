#pragma once
// The runtime side of baked directional light maps (internal to GISystem): uploads the maps
// once, in the layout engine::IndirectLightFrame's directional_* fields describe (an R32I
// element index per atlas texel, RGB halves per (bin, element) with a per-bin scale, the
// directions), and fills those fields of the system's frame. The renderer then integrates the
// glTF specular lobe of glossy static texels against them (engine/directional_radiance.h).
//   auto dlm = gi::DlmLighting::from_bake(std::move(baked), atlas_width, atlas_height).value();
//   dlm->fill(frame);   // GL context current; uploads on the first call
// GL objects are deleted with the object: destroy it before the GL context.

#include <engine/gpu/gl_objects.h>
#include <engine/indirect_light.h>
#include <engine/result.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "dlm/dlm.h"

namespace gi {

class DlmLighting {
 public:
  /// Error when the maps' atlas size differs from the uv1 layout's (`width` x `height`: the
  /// light atlas's or the PRM's) the static meshes are drawn with.
  static engine::Result<std::unique_ptr<DlmLighting>> from_bake(Dlm dlm, int width, int height);

  /// Sets frame.directional_*; uploads on the first call.
  void fill(engine::IndirectLightFrame& frame);

  int directions() const { return bins_; }
  std::size_t texels() const { return elements_; }
  /// GPU bytes: radiance buffer + directions + index texture.
  std::size_t gpu_bytes() const;

 private:
  DlmLighting() = default;
  int width_ = 0, height_ = 0, bins_ = 0;
  std::size_t elements_ = 0;
  bool tangent_frame_ = false;         ///< DlmSettings::tangent_frame_bins: the bins turn with each texel's normal.
  std::vector<std::int32_t> index_;    ///< Released after the upload.
  std::vector<glm::uvec2> packed_;     ///< Released after the upload.
  std::vector<glm::vec4> directions_;  ///< Direction and scale per bin.
  engine::GlTexture index_texture_;
  engine::GlBuffer radiance_buffer_;
  engine::GlBuffer direction_buffer_;
};

}  // namespace gi
