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
  /// `coarse_filled`: the coarse texels that hold values (Prm::texels: the covered texels and
  /// the dilated ones inside the charts' footprints), ascending. `fine_texels`: the fine
  /// layout's rasterization (its valid texels and their charts). Errors: the layouts are not of
  /// the same charts. `gutter_rings`: fine gutter rings filled as gi::dilate fills them (0:
  /// valid texels only).
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
  int fine_width() const { return fine_width_; }
  int coarse_width() const { return coarse_width_; }

  /// Weights are multiples of 1/kWeightSteps (16-bit on the GPU, the same values here).
  static constexpr float kWeightSteps = 65535.0f;
  /// A valid fine texel's read: the 2 x 2 coarse texels from (x, y) = origin, weights in the
  /// order (x, y), (x+1, y), (x, y+1), (x+1, y+1); 0 for a texel outside its chart's
  /// footprint or not filled. The nearest filled texel of the footprint when no tap is (weight
  /// 1 at the origin). 16 bytes on the GPU (docs/prm.md "What Sponza's medium PRM holds").
  struct Read {
    std::uint32_t fine = 0;  ///< Fine texel index (y x width + x).
    glm::ivec2 origin{0};    ///< Coarse texel coordinates (may be -1 at a border: those read 0).
    std::array<float, 4> weight{};
    bool operator==(const Read&) const = default;
  };
  /// A gutter-ring texel: the mean of its 8-neighbours filled before its ring (bit k of
  /// `neighbours`: (dx, dy) = kNeighbour[k]).
  struct RingTexel {
    std::uint32_t fine = 0;
    std::uint32_t neighbours = 0;
    bool operator==(const RingTexel&) const = default;
  };
  static constexpr std::array<glm::ivec2, 8> kNeighbour{
      glm::ivec2{-1, -1}, {0, -1}, {1, -1}, {-1, 0}, {1, 0}, {-1, 1}, {0, 1}, {1, 1}};
  std::span<const Read> reads() const { return reads_; }
  /// Ring r's texels are ring_texels()[ring_first()[r] .. ring_first()[r + 1]).
  std::span<const RingTexel> ring_texels() const { return ring_texels_; }
  std::span<const std::uint32_t> ring_first() const { return ring_first_; }
  /// Every fine texel written: the reads' texels, then the rings'.
  std::vector<std::uint32_t> fine_texels() const;
  /// Bytes the GPU pass uploads for this (16 per read, 8 per ring texel).
  std::size_t gpu_bytes() const { return reads_.size() * 16 + ring_texels_.size() * 8; }
  bool operator==(const PaneUpsampler&) const = default;

 private:
  void add_gutter_rings(int height, int rings);

  std::size_t fine_size_ = 0, coarse_size_ = 0, orphans_ = 0;
  int fine_width_ = 0, coarse_width_ = 0;
  std::vector<Read> reads_;
  std::vector<RingTexel> ring_texels_;
  std::vector<std::uint32_t> ring_first_{0};
};

}  // namespace gi
