#include "prm/prm_gpu_pass.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <glm/gtc/packing.hpp>

#include "gpu/gi_shaders.h"

namespace gi {

namespace {

constexpr const char* kWhere = "PRM GPU pass";
constexpr std::size_t kSsboLimitBytes = std::size_t{128} << 20;  // DESIGN.md §4 (llvmpipe): per buffer
constexpr std::uint32_t kGroupSize = 64;  // local_size_x of prm_sum.comp.glsl
constexpr std::size_t kBlock = 8;         // elements an invocation sums (three uvec4s of halves per pane)
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

/// Words of one packed pane: 3 halves per element, two per word, whole blocks of eight
/// elements (12 words, three uvec4s: the shader reads a block's three even for a short last
/// block), so every pane starts on a 16-byte boundary.
std::size_t pane_stride_words(std::size_t elements) { return 12 * ((elements + kBlock - 1) / kBlock); }

/// The power of two exponent s such that the pane's largest |value| x 2^s lies in
/// [2^14, 2^15): the top of the half range without overflow. 0 for an all-zero pane.
int pane_scale_exponent(std::span<const float> pane) {
  float largest = 0.0f;
  for (float v : pane) largest = std::max(largest, std::abs(v));
  if (largest == 0.0f) return 0;
  int e = 0;
  (void)std::frexp(largest, &e);  // largest = m 2^e, m in [0.5, 1)
  return std::min(15 - e, 126);   // keep the inverse scale 2^-s a normal float
}

/// Packs `pane` (3 floats per element) scaled by 2^exponent into `words` (zeroed, stride long).
void pack_pane(std::span<const float> pane, int exponent, std::span<std::uint32_t> words) {
  for (std::size_t h = 0; h < pane.size(); ++h) {
    const std::uint32_t half = glm::packHalf1x16(std::ldexp(pane[h], exponent));
    words[h / 2] |= half << (16 * (h & 1));
  }
}

std::size_t gl_limit(GLenum name) {
  GLint64 value = 0;
  glGetInteger64v(name, &value);
  return value > 0 ? static_cast<std::size_t>(value) : 0;
}

}  // namespace

engine::Result<PrmGpuPass> PrmGpuPass::create(const Prm& prm, const PrmGpuPassOptions& options) {
  // Check the data before acquiring anything.
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
  if (prm.panes.size() / 3 / std::max<std::size_t>(elements, 1) != clusters || prm.panes.size() != clusters * elements * 3)
    return error("panes hold " + std::to_string(prm.panes.size()) + " floats, expected " + std::to_string(clusters) +
                 " clusters x " + std::to_string(elements) + " texels x 3");
  for (std::size_t f = 0; f < prm.panes.size(); ++f)
    if (!std::isfinite(prm.panes[f]))
      return error("pane " + std::to_string(f / 3 / elements) + " element " + std::to_string(f / 3 % elements) +
                   " is not finite");

  // Every input is read through an RGBA32UI buffer texture: at most GL_MAX_TEXTURE_BUFFER_SIZE
  // texels of 16 bytes each.
  std::size_t buffer_limit = std::min(kSsboLimitBytes, gl_limit(GL_MAX_TEXTURE_BUFFER_SIZE) * 16);
  if (options.max_buffer_bytes > 0) buffer_limit = std::min(buffer_limit, options.max_buffer_bytes);
  const std::size_t texel_bytes = (elements + kBlock - 1) / kBlock * kBlock * sizeof(std::uint32_t);
  if (texel_bytes > buffer_limit)
    return error(std::to_string(elements) + " pane texels need " + std::to_string(texel_bytes) +
                 " bytes, above the buffer limit of " + std::to_string(buffer_limit));
  const std::size_t stride = pane_stride_words(elements);
  const std::size_t pane_bytes = stride * sizeof(std::uint32_t);
  if (pane_bytes > buffer_limit)
    return error("one pane of " + std::to_string(elements) + " texels needs " + std::to_string(pane_bytes) +
                 " bytes, above the buffer limit of " + std::to_string(buffer_limit));

  PrmGpuPass pass;
  pass.width_ = prm.width;
  pass.height_ = prm.height;
  pass.element_count_ = static_cast<std::uint32_t>(elements);
  pass.max_groups_x_ = options.max_groups_x > 0 ? std::min(options.max_groups_x, kMaxGroupsPerDimension)
                                                : kMaxGroupsPerDimension;

  auto program = engine::ShaderProgramBuilder(gi_shader_files())
                     .stage(engine::ShaderStage::Compute, "prm_sum.comp.glsl")
                     .build();
  if (!program) return program.error();
  pass.program_ = std::move(program).value();
  const GLuint id = pass.program_.id();
  pass.uniforms_ = {glGetUniformLocation(id, "u_element_count"), glGetUniformLocation(id, "u_first_weight"),
                    glGetUniformLocation(id, "u_weight_count"), glGetUniformLocation(id, "u_mode")};

  // Whole panes per buffer, as many as fit under the limit.
  const std::size_t panes_per_buffer = std::max<std::size_t>(1, buffer_limit / std::max<std::size_t>(pane_bytes, 1));
  pass.panes_.resize(clusters);
  std::vector<std::uint32_t> words;
  for (std::size_t first = 0; first < clusters; first += panes_per_buffer) {
    const std::size_t count = std::min(panes_per_buffer, clusters - first);
    words.assign(count * stride, 0u);
    for (std::size_t c = first; c < first + count; ++c) {
      const std::span<const float> pane(prm.panes.data() + c * elements * 3, elements * 3);
      const int exponent = pane_scale_exponent(pane);
      const std::size_t offset = (c - first) * stride;
      pack_pane(pane, exponent, std::span<std::uint32_t>(words).subspan(offset, stride));
      pass.panes_[c] = {static_cast<std::uint32_t>(pass.pane_buffers_.size()), static_cast<std::uint32_t>(offset),
                        std::ldexp(1.0f, -exponent)};
    }
    const std::size_t bytes = std::max<std::size_t>(words.size() * sizeof(std::uint32_t), 16);
    words.resize(bytes / sizeof(std::uint32_t), 0u);
    pass.pane_buffers_.push_back(engine::GlBuffer::create(bytes, words.data()));
    pass.pane_buffer_bytes_.push_back(bytes);
    pass.pane_textures_.push_back(engine::GlTexture::create(GL_TEXTURE_BUFFER));
    glTextureBuffer(pass.pane_textures_.back().id(), GL_RGBA32UI, pass.pane_buffers_.back().id());
  }
  if (pass.pane_buffers_.empty()) {  // no clusters: a stub so binding 1 always holds a buffer
    const std::uint32_t zeros[4] = {};
    pass.pane_buffers_.push_back(engine::GlBuffer::create(sizeof(zeros), zeros));
    pass.pane_buffer_bytes_.push_back(sizeof(zeros));
    pass.pane_textures_.push_back(engine::GlTexture::create(GL_TEXTURE_BUFFER));
    glTextureBuffer(pass.pane_textures_.back().id(), GL_RGBA32UI, pass.pane_buffers_.back().id());
  }

  // The shader reads texel coordinates packed x | y << 16 (no division per lane).
  std::vector<std::uint32_t> texels(prm.texels);
  for (std::uint32_t& t : texels) {
    const auto w = static_cast<std::uint32_t>(prm.width);
    t = (t % w) | ((t / w) << 16);
  }
  texels.resize(std::max<std::size_t>((elements + kBlock - 1) / kBlock * kBlock, kBlock), 0u);  // whole blocks; never empty
  pass.texels_ = engine::GlBuffer::create(texels.size() * sizeof(std::uint32_t), texels.data());
  pass.texels_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  glTextureBuffer(pass.texels_texture_.id(), GL_RGBA32UI, pass.texels_.id());
  pass.weights_ = engine::GlBuffer::create();
  pass.weights_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  pass.max_weights_ = buffer_limit / sizeof(GpuPaneWeight);

  pass.output_ = engine::GlTexture::create_2d(GL_RGBA32F, prm.width, prm.height);
  glClearTexImage(pass.output_.id(), 0, GL_RGBA, GL_FLOAT, nullptr);
  glTextureParameteri(pass.output_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(pass.output_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTextureParameteri(pass.output_.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTextureParameteri(pass.output_.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  if (glGetError() == GL_OUT_OF_MEMORY)
    return error("out of GPU memory uploading " + std::to_string(clusters) + " panes of " +
                 std::to_string(elements) + " texels");
  return pass;
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
  // Weights grouped by pane buffer: one dispatch per buffer that holds a selected pane.
  std::vector<GpuPaneWeight> weights;
  weights.reserve(std::max<std::size_t>(selected.size(), 1));
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(pane_buffers_.size(), {0u, 0u});  // first, count
  for (std::uint32_t b = 0; b < pane_buffers_.size(); ++b) {
    ranges[b].first = static_cast<std::uint32_t>(weights.size());
    for (const ClusterWeight& w : selected) {
      const PaneLocation& p = panes_[w.cluster];
      if (p.buffer != b) continue;
      const glm::vec3 scaled = w.weight * p.inverse_scale;
      weights.push_back({scaled.x, scaled.y, scaled.z, p.word_offset / 4});
    }
    ranges[b].second = static_cast<std::uint32_t>(weights.size()) - ranges[b].first;
  }
  if (weights.empty()) weights.emplace_back();  // GL buffers cannot be empty
  weights_bytes_ = weights.size() * sizeof(GpuPaneWeight);
  glNamedBufferData(weights_.id(), static_cast<GLsizeiptr>(weights_bytes_), weights.data(), GL_STREAM_DRAW);
  glTextureBuffer(weights_texture_.id(), GL_RGBA32UI, weights_.id());
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

std::size_t PrmGpuPass::gpu_bytes() const {
  const std::size_t atlas_bytes = static_cast<std::size_t>(width_) * static_cast<std::size_t>(height_) * 16;
  std::size_t bytes = std::max<std::size_t>((element_count_ + kBlock - 1) / kBlock * kBlock, kBlock) * sizeof(std::uint32_t) +
                      weights_bytes_;
  for (std::size_t b : pane_buffer_bytes_) bytes += b;
  if (!output_.empty()) bytes += atlas_bytes;
  if (!base_.empty()) bytes += atlas_bytes;
  return bytes;
}

}  // namespace gi
