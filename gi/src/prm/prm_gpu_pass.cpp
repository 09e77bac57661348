#include "prm/prm_gpu_pass.h"

#include <GL/glcorearb.h>

#include <algorithm>
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
static_assert(sizeof(glm::vec3) == 12, "set_base and read_back move glm::vec3 arrays as packed RGB floats");

enum class SumMode : std::uint32_t { Zero = 0, Base = 1, Accumulate = 2 };

engine::Error error(std::string message) { return engine::Error{"", kWhere, std::move(message)}; }

/// Words of one packed block of eight elements: 24 halves in three uvec4s, or eight RGB9E5
/// words in two. The shader reads a block's uvec4s whole, even for a short last block.
std::size_t block_words(PrmPaneEncoding encoding) { return encoding == PrmPaneEncoding::Half ? 12 : 8; }

/// Words of one packed pane: whole blocks, so every pane starts on a 16-byte boundary.
std::size_t pane_stride_words(std::size_t elements, PrmPaneEncoding encoding) {
  return block_words(encoding) * ((elements + kBlock - 1) / kBlock);
}

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
  const std::size_t elements = std::max<std::size_t>(prm.texels.size(), 1);
  for (std::size_t f = 0; f < prm.panes.size(); ++f) {
    const bool finite = std::isfinite(prm.panes[f]);
    if (finite && (encoding == PrmPaneEncoding::Half || prm.panes[f] >= 0.0f)) continue;
    return error("pane " + std::to_string(f / 3 / elements) + " element " + std::to_string(f / 3 % elements) +
                 (finite ? " is negative (the shared-exponent encoding holds only values >= 0)" : " is not finite"));
  }
  return std::nullopt;
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
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  if (prm.panes.size() / 3 / std::max<std::size_t>(elements, 1) != clusters ||
      prm.panes.size() != clusters * elements * 3)
    return error("panes hold " + std::to_string(prm.panes.size()) + " floats, expected " + std::to_string(clusters) +
                 " clusters x " + std::to_string(elements) + " texels x 3");
  return check_pane_values(prm, encoding);
}

// Every input is read through an RGBA32UI buffer texture: at most GL_MAX_TEXTURE_BUFFER_SIZE
// texels of 16 bytes each. The limit per buffer, or the error when the texels or one pane
// exceed it.
engine::Result<std::size_t> buffer_limit_for(const Prm& prm, const PrmGpuPassOptions& options) {
  const std::size_t elements = prm.texels.size();
  std::size_t buffer_limit = std::min(kSsboLimitBytes, gl_limit(GL_MAX_TEXTURE_BUFFER_SIZE) * 16);
  if (options.max_buffer_bytes > 0) buffer_limit = std::min(buffer_limit, options.max_buffer_bytes);
  const std::size_t texel_bytes = (elements + kBlock - 1) / kBlock * kBlock * sizeof(std::uint32_t);
  if (texel_bytes > buffer_limit)
    return error(std::to_string(elements) + " pane texels need " + std::to_string(texel_bytes) +
                 " bytes, above the buffer limit of " + std::to_string(buffer_limit));
  const std::size_t pane_bytes = pane_stride_words(elements, options.encoding) * sizeof(std::uint32_t);
  if (pane_bytes > buffer_limit)
    return error("one pane of " + std::to_string(elements) + " texels needs " + std::to_string(pane_bytes) +
                 " bytes, above the buffer limit of " + std::to_string(buffer_limit));
  return buffer_limit;
}

}  // namespace

engine::Result<PrmGpuPass> PrmGpuPass::create(const Prm& prm, const PrmGpuPassOptions& options) {
  // Check the data before acquiring anything.
  if (auto bad = check_prm(prm, options.encoding)) return *bad;
  auto buffer_limit = buffer_limit_for(prm, options);
  if (!buffer_limit) return buffer_limit.error();
  const std::size_t elements = prm.texels.size();
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);

  PrmGpuPass pass;
  pass.width_ = prm.width;
  pass.height_ = prm.height;
  pass.element_count_ = static_cast<std::uint32_t>(elements);
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
  pass.uniforms_ = {glGetUniformLocation(id, "u_element_count"), glGetUniformLocation(id, "u_first_weight"),
                    glGetUniformLocation(id, "u_weight_count"), glGetUniformLocation(id, "u_mode")};

  pass.upload_panes(prm, options.encoding, *buffer_limit);
  pass.upload_texels(prm, *buffer_limit);
  pass.create_output();
  if (glGetError() == GL_OUT_OF_MEMORY)
    return error("out of GPU memory uploading " + std::to_string(clusters) + " panes of " + std::to_string(elements) +
                 " texels");
  return pass;
}

