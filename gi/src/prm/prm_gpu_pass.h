#pragma once
// The PRM runtime sum on the GPU (Szécsi et al. 2006, §5.2): the weighted sum of the
// selected clusters' panes, written into an RGBA32F irradiance atlas texture, the GPU twin
// of gi::sum_panes (prm_runtime.h). Panes are uploaded once, as half floats or RGB9E5
// (PrmPaneEncoding); a run uploads only the K weights and dispatches one compute pass
// (gi/shaders/prm_sum.comp.glsl). Panes coarser than the atlas (Prm::atlas) are summed into
// a texture of the pane layout, then a second pass (gi/shaders/prm_upsample.comp.glsl)
// applies the PaneUpsampler's taps (uploaded once, SSBOs) into the atlas texture.
//   auto pass = gi::PrmGpuPass::create(prm).value();            // a GL context is current
//   if (auto s = pass.run(gi::select_clusters(weights, 32)); !s) { /* s.error() */ }
//   // pass.texture(): irradiance (W/m^2) per atlas texel, 0 outside the panes' texels
//
// Precision (PrmPaneEncoding::SharedExponent: see there; its CPU twin sums decoded_panes()):
// half-float pane values are stored after a per-pane power-of-two scale
// (exact, folded into the weight), so each pane value carries a relative rounding error of
// at most 2^-11 (~4.9e-4) whatever its magnitude, down to 2^-29 of its pane's largest value
// (smaller values are absolute errors below 2^-40 of it). Sums, weights and the atlas are
// 32-bit floats: a texel's error is at most ~5e-4 x sum_k |weight_k| |pane_k| plus float
// rounding.
//
// GL state: create(), run(), set_base() and read_back() need the creating context current
// and change the bound program, texture units 0-3 (buffer textures), image units 0-2 and
// shader storage bindings 0-1.

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>
#include <engine/result.h>

#include "prm/prm.h"
#include "prm/prm_runtime.h"

namespace gi {

/// How PrmGpuPass holds the panes in GPU memory. Encoded at upload from the float panes (the
/// bundle's files are unchanged); both start from a per-pane power-of-two scale folded into
/// the weights. decoded_panes() gives the values the pass sums, for its CPU twin.
enum class PrmPaneEncoding : std::uint8_t {
  /// Three half floats per element (6 bytes): each value within 2^-11 (~4.9e-4) of itself.
  Half,
  /// RGB9E5 (4 bytes, a third fewer bytes to stream per light change): three 9-bit
  /// mantissas sharing the largest channel's exponent in one 32-bit word, decoded with
  /// integer ops. Each channel within 2^-9 x (1 + 2^-9) (~2e-3) of the element's largest
  /// channel (half a mantissa step; the largest has 256-511 steps). Pane values must not be
  /// negative.
  SharedExponent,
};

/// The panes as PrmGpuPass sums them under `encoding`: prm.panes (same blocks) encoded and
/// decoded, each pane through its power-of-two scale. gi::sum_panes over a Prm holding these
/// panes is the pass's CPU twin up to float summation order. Error: a non-finite value, or a
/// negative one under SharedExponent.
engine::Result<PrmPanes> decoded_panes(const Prm& prm, PrmPaneEncoding encoding);

struct PrmGpuPassOptions {
  /// Pane encoding in GPU memory (docs/prm.md "Pane encoding" measures both on the demo level).
  PrmPaneEncoding encoding = PrmPaneEncoding::Half;
  /// Largest pane buffer (bytes) read as one buffer texture; panes are split over several
  /// buffers (whole panes each) above it. 0: the driver's GL_MAX_TEXTURE_BUFFER_SIZE x 16
  /// bytes, at most 128 MiB. Tests set it small to exercise the split.
  std::size_t max_buffer_bytes = 0;
  /// Work groups along x before the grid wraps into y. 0: GL's minimum limit, 65535. Tests
  /// set it small to exercise the 2-D grid.
  std::uint32_t max_groups_x = 0;
};

/// Sums weighted PRM panes into an irradiance atlas texture on the GPU. Move-only; owns its
/// GL objects (moved-from: empty).
///   auto pass = gi::PrmGpuPass::create(prm).value();
///   pass.run(selected);   // then sample pass.texture() like a light atlas
class PrmGpuPass {
 public:
  /// Compiles the shader, uploads `prm`'s texels and all its panes and creates the
  /// RGBA32F output texture at the light atlas's size (prm.atlas_width() x atlas_height(),
  /// linear filtering, clamped, all zero); coarse panes add a texture of the pane layout
  /// and the upsampler's taps. Errors:
  /// inconsistent sizes, texels not ascending or outside the atlas, non-finite pane values,
  /// one pane or the texel list larger than the buffer limit, atlas above the texture limit,
  /// shader build failure.
  static engine::Result<PrmGpuPass> create(const Prm& prm, const PrmGpuPassOptions& options = {});

