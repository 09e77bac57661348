#pragma once
// PRM panes at a coarser density than the light atlas (issue 38): a field over one layout of
// the static world's charts (the panes' layout, `coarse`) read at every texel of another
// layout of the same charts (the light atlas's, `fine`). Indirect light from a moving light is
// low-frequency, so a pane needs far fewer texels than the atlas; what must not happen is
// light bleeding between surfaces, so each fine texel reads only its own chart's coarse
// texels: bilinear taps inside that chart's footprint that the pane holds, their weights
// renormalized (the nearest such texel when no tap is). Both layouts are cut into the same
// charts (charting does not depend on the density), so a chart's coarse coordinates are an
// affine map of its fine ones, solved from one of its triangles. The fine layout's gutter
// rings are read like the light atlas dilates them (each ring texel the mean of its filled
// 8-neighbours, atlas_dilation.h), so bilinear lookups at chart borders find pane light.
//   const auto up = gi::PaneUpsampler::build(prm.layout, prm.texels, atlas_layout, atlas_texels).value();
//   std::vector<glm::vec3> fine = up.apply(coarse_image);  // coarse_image: prm.width x prm.height

#include <engine/result.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi {

class PaneUpsampler {
 public:
  /// `coarse_filled`: the coarse texels that hold values (Prm::texels: covered texels and
  /// their dilation rings), ascending. `fine_texels`: the fine layout's rasterization (its
  /// valid texels and their charts). Errors: the layouts are not of the same charts.
  /// `gutter_rings`: fine gutter rings filled as gi::dilate fills them (0: valid texels only).
  static engine::Result<PaneUpsampler> build(const AtlasLayout& coarse, std::span<const std::uint32_t> coarse_filled,
                                             const AtlasLayout& fine, const AtlasTexels& fine_texels,
                                             int gutter_rings = 0);

  /// A fine image (fine width x height, 0 where no valid texel) from a coarse one (coarse
  /// width x height); empty when `coarse_image` is not of that size.
  std::vector<glm::vec3> apply(std::span<const glm::vec3> coarse_image) const;

  /// Fine texels whose chart had no filled coarse texel (they read 0): 0 for layouts of one
  /// static world.
  std::size_t orphans() const { return orphans_; }
  std::size_t fine_size() const { return fine_size_; }
  std::size_t coarse_size() const { return coarse_size_; }

  /// One coarse texel a fine texel reads, and its weight.
  struct Tap {
    std::uint32_t coarse = 0;  ///< Coarse texel index (y x width + x).
    float weight = 0.0f;
  };
  /// The fine texels written (valid texels ascending, then the gutter rings').
  std::span<const std::uint32_t> fine_texels() const { return fine_texel_; }
  /// fine_texels().size() + 1 entries: entry k's taps are taps()[tap_first()[k] .. tap_first()[k + 1]).
  std::span<const std::uint32_t> tap_first() const { return tap_first_; }
  std::span<const Tap> taps() const { return taps_; }

 private:
  void add_gutter_rings(int width, int height, int rings);

  std::size_t fine_size_ = 0, coarse_size_ = 0, orphans_ = 0;
  std::vector<std::uint32_t> fine_texel_;
  std::vector<std::uint32_t> tap_first_{0};
  std::vector<Tap> taps_;
};

}  // namespace gi