void PrmGpuPass::upload_panes(const Prm& prm, PrmPaneEncoding encoding, std::size_t buffer_limit) {
  const std::size_t elements = prm.texels.size();
  const auto clusters = static_cast<std::size_t>(prm.cluster_count);
  const std::size_t stride = pane_stride_words(elements, encoding);
  const std::size_t pane_bytes = stride * sizeof(std::uint32_t);
  // Whole panes per buffer, as many as fit under the limit.
  const std::size_t panes_per_buffer = std::max<std::size_t>(1, buffer_limit / std::max<std::size_t>(pane_bytes, 1));
  panes_.resize(clusters);
  std::vector<std::uint32_t> words;
  for (std::size_t first = 0; first < clusters; first += panes_per_buffer) {
    const std::size_t count = std::min(panes_per_buffer, clusters - first);
    words.assign(count * stride, 0u);
    for (std::size_t c = first; c < first + count; ++c) {
      const std::span<const float> pane(prm.panes.data() + c * elements * 3, elements * 3);
      const int exponent = pane_scale_exponent(pane, encoding);
      const std::size_t offset = (c - first) * stride;
      pack_pane(pane, exponent, encoding, std::span<std::uint32_t>(words).subspan(offset, stride));
      panes_[c] = {static_cast<std::uint32_t>(pane_buffers_.size()), static_cast<std::uint32_t>(offset),
                   std::ldexp(1.0f, -exponent)};
    }
    const std::size_t bytes = std::max<std::size_t>(words.size() * sizeof(std::uint32_t), 16);
    words.resize(bytes / sizeof(std::uint32_t), 0u);
    pane_buffers_.push_back(engine::GlBuffer::create(bytes, words.data()));
    pane_buffer_bytes_.push_back(bytes);
    pane_textures_.push_back(engine::GlTexture::create(GL_TEXTURE_BUFFER));
    glTextureBuffer(pane_textures_.back().id(), GL_RGBA32UI, pane_buffers_.back().id());
  }
  if (pane_buffers_.empty()) {  // no clusters: a stub so binding 1 always holds a buffer
    const std::uint32_t zeros[4] = {};
    pane_buffers_.push_back(engine::GlBuffer::create(sizeof(zeros), zeros));
    pane_buffer_bytes_.push_back(sizeof(zeros));
    pane_textures_.push_back(engine::GlTexture::create(GL_TEXTURE_BUFFER));
    glTextureBuffer(pane_textures_.back().id(), GL_RGBA32UI, pane_buffers_.back().id());
  }
}

void PrmGpuPass::upload_texels(const Prm& prm, std::size_t buffer_limit) {
  const std::size_t elements = prm.texels.size();
  // The shader reads texel coordinates packed x | y << 16 (no division per lane).
  std::vector<std::uint32_t> texels(prm.texels);
  for (std::uint32_t& t : texels) {
    const auto w = static_cast<std::uint32_t>(prm.width);
    t = (t % w) | ((t / w) << 16);
  }
  texels.resize(std::max<std::size_t>((elements + kBlock - 1) / kBlock * kBlock, kBlock),
                0u);  // whole blocks; never empty
  texels_ = engine::GlBuffer::create(texels.size() * sizeof(std::uint32_t), texels.data());
  texels_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  glTextureBuffer(texels_texture_.id(), GL_RGBA32UI, texels_.id());
  weights_ = engine::GlBuffer::create();
  weights_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  max_weights_ = buffer_limit / sizeof(GpuPaneWeight);
}

void PrmGpuPass::create_output() {
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

  if (selected.size() > max_weights_)
    return error(std::to_string(selected.size()) + " selected clusters, above the weight buffer's limit of " +
                 std::to_string(max_weights_));
  const std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges = upload_weights(selected);
  if (element_count_ == 0) return {};

  program_.use();
  glProgramUniform1ui(program_.id(), uniforms_.element_count, element_count_);
  glBindTextureUnit(0, texels_texture_.id());
  glBindTextureUnit(2, weights_texture_.id());
  glBindImageTexture(0, output_.id(), 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, base_.id(), 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);

  const auto blocks = static_cast<std::uint32_t>((element_count_ + kBlock - 1) / kBlock);
  const std::uint32_t groups = (blocks + kGroupSize - 1) / kGroupSize;
  const std::uint32_t groups_x = std::min(groups, max_groups_x_);
  const std::uint32_t groups_y = (groups + groups_x - 1) / groups_x;

  // One dispatch per buffer holding a selected pane; K = 0 still needs one to write the
  // base (or zeros). The first writes, later ones accumulate.
  std::vector<std::size_t> dispatches;
  for (std::size_t b = 0; b < ranges.size(); ++b)
    if (ranges[b].second > 0) dispatches.push_back(b);
  if (dispatches.empty()) dispatches.push_back(0);
  for (std::size_t d = 0; d < dispatches.size(); ++d) {
    const std::size_t b = dispatches[d];
    if (d > 0) glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
    const SumMode mode = d > 0 ? SumMode::Accumulate : base_.empty() ? SumMode::Zero : SumMode::Base;
    glProgramUniform1ui(program_.id(), uniforms_.mode, static_cast<GLuint>(mode));
    glProgramUniform1ui(program_.id(), uniforms_.first_weight, ranges[b].first);
    glProgramUniform1ui(program_.id(), uniforms_.weight_count, ranges[b].second);
    glBindTextureUnit(1, pane_textures_[b].id());
    glDispatchCompute(groups_x, groups_y, 1);
  }
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_FRAMEBUFFER_BARRIER_BIT | GL_PIXEL_BUFFER_BARRIER_BIT);
  return {};
}