  PrmGpuPass() = default;
  PrmGpuPass(PrmGpuPass&&) noexcept = default;
  PrmGpuPass& operator=(PrmGpuPass&&) noexcept = default;
  PrmGpuPass(const PrmGpuPass&) = delete;
  PrmGpuPass& operator=(const PrmGpuPass&) = delete;
  ~PrmGpuPass() = default;

  /// Writes base + sum over `selected` of weight x pane into every pane texel (texels outside
  /// the panes keep 0); coarse panes: base + that sum upsampled, at every texel the
  /// upsampler lists (the atlas's valid texels and gutter rings). Overwrites the previous run. K = 0 writes the base
  /// (or 0). A cluster listed twice counts twice. Only the tiles the selected clusters store blocks on, and those of
  /// the previous run, are written (every tile after creation or set_base): the work follows the lit blocks. Ends with
  /// a memory barrier for texture fetches, image access and read-back. Errors: a cluster index >= cluster_count; more
  /// selected blocks than the weight buffer texture holds (the buffer limit / 16 bytes).
  engine::Status run(std::span<const ClusterWeight> selected);

  /// A base irradiance atlas (width x height texels, row-major) added at the pane texels by
  /// every later run (e.g. a static-light atlas); an empty span removes it. Error: wrong size.
  engine::Status set_base(std::span<const glm::vec3> base_atlas);

  /// The RGBA32F output atlas (GL name; owned by the pass). Alpha is 1 at pane texels.
  std::uint32_t texture() const { return output_.id(); }
  /// The output atlas read back (width x height, row-major): for tests and tools.
  std::vector<glm::vec3> read_back() const;
  /// GPU memory held: texel list, pane buffers, weights, output and base textures (bytes).
  std::size_t gpu_bytes() const;
  /// gpu_bytes() by part (bytes; docs/prm.md "What Sponza's medium PRM holds").
  struct Memory {
    std::size_t panes = 0;     ///< Pane buffers (encoded blocks, tiles padded to 8 slots).
    std::size_t texels = 0;    ///< The slots' texel coordinates (4 bytes per slot).
    std::size_t work = 0;      ///< The last run's weights and chunk list.
    std::size_t upsample = 0;  ///< Coarse panes: the upsampler's fine texels and taps.
    std::size_t coarse = 0;    ///< Coarse panes: the K-sum texture at the pane layout (RGBA32F).
    std::size_t output = 0;    ///< The output atlas (RGBA32F).
    std::size_t base = 0;      ///< The base atlas (RGBA32F), when set.
    std::size_t total() const { return panes + texels + work + upsample + coarse + output + base; }
  };
  Memory memory() const;

  int width() const { return width_; }
  int height() const { return height_; }
  /// Pane buffers the panes were split over (1 unless they exceed the buffer limit).
  std::size_t pane_buffer_count() const { return pane_buffers_.size(); }
  /// Bytes the panes occupy in GPU memory (all buffers, padding included).
  std::size_t pane_bytes() const;
  /// Blocks of eight pane slots the last run dispatched (over all its dispatches).
  std::size_t last_run_chunks() const { return last_chunks_; }
  /// True when the panes are coarser than the output atlas (a second, upsampling pass).
  bool upsamples() const { return upsample_count_ > 0; }

