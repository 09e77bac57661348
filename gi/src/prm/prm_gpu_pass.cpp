#include "prm/prm_gpu_pass.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include <glm/gtc/packing.hpp>

#include "gpu/gi_shaders.h"

namespace gi {

namespace {

constexpr const char* kWhere = "PRM GPU pass";
constexpr std::size_t kSsboLimitBytes = std::size_t{128} << 20;  // DESIGN.md §4 (llvmpipe): per buffer
constexpr std::uint32_t kGroupSize = 64;                         // local_size_x of prm_sum.comp.glsl
constexpr std::size_t kBlock = 8;  // elements an invocation sums (per pane three uvec4s of halves or two of RGB9E5)
constexpr std::uint32_t kMaxGroupsPerDimension = 65535;

/// The weight of one selected cluster as prm_sum.comp.glsl reads it (std430 PaneWeight).
struct GpuPaneWeight {
  float r = 0.0f, g = 0.0f, b = 0.0f;  // weight x the pane's inverse packing scale
  std::uint32_t pane_offset = 0;       // first uvec4 of the pane in its buffer
};
static_assert(sizeof(GpuPaneWeight) == 16, "must match PaneWeight in prm_sum.comp.glsl (std430)");

/// One block of eight pane slots to sum: its first slot / 8, its weights
/// weights[first .. first + count), and its index within its tile (the offset into each block).
struct GpuChunk {
  std::uint32_t chunk = 0, first_weight = 0, weight_count = 0, chunk_in_tile = 0;
};
static_assert(sizeof(GpuChunk) == 16, "one RGBA32UI texel of the chunk buffer texture");
constexpr std::uint32_t kNoTexel = 0xffffffffu;  // a padding slot (prm_sum.comp.glsl skips it)
static_assert(sizeof(glm::vec3) == 12, "set_base and read_back move glm::vec3 arrays as packed RGB floats");

enum class SumMode : std::uint32_t { Zero = 0, Base = 1, Accumulate = 2 };

engine::Error error(std::string message) { return engine::Error{"", kWhere, std::move(message)}; }

/// Words of one packed block of eight elements: 24 halves in three uvec4s, or eight RGB9E5
/// words in two. The shader reads a block's uvec4s whole, even for a short last block.
std::size_t block_words(PrmPaneEncoding encoding) { return encoding == PrmPaneEncoding::Half ? 12 : 8; }

/// The power of two exponent s such that the pane's largest |value| x 2^s lies in
/// [2^14, 2^15): the top of the half range without overflow (and below RGB9E5's largest
/// value, 65408). 0 for an all-zero pane. Capped so the inverse scale (times RGB9E5's 2^-24)
/// stays a normal float.
int pane_scale_exponent(std::span<const float> pane, PrmPaneEncoding encoding) {
  float largest = 0.0f;
  for (float v : pane) largest = std::max(largest, std::abs(v));
  if (largest == 0.0f) return 0;
  int e = 0;
  (void)std::frexp(largest, &e);  // largest = m 2^e, m in [0.5, 1)
  return std::min(15 - e, encoding == PrmPaneEncoding::Half ? 126 : 126 - 24);
}

// RGB9E5 as GL's EXT_texture_shared_exponent defines it (N = 9 mantissa bits, bias B = 15),
// but decoded as mantissa x 2^(e - 24) (prm_sum.comp.glsl folds the 2^-24 into the weight).
constexpr int kMantissaBits = 9;
constexpr int kExponentBias = 15;
constexpr int kMantissaShift = kExponentBias + kMantissaBits;  // 24

/// Encodes non-negative r, g, b below 2^15 (the pane scale puts them there).
std::uint32_t encode_rgb9e5(float r, float g, float b) {
  const float largest = std::max({r, g, b});
  if (!(largest > 0.0f)) return 0u;
  int e = 0;
  (void)std::frexp(largest, &e);  // floor(log2(largest)) = e - 1
  int shared = std::max(-kExponentBias - 1, e - 1) + 1 + kExponentBias;
  const auto quantize = [](float v, int exponent) {
    return static_cast<std::uint32_t>(std::floor(std::ldexp(static_cast<double>(v), kMantissaShift - exponent) + 0.5));
  };
  if (quantize(largest, shared) == (1u << kMantissaBits)) ++shared;  // rounded up to the next power of two
  shared = std::min(shared, 31);
  const std::uint32_t limit = (1u << kMantissaBits) - 1u;
  return std::min(quantize(r, shared), limit) | std::min(quantize(g, shared), limit) << 9 |
         std::min(quantize(b, shared), limit) << 18 | static_cast<std::uint32_t>(shared) << 27;
}

glm::vec3 decode_rgb9e5(std::uint32_t w) {
  const float scale = std::ldexp(1.0f, static_cast<int>(w >> 27) - kMantissaShift);
  return glm::vec3(static_cast<float>(w & 511u), static_cast<float>(w >> 9 & 511u),
                   static_cast<float>(w >> 18 & 511u)) *
         scale;
}

/// Packs `pane` (3 floats per element) scaled by 2^exponent into `words` (zeroed, stride long).
void pack_pane(std::span<const float> pane, int exponent, PrmPaneEncoding encoding, std::span<std::uint32_t> words) {
  if (encoding == PrmPaneEncoding::Half) {
    for (std::size_t h = 0; h < pane.size(); ++h) {
      const std::uint32_t half = glm::packHalf1x16(std::ldexp(pane[h], exponent));
      words[h / 2] |= half << (16 * (h & 1));
    }
    return;
  }
  for (std::size_t i = 0; i < pane.size() / 3; ++i)
    words[i] = encode_rgb9e5(std::ldexp(pane[3 * i], exponent), std::ldexp(pane[3 * i + 1], exponent),
                             std::ldexp(pane[3 * i + 2], exponent));
}

/// The values `pack_pane` stored, unscaled again: what the shader sums.
void unpack_pane(std::span<const std::uint32_t> words, int exponent, PrmPaneEncoding encoding, std::span<float> pane) {
  if (encoding == PrmPaneEncoding::Half) {
    for (std::size_t h = 0; h < pane.size(); ++h)
      pane[h] = std::ldexp(glm::unpackHalf1x16(static_cast<std::uint16_t>(words[h / 2] >> (16 * (h & 1)))), -exponent);
    return;
  }
  for (std::size_t i = 0; i < pane.size() / 3; ++i) {
    const glm::vec3 v = decode_rgb9e5(words[i]);
    for (int ch = 0; ch < 3; ++ch) pane[3 * i + static_cast<std::size_t>(ch)] = std::ldexp(v[ch], -exponent);
  }
}

/// Error naming the first pane value the encoding cannot hold, if any.
std::optional<engine::Error> check_pane_values(const Prm& prm, PrmPaneEncoding encoding) {
  const std::vector<float>& values = prm.panes.values;
  for (std::size_t f = 0; f < values.size(); ++f) {
    const bool finite = std::isfinite(values[f]);
    if (finite && (encoding == PrmPaneEncoding::Half || values[f] >= 0.0f)) continue;
    return error("stored pane value " + std::to_string(f / 3) +
                 (finite ? " is negative (the shared-exponent encoding holds only values >= 0)" : " is not finite"));
  }
  return std::nullopt;
}

/// Cluster c's stored values (contiguous: its blocks follow each other).
std::span<const float> cluster_values(const PrmPanes& p, std::size_t c) {
  const std::uint32_t b0 = p.cluster_first[c], b1 = p.cluster_first[c + 1];
  if (b0 == b1) return {};
  const std::size_t first = p.block_value[b0] * 3;
  const std::size_t last = (p.block_value[b1 - 1] + p.tiles.size(p.blocks[b1 - 1])) * 3;
  return std::span<const float>(p.values).subspan(first, last - first);
}

/// Pane slots of a tile on the GPU: its elements padded to whole blocks of eight.
std::size_t tile_slots(const PrmTiles& tiles, std::size_t k) { return (tiles.size(k) + kBlock - 1) / kBlock * kBlock; }

/// Words cluster c's blocks take in a pane buffer.
std::size_t cluster_words(const PrmPanes& p, std::size_t c, PrmPaneEncoding encoding) {
  std::size_t words = 0;
  for (std::uint32_t b = p.cluster_first[c]; b < p.cluster_first[c + 1]; ++b)
    words += tile_slots(p.tiles, p.blocks[b]) / kBlock * block_words(encoding);
  return words;
}

std::size_t gl_limit(GLenum name) {
  GLint64 value = 0;
  glGetInteger64v(name, &value);
  return value > 0 ? static_cast<std::size_t>(value) : 0;
}

// The bake's atlas, texels and panes checked before anything is acquired.
std::optional<engine::Error> check_prm(const Prm& prm, PrmPaneEncoding encoding) {
  if (prm.width <= 0 || prm.height <= 0)
    return error("atlas size " + std::to_string(prm.width) + "x" + std::to_string(prm.height) + " is empty");
  const std::size_t atlas_texels = static_cast<std::size_t>(prm.width) * static_cast<std::size_t>(prm.height);
  if (atlas_texels > std::numeric_limits<std::uint32_t>::max()) return error("atlas has more than 2^32 texels");
  const std::size_t max_texture = gl_limit(GL_MAX_TEXTURE_SIZE);
  if (static_cast<std::size_t>(std::max(prm.width, prm.height)) > std::min<std::size_t>(max_texture, 65536))
    return error("atlas size " + std::to_string(prm.width) + "x" + std::to_string(prm.height) +
                 " exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_texture) + " (or 65536)");
  const std::size_t elements = prm.texels.size();
  for (std::size_t i = 0; i < elements; ++i) {
    if (prm.texels[i] >= atlas_texels)
      return error("texel " + std::to_string(i) + " (" + std::to_string(prm.texels[i]) + ") is outside the " +
                   std::to_string(prm.width) + "x" + std::to_string(prm.height) + " atlas");
    if (i > 0 && prm.texels[i] <= prm.texels[i - 1])
      return error("texels are not strictly ascending at element " + std::to_string(i));
  }
  if (prm.cluster_count < 0) return error("negative cluster count");
  const PrmPanes& p = prm.panes;
  if (p.cluster_count() != static_cast<std::size_t>(prm.cluster_count) || p.tiles.elements.size() != elements ||
      p.block_value.size() != p.blocks.size())
    return error("panes hold " + std::to_string(p.cluster_count()) + " clusters over " +
                 std::to_string(p.tiles.elements.size()) + " texels, expected " + std::to_string(prm.cluster_count) +
                 " x " + std::to_string(elements));
  std::size_t stored = 0;
  for (std::uint32_t k : p.blocks) {
    if (k >= p.tiles.tiles())
      return error("a stored block lies on tile " + std::to_string(k) + " of " + std::to_string(p.tiles.tiles()));
    stored += p.tiles.size(k);
  }
  if (p.values.size() != stored * 3)
    return error("panes hold " + std::to_string(p.values.size()) + " floats, their blocks " + std::to_string(stored) +
                 " texels x 3");
  return check_pane_values(prm, encoding);
}

// Every input is read through an RGBA32UI buffer texture: at most GL_MAX_TEXTURE_BUFFER_SIZE
// texels of 16 bytes each. The limit per buffer, or the error when the texels or one pane
// exceed it.
engine::Result<std::size_t> buffer_limit_for(const Prm& prm, const PrmGpuPassOptions& options) {
  const std::size_t elements = prm.texels.size();
  std::size_t buffer_limit = std::min(kSsboLimitBytes, gl_limit(GL_MAX_TEXTURE_BUFFER_SIZE) * 16);
  if (options.max_buffer_bytes > 0) buffer_limit = std::min(buffer_limit, options.max_buffer_bytes);
  std::size_t slots = 0;
  for (std::size_t k = 0; k < prm.panes.tiles.tiles(); ++k) slots += tile_slots(prm.panes.tiles, k);
  const std::size_t texel_bytes = slots * sizeof(std::uint32_t);
  if (texel_bytes > buffer_limit)
    return error(std::to_string(elements) + " pane texels need " + std::to_string(texel_bytes) +
                 " bytes, above the buffer limit of " + std::to_string(buffer_limit));
  for (std::size_t c = 0; c < prm.panes.cluster_count(); ++c) {
    const std::size_t pane_bytes = cluster_words(prm.panes, c, options.encoding) * sizeof(std::uint32_t);
    if (pane_bytes > buffer_limit)
      return error("pane " + std::to_string(c) + " needs " + std::to_string(pane_bytes) +
                   " bytes, above the buffer limit of " + std::to_string(buffer_limit));
  }
  return buffer_limit;
}

}  // namespace

engine::Result<PrmGpuPass> PrmGpuPass::create(const Prm& prm, const PrmGpuPassOptions& options) {
  // Check the data before acquiring anything.
  if (auto bad = check_prm(prm, options.encoding)) return *bad;
  if (prm.atlas && !prm.atlas->upsampler) return error("coarse panes without their upsampler");
  if (prm.atlas) {
    const PaneUpsampler& up = *prm.atlas->upsampler;
    const std::size_t max_texture = std::min<std::size_t>(gl_limit(GL_MAX_TEXTURE_SIZE), 65536);
    if (up.coarse_size() != static_cast<std::size_t>(prm.width) * static_cast<std::size_t>(prm.height) ||
        up.fine_size() != static_cast<std::size_t>(prm.atlas_width()) * static_cast<std::size_t>(prm.atlas_height()))
      return error("the upsampler reads a " + std::to_string(up.coarse_size()) + "-texel layout into a " +
                   std::to_string(up.fine_size()) + "-texel one, the PRM's are " + std::to_string(prm.width) + "x" +
                   std::to_string(prm.height) + " and " + std::to_string(prm.atlas_width()) + "x" +
                   std::to_string(prm.atlas_height()));
    if (prm.atlas_width() <= 0 || prm.atlas_height() <= 0 ||
        static_cast<std::size_t>(std::max(prm.atlas_width(), prm.atlas_height())) > max_texture)
      return error("atlas size " + std::to_string(prm.atlas_width()) + "x" + std::to_string(prm.atlas_height()) +
                   " is empty or exceeds GL_MAX_TEXTURE_SIZE " + std::to_string(max_texture) + " (or 65536)");
  }
  auto buffer_limit = buffer_limit_for(prm, options);
  if (!buffer_limit) return buffer_limit.error();
  const std::size_t elements = prm.texels.size();
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);