std::vector<std::pair<std::uint32_t, std::uint32_t>> PrmGpuPass::upload_weights(
    std::span<const ClusterWeight> selected) {
  // Weights grouped by pane buffer: one dispatch per buffer that holds a selected pane.
  std::vector<GpuPaneWeight> weights;
  weights.reserve(std::max<std::size_t>(selected.size(), 1));
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(pane_buffers_.size(), {0u, 0u});  // first, count
  for (std::uint32_t b = 0; b < pane_buffers_.size(); ++b) {
    ranges[b].first = static_cast<std::uint32_t>(weights.size());
    for (const ClusterWeight& w : selected) {
      const PaneLocation& p = panes_[w.cluster];
      if (p.buffer != b) continue;
      const glm::vec3 scaled = w.weight * (p.inverse_scale * decode_scale_);
      weights.push_back({scaled.x, scaled.y, scaled.z, p.word_offset / 4});
    }
    ranges[b].second = static_cast<std::uint32_t>(weights.size()) - ranges[b].first;
  }
  if (weights.empty()) weights.emplace_back();  // GL buffers cannot be empty
  weights_bytes_ = weights.size() * sizeof(GpuPaneWeight);
  glNamedBufferData(weights_.id(), static_cast<GLsizeiptr>(weights_bytes_), weights.data(), GL_STREAM_DRAW);
  glTextureBuffer(weights_texture_.id(), GL_RGBA32UI, weights_.id());
  return ranges;
}

engine::Status PrmGpuPass::set_base(std::span<const glm::vec3> base_atlas) {
  GI_EXPECTS(!output_.empty(), "PrmGpuPass::set_base on an empty (default or moved-from) pass");
  if (base_atlas.empty()) {
    base_.reset();
    return {};
  }
  const std::size_t texels = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_);
  if (base_atlas.size() != texels)
    return error("base atlas holds " + std::to_string(base_atlas.size()) + " texels, the PRM atlas " +
                 std::to_string(width_) + "x" + std::to_string(height_));
  if (base_.empty()) base_ = engine::GlTexture::create_2d(GL_RGBA32F, width_, height_);
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

engine::Result<std::vector<float>> decoded_panes(const Prm& prm, PrmPaneEncoding encoding) {
  if (auto bad = check_pane_values(prm, encoding)) return *bad;
  const std::size_t elements = prm.texels.size();
  std::vector<float> out(prm.panes.size(), 0.0f);
  if (elements == 0) return out;
  std::vector<std::uint32_t> words(pane_stride_words(elements, encoding));
  for (std::size_t first = 0; first + elements * 3 <= prm.panes.size(); first += elements * 3) {
    const std::span<const float> pane(prm.panes.data() + first, elements * 3);
    const int exponent = pane_scale_exponent(pane, encoding);
    std::fill(words.begin(), words.end(), 0u);
    pack_pane(pane, exponent, encoding, words);
    unpack_pane(words, exponent, encoding, std::span<float>(out.data() + first, elements * 3));
  }
  return out;
}

std::size_t PrmGpuPass::pane_bytes() const {
  std::size_t bytes = 0;
  for (std::size_t b : pane_buffer_bytes_) bytes += b;
  return bytes;
}

std::size_t PrmGpuPass::gpu_bytes() const {
  const std::size_t atlas_bytes = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 16;
  std::size_t bytes =
      std::max<std::size_t>((element_count_ + kBlock - 1) / kBlock * kBlock, kBlock) * sizeof(std::uint32_t) +
      weights_bytes_;
  for (std::size_t b : pane_buffer_bytes_) bytes += b;
  if (!output_.empty()) bytes += atlas_bytes;
  if (!base_.empty()) bytes += atlas_bytes;
  return bytes;
}

}  // namespace gi