 private:
  /// Packs each pane's blocks into buffers of whole panes under `buffer_limit` bytes each,
  /// with their buffer textures and each block's location.
  void upload_panes(const Prm& prm, PrmPaneEncoding encoding, std::size_t buffer_limit);
  /// The texel coordinates tile by tile (padded to blocks of eight), the empty weight and
  /// chunk buffers.
  void upload_texels(const Prm& prm, std::size_t buffer_limit);
  /// The cleared, bilinear RGBA32F output texture (and the coarse sum's, coarse panes).
  void create_output();
  /// Coarse panes: the upsampler's texels and taps as SSBOs, and its program.
  engine::Status upload_upsampler(const PaneUpsampler& up, int coarse_width);
  /// Coarse panes: the upsampling dispatch from the coarse sum into the output.
  void run_upsample();
  /// One compute dispatch: the pane buffer it reads and its chunks.
  struct Dispatch {
    std::uint32_t buffer = 0, first_chunk = 0, chunk_count = 0;
  };
  /// The tiles this run writes, ascending (tile_mark_ holds their positions).
  std::vector<std::uint32_t> touched_tiles(std::span<const ClusterWeight> selected);
  /// Uploads the selected blocks' weights grouped per pane buffer and tile, and the chunks
  /// each dispatch sums.
  std::vector<Dispatch> upload_work(std::span<const ClusterWeight> selected);

  /// Where one cluster's pane lives: its buffer and its packing scale.
  struct PaneLocation {
    std::uint32_t buffer = 0;
    float inverse_scale = 1.0f;
  };
  struct Uniforms {
    int first_chunk = -1;
    int chunk_count = -1;
    int mode = -1;
  };

  engine::ShaderProgram program_;
  Uniforms uniforms_;
  engine::GlBuffer texels_;
  std::vector<engine::GlBuffer> pane_buffers_;
  std::vector<std::size_t> pane_buffer_bytes_;
  std::vector<engine::GlTexture> pane_textures_;  ///< Each pane buffer as an RGBA32UI buffer texture.
  std::vector<PaneLocation> panes_;
  std::vector<std::uint32_t> cluster_first_;  ///< PrmPanes::cluster_first.
  std::vector<std::uint32_t> blocks_;         ///< PrmPanes::blocks: the tile of each stored block.
  std::vector<std::uint32_t> block_offset_;   ///< First uvec4 of each stored block in its buffer.
  std::vector<std::uint32_t> tile_slot_;      ///< tiles+1: first slot of each tile (a multiple of 8).
  std::vector<std::int32_t> tile_mark_;       ///< Per tile: its position in a run's list, else -1.
  std::vector<std::uint32_t> last_tiles_;     ///< Tiles the previous run added light to.
  bool write_all_ = true;                     ///< The next run writes every tile (new base or output).
  std::size_t texel_slots_ = 0;
  std::size_t last_chunks_ = 0;
  engine::GlBuffer chunks_;
  engine::GlTexture chunks_texture_;  ///< chunks_ as an RGBA32UI buffer texture.
  std::size_t chunks_bytes_ = 0;
  engine::GlBuffer weights_;
  engine::GlTexture texels_texture_;   ///< texels_ as an RGBA32UI buffer texture.
  engine::GlTexture weights_texture_;  ///< weights_ as an RGBA32UI buffer texture.
  std::size_t max_weights_ = 0;        ///< Weights one run can upload (the buffer limit).
  std::size_t weights_bytes_ = 0;      ///< Size of the last weight upload.
  engine::GlTexture output_;
  engine::GlTexture base_;
  int width_ = 0;  ///< Of the output (the light atlas).
  int height_ = 0;
  int pane_width_ = 0;  ///< Of the pane layout (the sum pass's coordinates).
  int pane_height_ = 0;
  engine::GlTexture coarse_;  ///< Coarse panes: the K-sum at the pane layout (no base).
  engine::ShaderProgram upsample_program_;
  engine::GlBuffer upsample_reads_;  ///< Per read: fine texel, coarse origin, 4 16-bit weights.
  engine::GlBuffer upsample_rings_;  ///< Per ring texel: fine texel, neighbour mask.
  std::size_t upsample_bytes_ = 0;
  std::uint32_t upsample_count_ = 0;  ///< Fine texels written (0: dense panes, no upsampling).
  std::uint32_t upsample_reads_count_ = 0;
  std::vector<std::uint32_t> upsample_ring_first_;  ///< PaneUpsampler::ring_first.
  enum class UpsampleMode : std::uint32_t { Reads = 0, Ring = 1, Base = 2 };
  struct UpsampleUniforms {
    int first = -1, count = -1, mode = -1, reads = -1;
  };
  UpsampleUniforms upsample_uniforms_;
  std::uint32_t max_groups_x_ = 65535;
  float decode_scale_ = 1.0f;  ///< Folded into every weight: 2^-24 for RGB9E5 mantissas, 1 for halves.
};

}  // namespace gi