  PrmGpuPass pass;
  pass.width_ = prm.atlas_width();
  pass.height_ = prm.atlas_height();
  pass.pane_width_ = prm.width;
  pass.pane_height_ = prm.height;
  pass.decode_scale_ = options.encoding == PrmPaneEncoding::Half ? 1.0f : std::ldexp(1.0f, -kMantissaShift);
  pass.max_groups_x_ =
      options.max_groups_x > 0 ? std::min(options.max_groups_x, kMaxGroupsPerDimension) : kMaxGroupsPerDimension;

  engine::ShaderProgramBuilder builder(gi_shader_files());
  builder.stage(engine::ShaderStage::Compute, "prm_sum.comp.glsl");
  if (options.encoding == PrmPaneEncoding::SharedExponent) builder.define("PRM_PANES_RGB9E5 1");
  auto program = builder.build();
  if (!program) return program.error();
  pass.program_ = std::move(program).value();
  const GLuint id = pass.program_.id();
  pass.uniforms_ = {glGetUniformLocation(id, "u_first_chunk"), glGetUniformLocation(id, "u_chunk_count"),
                    glGetUniformLocation(id, "u_mode")};

  pass.upload_panes(prm, options.encoding, *buffer_limit);
  pass.upload_texels(prm, *buffer_limit);
  if (prm.atlas)
    if (engine::Status s = pass.upload_upsampler(*prm.atlas->upsampler, prm.width); !s) return s.error();
  pass.create_output();
  if (glGetError() == GL_OUT_OF_MEMORY)
    return error("out of GPU memory uploading " + std::to_string(clusters) + " panes of " + std::to_string(elements) +
                 " texels");
  return pass;
}

void PrmGpuPass::upload_panes(const Prm& prm, PrmPaneEncoding encoding, std::size_t buffer_limit) {
  const PrmPanes& p = prm.panes;
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  cluster_first_ = p.cluster_first;
  blocks_ = p.blocks;
  block_offset_.assign(p.blocks.size(), 0u);
  panes_.resize(clusters);
  // Whole panes per buffer, as many as fit under the limit.
  std::vector<std::uint32_t> words;
  const auto flush = [&] {
    const std::size_t bytes = std::max<std::size_t>(words.size() * sizeof(std::uint32_t), 16);
    words.resize(bytes / sizeof(std::uint32_t), 0u);
    pane_buffers_.push_back(engine::GlBuffer::create(bytes, words.data()));
    pane_buffer_bytes_.push_back(bytes);
    pane_textures_.push_back(engine::GlTexture::create(GL_TEXTURE_BUFFER));
    glTextureBuffer(pane_textures_.back().id(), GL_RGBA32UI, pane_buffers_.back().id());
    words.clear();
  };
  for (std::size_t c = 0; c < clusters; ++c) {
    const std::size_t need = cluster_words(p, c, encoding);
    if (!words.empty() && (words.size() + need) * sizeof(std::uint32_t) > buffer_limit) flush();
    const int exponent = pane_scale_exponent(cluster_values(p, c), encoding);
    panes_[c] = {static_cast<std::uint32_t>(pane_buffers_.size()), std::ldexp(1.0f, -exponent)};
    for (std::uint32_t b = p.cluster_first[c]; b < p.cluster_first[c + 1]; ++b) {
      const std::size_t n = p.tiles.size(p.blocks[b]);
      const std::size_t stride = tile_slots(p.tiles, p.blocks[b]) / kBlock * block_words(encoding);
      block_offset_[b] = static_cast<std::uint32_t>(words.size() / 4);
      words.resize(words.size() + stride, 0u);
      pack_pane(std::span<const float>(p.values).subspan(p.block_value[b] * 3, n * 3), exponent, encoding,
                std::span<std::uint32_t>(words).last(stride));
    }
  }
  if (!words.empty() || pane_buffers_.empty()) flush();  // never empty: binding 1 always holds a buffer
}

void PrmGpuPass::upload_texels(const Prm& prm, std::size_t buffer_limit) {
  // Slots tile by tile, each tile padded to whole blocks of eight (padding: kNoTexel). The
  // shader reads texel coordinates packed x | y << 16 (no division per lane).
  const PrmTiles& tiles = prm.panes.tiles;
  const auto w = static_cast<std::uint32_t>(prm.width);
  std::vector<std::uint32_t> texels;
  tile_slot_.assign(1, 0u);
  for (std::size_t k = 0; k < tiles.tiles(); ++k) {
    for (std::uint32_t j = tiles.first[k]; j < tiles.first[k + 1]; ++j) {
      const std::uint32_t t = prm.texels[tiles.elements[j]];
      texels.push_back((t % w) | ((t / w) << 16));
    }
    texels.resize(tile_slot_.back() + tile_slots(tiles, k), kNoTexel);
    tile_slot_.push_back(static_cast<std::uint32_t>(texels.size()));
  }
  if (texels.empty()) texels.assign(kBlock, kNoTexel);  // never empty
  texel_slots_ = texels.size();
  texels_ = engine::GlBuffer::create(texels.size() * sizeof(std::uint32_t), texels.data());
  texels_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  glTextureBuffer(texels_texture_.id(), GL_RGBA32UI, texels_.id());
  weights_ = engine::GlBuffer::create();
  weights_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  chunks_ = engine::GlBuffer::create();
  chunks_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  max_weights_ = buffer_limit / sizeof(GpuPaneWeight);
  tile_mark_.assign(tiles.tiles(), -1);
  write_all_ = true;
}

engine::Status PrmGpuPass::upload_upsampler(const PaneUpsampler& up, int coarse_width) {
  engine::ShaderProgramBuilder builder(gi_shader_files());
  builder.stage(engine::ShaderStage::Compute, "prm_upsample.comp.glsl");
  auto program = builder.build();
  if (!program) return program.error();
  upsample_program_ = std::move(program).value();
  const GLuint id = upsample_program_.id();
  upsample_uniforms_ = {glGetUniformLocation(id, "u_first"), glGetUniformLocation(id, "u_count"),
                        glGetUniformLocation(id, "u_mode"), glGetUniformLocation(id, "u_reads")};
  const auto packed = [](std::uint32_t t, std::uint32_t w) { return (t % w) | ((t / w) << 16); };
  const auto fw = static_cast<std::uint32_t>(width_);
  if (coarse_width != up.coarse_width()) return error("the upsampler reads another pane layout");
  std::vector<glm::uvec4> reads;
  reads.reserve(std::max<std::size_t>(up.reads().size(), 1));
  const auto weight = [](float w) { return static_cast<std::uint32_t>(std::lround(w * PaneUpsampler::kWeightSteps)); };
  for (const PaneUpsampler::Read& r : up.reads()) {
    if (r.origin.x < -1 || r.origin.y < -1 || r.origin.x > 65534 || r.origin.y > 65534)
      return error("an upsampling read's origin lies outside the pane layout");
    const auto ox = static_cast<std::uint32_t>(r.origin.x + 1), oy = static_cast<std::uint32_t>(r.origin.y + 1);
    reads.emplace_back(packed(r.fine, fw), ox | (oy << 16), weight(r.weight[0]) | (weight(r.weight[1]) << 16),
                       weight(r.weight[2]) | (weight(r.weight[3]) << 16));
  }
  std::vector<glm::uvec2> rings;
  rings.reserve(std::max<std::size_t>(up.ring_texels().size(), 1));
  for (const PaneUpsampler::RingTexel& r : up.ring_texels()) rings.emplace_back(packed(r.fine, fw), r.neighbours);
  upsample_reads_count_ = static_cast<std::uint32_t>(reads.size());
  upsample_ring_first_.assign(up.ring_first().begin(), up.ring_first().end());
  if (reads.empty()) reads.emplace_back(0u);  // GL buffers cannot be empty
  if (rings.empty()) rings.emplace_back(0u);
  upsample_reads_ = engine::GlBuffer::create(reads.size() * sizeof(glm::uvec4), reads.data());
  upsample_rings_ = engine::GlBuffer::create(rings.size() * sizeof(glm::uvec2), rings.data());
  upsample_bytes_ = reads.size() * sizeof(glm::uvec4) + rings.size() * sizeof(glm::uvec2);
  upsample_count_ = static_cast<std::uint32_t>(up.reads().size() + up.ring_texels().size());
  return {};
}

void PrmGpuPass::run_upsample() {
  upsample_program_.use();
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, upsample_reads_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, upsample_rings_.id());
  glBindImageTexture(0, output_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, base_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  glBindImageTexture(2, coarse_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  const GLuint id = upsample_program_.id();
  const auto dispatch = [&](UpsampleMode mode, std::uint32_t first, std::uint32_t count) {
    if (count == 0) return;
    glProgramUniform1ui(id, upsample_uniforms_.mode, static_cast<GLuint>(mode));
    glProgramUniform1ui(id, upsample_uniforms_.first, first);
    glProgramUniform1ui(id, upsample_uniforms_.count, count);
    const std::uint32_t groups = (count + kGroupSize - 1) / kGroupSize;
    const std::uint32_t groups_x = std::min(groups, max_groups_x_);
    glDispatchCompute(groups_x, (groups + groups_x - 1) / groups_x, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
  };
  // The reads, then the rings one after the other (each reads the ones before), then the
  // base at every texel written in one dispatch (the rings take the mean of the panes' light
  // alone). Each dispatch is a fixed cost on llvmpipe (docs/performance.md).
  dispatch(UpsampleMode::Reads, 0, upsample_reads_count_);
  for (std::size_t r = 0; r + 1 < upsample_ring_first_.size(); ++r)
    dispatch(UpsampleMode::Ring, upsample_ring_first_[r], upsample_ring_first_[r + 1] - upsample_ring_first_[r]);
  if (!base_.empty()) {
    glProgramUniform1ui(id, upsample_uniforms_.reads, upsample_reads_count_);
    dispatch(UpsampleMode::Base, 0, upsample_count_);
  }
}

void PrmGpuPass::create_output() {
  if (upsample_count_ > 0) {
    coarse_ = engine::GlTexture::create_2d(GL_RGBA32F, pane_width_, pane_height_);
    glClearTexImage(coarse_.id(), 0, GL_RGBA, GL_FLOAT, nullptr);
  }
  output_ = engine::GlTexture::create_2d(GL_RGBA32F, width_, height_);
  glClearTexImage(output_.id(), 0, GL_RGBA, GL_FLOAT, nullptr);
  glTextureParameteri(output_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(output_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(output_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(output_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
}

engine::Status PrmGpuPass::run(std::span<const ClusterWeight> selected) {
  GI_EXPECTS(!program_.empty(), "PrmGpuPass::run on an empty (default or moved-from) pass");
  for (const ClusterWeight& w : selected)
    if (w.cluster >= panes_.size())
      return error("selected cluster " + std::to_string(w.cluster) + " does not exist (" +
                   std::to_string(panes_.size()) + " clusters)");
  std::size_t blocks = 0;
  for (const ClusterWeight& w : selected) blocks += cluster_first_[w.cluster + 1] - cluster_first_[w.cluster];
  if (blocks > max_weights_)
    return error(std::to_string(blocks) + " selected pane blocks, above the weight buffer's limit of " +
                 std::to_string(max_weights_));
  const std::vector<Dispatch> dispatches = upload_work(selected);
  last_chunks_ = 0;
  for (const Dispatch& d : dispatches) last_chunks_ += d.chunk_count;
  if (dispatches.empty()) return {};

  program_.use();
  glBindTextureUnit(0, texels_texture_.id());
  glBindTextureUnit(2, weights_texture_.id());
  glBindTextureUnit(3, chunks_texture_.id());
  // Coarse panes: the sum goes to the pane layout's texture, from zero (the base is added
  // at the atlas's texels by the upsampling pass).
  const bool coarse = upsample_count_ > 0;
  glBindImageTexture(0, coarse ? coarse_.id() : output_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, base_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  // One dispatch per pane buffer holding a selected block, over the touched tiles' blocks of
  // eight slots; the first writes (from the base or zero), later ones accumulate.
  for (std::size_t d = 0; d < dispatches.size(); ++d) {
    if (d > 0) glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    const SumMode mode = d > 0 ? SumMode::Accumulate : base_.empty() || coarse ? SumMode::Zero : SumMode::Base;
    const std::uint32_t groups = (dispatches[d].chunk_count + kGroupSize - 1) / kGroupSize;
    const std::uint32_t groups_x = std::min(groups, max_groups_x_);
    const std::uint32_t groups_y = (groups + groups_x - 1) / groups_x;
    glProgramUniform1ui(program_.id(), uniforms_.mode, static_cast<GLuint>(mode));
    glProgramUniform1ui(program_.id(), uniforms_.first_chunk, dispatches[d].first_chunk);
    glProgramUniform1ui(program_.id(), uniforms_.chunk_count, dispatches[d].chunk_count);
    glBindTextureUnit(1, pane_textures_[dispatches[d].buffer].id());
    glDispatchCompute(groups_x, groups_y, 1);
  }
  if (coarse) {
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    run_upsample();
  }
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_FRAMEBUFFER_BARRIER_BIT | GL_PIXEL_BUFFER_BARRIER_BIT);
  return {};
}

std::vector<std::uint32_t> PrmGpuPass::touched_tiles(std::span<const ClusterWeight> selected) {
  // This run's tiles and the last run's (they go back to the base); every tile after
  // creation or a new base. Ascending, each once; tile_mark_ maps each to its position
  // until upload_work resets it.
  std::vector<std::uint32_t> tiles;
  const auto add = [&](std::uint32_t k) {
    if (tile_mark_[k] >= 0) return;
    tile_mark_[k] = 0;
    tiles.push_back(k);
  };
  if (write_all_) {
    for (std::uint32_t k = 0; k < tile_mark_.size(); ++k) add(k);
  } else {
    for (std::uint32_t k : last_tiles_) add(k);
    for (const ClusterWeight& w : selected)
      for (std::uint32_t b = cluster_first_[w.cluster]; b < cluster_first_[w.cluster + 1]; ++b) add(blocks_[b]);
  }
  std::sort(tiles.begin(), tiles.end());
  for (std::size_t i = 0; i < tiles.size(); ++i) tile_mark_[tiles[i]] = static_cast<std::int32_t>(i);
  write_all_ = false;
  return tiles;
}

// Long because the weights of one pane buffer are grouped per touched tile (a counting sort
// that keeps the selection's order, the CPU twin's summation order) and its chunks listed
// in the same pass; split, the counts would travel between functions.
std::vector<PrmGpuPass::Dispatch> PrmGpuPass::upload_work(std::span<const ClusterWeight> selected) {
  const std::vector<std::uint32_t> tiles = touched_tiles(selected);
  std::vector<GpuPaneWeight> weights;
  std::vector<GpuChunk> chunks;
  std::vector<Dispatch> dispatches;
  std::vector<std::uint32_t> count(tiles.size() + 1);
  for (std::uint32_t g = 0; g < pane_buffers_.size() && !tiles.empty(); ++g) {
    std::fill(count.begin(), count.end(), 0u);
    for (const ClusterWeight& w : selected)
      if (panes_[w.cluster].buffer == g)
        for (std::uint32_t b = cluster_first_[w.cluster]; b < cluster_first_[w.cluster + 1]; ++b)
          ++count[static_cast<std::size_t>(tile_mark_[blocks_[b]]) + 1];
    for (std::size_t i = 1; i < count.size(); ++i) count[i] += count[i - 1];
    if (count.back() == 0 && !dispatches.empty()) continue;
    const auto first_weight = static_cast<std::uint32_t>(weights.size());
    weights.resize(weights.size() + count.back());
    std::vector<std::uint32_t> at(count.begin(), count.end() - 1);
    for (const ClusterWeight& w : selected) {
      const PaneLocation& p = panes_[w.cluster];
      if (p.buffer != g) continue;
      const glm::vec3 scaled = w.weight * (p.inverse_scale * decode_scale_);
      for (std::uint32_t b = cluster_first_[w.cluster]; b < cluster_first_[w.cluster + 1]; ++b)
        weights[first_weight + at[static_cast<std::size_t>(tile_mark_[blocks_[b]])]++] = {scaled.x, scaled.y, scaled.z,
                                                                                          block_offset_[b]};
    }
    // The first dispatch writes every touched tile (from the base or zero), later ones only
    // the tiles they add to.
    Dispatch d{g, static_cast<std::uint32_t>(chunks.size()), 0u};
    for (std::size_t i = 0; i < tiles.size(); ++i) {
      const std::uint32_t n = count[i + 1] - count[i];
      if (n == 0 && !dispatches.empty()) continue;
      const std::uint32_t slot = tile_slot_[tiles[i]], slots = tile_slot_[tiles[i] + 1] - slot;
      for (std::uint32_t k = 0; k < slots / kBlock; ++k)
        chunks.push_back({slot / static_cast<std::uint32_t>(kBlock) + k, first_weight + count[i], n, k});
    }
    d.chunk_count = static_cast<std::uint32_t>(chunks.size()) - d.first_chunk;
    dispatches.push_back(d);
  }
  for (std::uint32_t k : tiles) tile_mark_[k] = -1;
  last_tiles_.clear();
  for (const ClusterWeight& w : selected)
    for (std::uint32_t b = cluster_first_[w.cluster]; b < cluster_first_[w.cluster + 1]; ++b)
      last_tiles_.push_back(blocks_[b]);
  if (weights.empty()) weights.emplace_back();  // GL buffers cannot be empty
  if (chunks.empty()) chunks.emplace_back();
  weights_bytes_ = weights.size() * sizeof(GpuPaneWeight);
  chunks_bytes_ = chunks.size() * sizeof(GpuChunk);
  glNamedBufferData(weights_.id(), static_cast<GLsizeiptr>(weights_bytes_), weights.data(), GL_STREAM_DRAW);
  glTextureBuffer(weights_texture_.id(), GL_RGBA32UI, weights_.id());
  glNamedBufferData(chunks_.id(), static_cast<GLsizeiptr>(chunks_bytes_), chunks.data(), GL_STREAM_DRAW);
  glTextureBuffer(chunks_texture_.id(), GL_RGBA32UI, chunks_.id());
  return dispatches;
}

engine::Status PrmGpuPass::set_base(std::span<const glm::vec3> base_atlas) {
  GI_EXPECTS(!output_.empty(), "PrmGpuPass::set_base on an empty (default or moved-from) pass");
  if (base_atlas.empty()) {
    base_.reset();
    write_all_ = true;
    return {};
  }
  const std::size_t texels = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  if (base_atlas.size() != texels)
    return error("base atlas holds " + std::to_string(base_atlas.size()) + " texels, the PRM atlas " +
                 std::to_string(width_) + "x" + std::to_string(height_));
  if (base_.empty()) base_ = engine::GlTexture::create_2d(GL_RGBA32F, width_, height_);
  write_all_ = true;  // the next run writes the new base at every pane texel
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(base_.id(), 0, 0, 0, width_, height_, GL_RGB, GL_FLOAT, base_atlas.data());
  return {};
}

std::vector<glm::vec3> PrmGpuPass::read_back() const {
  GI_EXPECTS(!output_.empty(), "PrmGpuPass::read_back on an empty (default or moved-from) pass");
  std::vector<glm::vec3> atlas(static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_));
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(output_.id(), 0, GL_RGB, GL_FLOAT, static_cast<GLsizei>(atlas.size() * sizeof(glm::vec3)),
                    atlas.data());
  return atlas;
}

engine::Result<PrmPanes> decoded_panes(const Prm& prm, PrmPaneEncoding encoding) {
  if (auto bad = check_pane_values(prm, encoding)) return *bad;
  PrmPanes out = prm.panes;
  std::vector<std::uint32_t> words;
  for (std::size_t c = 0; c < out.cluster_count(); ++c) {
    const std::span<const float> pane = cluster_values(prm.panes, c);
    if (pane.empty()) continue;
    const int exponent = pane_scale_exponent(pane, encoding);
    words.assign(pane.size(), 0u);  // at least the words pack_pane writes
    pack_pane(pane, exponent, encoding, words);
    const auto first = static_cast<std::size_t>(pane.data() - prm.panes.values.data());
    unpack_pane(words, exponent, encoding, std::span<float>(out.values).subspan(first, pane.size()));
  }
  return out;
}

std::size_t PrmGpuPass::pane_bytes() const {
  std::size_t bytes = 0;
  for (std::size_t b : pane_buffer_bytes_) bytes += b;
  return bytes;
}

std::size_t PrmGpuPass::gpu_bytes() const { return memory().total(); }

PrmGpuPass::Memory PrmGpuPass::memory() const {
  const std::size_t atlas_bytes = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 16;
  Memory m;
  for (std::size_t b : pane_buffer_bytes_) m.panes += b;
  m.texels = texel_slots_ * sizeof(std::uint32_t);
  m.work = weights_bytes_ + chunks_bytes_;
  m.upsample = upsample_bytes_;
  if (!coarse_.empty()) m.coarse = static_cast<std::size_t>(pane_width_) * static_cast<std::size_t>(pane_height_) * 16;
  if (!output_.empty()) m.output = atlas_bytes;
  if (!base_.empty()) m.base = atlas_bytes;
  return m;
}

}  // namespace gi
