#include "antiradiance/antiradiance_gpu_pass.h"

#include <GL/glcorearb.h>

#include <engine/check.h>

#include <algorithm>
#include <string>

#include "gpu/gi_shaders.h"

namespace gi {

namespace {

constexpr const char* kWhere = "antiradiance GPU pass";
constexpr std::size_t kSsboLimitBytes = std::size_t{128} << 20;  // DESIGN.md §4 (llvmpipe)
constexpr std::uint32_t kGroupSize = 64;                         // antiradiance_common.glsl
constexpr std::uint32_t kMaxGroupsPerDimension = 65535;

// A link as the global pass reads it: the sender and the form factor. Its bin is the run's
// (links are sorted by (receiver, bin): every link of a run has the run's bin), so it is not
// stored: 8 bytes instead of 16 per link on the GPU and in each door move's upload.
struct GpuLink {
  std::uint32_t sender;
  float form_factor;
};
static_assert(sizeof(GpuLink) == 8, "must match Link in antiradiance_global.comp.glsl (std430)");

struct GpuLeaf {
  glm::vec4 normal_area;
  glm::vec4 albedo;
  glm::vec4 direct;
};
static_assert(sizeof(GpuLeaf) == 48, "must match Leaf in antiradiance_local.comp.glsl (std430)");

engine::Error error(std::string message) { return engine::Error{"", kWhere, std::move(message)}; }

std::size_t ssbo_limit() {
  GLint64 value = 0;
  glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &value);
  return std::min(kSsboLimitBytes, value > 0 ? static_cast<std::size_t>(value) : kSsboLimitBytes);
}

// A mutable buffer of `bytes` (at least 16: GL buffers cannot be empty) holding `data` (or zeros).
engine::GlBuffer buffer(std::size_t bytes, const void* data) {
  engine::GlBuffer b = engine::GlBuffer::create();
  const std::size_t size = std::max<std::size_t>(bytes, 16);
  glNamedBufferData(b.id(), static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_DRAW);
  if (data != nullptr && bytes > 0)
    glNamedBufferSubData(b.id(), 0, static_cast<GLsizeiptr>(bytes), data);
  else
    glClearNamedBufferData(b.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  return b;
}

engine::Result<engine::ShaderProgram> compile(const char* name) {
  return engine::ShaderProgramBuilder(gi_shader_files()).stage(engine::ShaderStage::Compute, name).build();
}

}  // namespace

engine::Result<AntiradianceGpuPass> AntiradianceGpuPass::create(const ElementHierarchy& h, const DirectionalBins& bins,
                                                                const LinkMesh& links) {
  const std::size_t limit = ssbo_limit();
  const std::size_t m = static_cast<std::size_t>(bins.count());
  const std::size_t table = h.nodes.size() * m * 3 * sizeof(float);
  if (table > limit)
    return error(std::to_string(h.nodes.size()) + " elements x " + std::to_string(m) + " bins need " +
                 std::to_string(table) + " bytes per table, above the SSBO limit of " + std::to_string(limit));
  if (links.links.size() * sizeof(GpuLink) > limit)
    return error(std::to_string(links.links.size()) + " links exceed the SSBO limit of " + std::to_string(limit));

  AntiradianceGpuPass pass(h);
  pass.m_ = static_cast<std::uint32_t>(m);
  pass.nodes_ = static_cast<std::uint32_t>(h.nodes.size());
  pass.leaves_ = static_cast<std::uint32_t>(h.leaf_count());
  for (auto [program, name] :
       {std::pair{&pass.global_, "antiradiance_global.comp.glsl"},
        std::pair{&pass.push_, "antiradiance_push.comp.glsl"}, std::pair{&pass.local_, "antiradiance_local.comp.glsl"},
        std::pair{&pass.pull_, "antiradiance_pull.comp.glsl"}}) {
    auto p = compile(name);
    if (!p) return p.error();
    *program = std::move(p).value();
  }

  std::vector<std::int32_t> parents(h.nodes.size());
  std::vector<glm::ivec2> child_range(h.nodes.size());
  for (std::size_t n = 0; n < h.nodes.size(); ++n) {
    parents[n] = h.nodes[n].parent;
    child_range[n] = glm::ivec2(h.nodes[n].first_child, h.nodes[n].child_count);
  }
  std::vector<std::int32_t> by_level;
  nodes_by_level(h, by_level, pass.level_offsets_);
  std::vector<glm::vec4> bin_data(m);
  for (std::size_t b = 0; b < m; ++b)
    bin_data[b] = glm::vec4(bins.direction(static_cast<int>(b)), bins.solid_angle(static_cast<int>(b)));

  pass.parents_ = buffer(parents.size() * sizeof(std::int32_t), parents.data());
  pass.leaf_nodes_ = buffer(h.leaves.size() * sizeof(std::int32_t), h.leaves.data());
  pass.child_range_ = buffer(child_range.size() * sizeof(glm::ivec2), child_range.data());
  pass.children_ = buffer(h.children.size() * sizeof(std::int32_t), h.children.data());
  pass.by_level_ = buffer(by_level.size() * sizeof(std::int32_t), by_level.data());
  pass.bins_ = buffer(bin_data.size() * sizeof(glm::vec4), bin_data.data());
  pass.leaf_data_ = buffer(h.leaf_count() * sizeof(GpuLeaf), nullptr);
  const std::size_t leaf_table = h.leaf_count() * m * 3 * sizeof(float);
  pass.i_ex_ = buffer(table, nullptr);
  pass.l_in_ = buffer(table, nullptr);
  pass.i_l_ = buffer(leaf_table, nullptr);
  pass.i_a_ = buffer(leaf_table, nullptr);
  pass.irradiance_ = buffer(h.leaf_count() * sizeof(glm::vec4), nullptr);
  pass.residual_ = buffer(h.leaf_count() * sizeof(glm::vec2), nullptr);
  pass.bytes_ = parents.size() * 4 + h.leaves.size() * 4 + child_range.size() * 8 + h.children.size() * 4 +
                by_level.size() * 4 + m * 16 + h.leaf_count() * 48 + 2 * table + 2 * leaf_table + h.leaf_count() * 24;
  if (engine::Status st = pass.set_links(links); !st) return st.error();
  if (glGetError() == GL_OUT_OF_MEMORY) return error("out of GPU memory allocating the tables");
  return pass;
}

engine::Status AntiradianceGpuPass::set_links(const LinkMesh& links) {
  GI_EXPECTS(links.offsets.size() == static_cast<std::size_t>(nodes_) + 1,
             "set_links: offsets must match the hierarchy");
  if (links.links.size() * sizeof(GpuLink) > ssbo_limit())
    return error(std::to_string(links.links.size()) + " links exceed the SSBO limit");
  std::vector<GpuLink> data(links.links.size());
  for (std::size_t k = 0; k < data.size(); ++k)
    data[k] = {static_cast<std::uint32_t>(links.links[k].sender), links.links[k].form_factor};
  // One run per (receiver, bin): first link, count, destination entry.
  std::vector<glm::uvec4> runs;
  for (std::size_t k = 0; k < links.links.size();) {
    const Link& first = links.links[k];
    std::size_t e = k + 1;
    while (e < links.links.size() && links.links[e].receiver == first.receiver && links.links[e].bin == first.bin) ++e;
    runs.emplace_back(static_cast<std::uint32_t>(k), static_cast<std::uint32_t>(e - k),
                      static_cast<std::uint32_t>(first.receiver) * m_ + static_cast<std::uint32_t>(first.bin), 0u);
    k = e;
  }
  runs_count_ = static_cast<std::uint32_t>(runs.size());
  runs_ = buffer(runs.size() * sizeof(glm::uvec4), runs.data());
  links_ = buffer(data.size() * sizeof(GpuLink), data.data());
  link_bytes_ = runs.size() * sizeof(glm::uvec4) + data.size() * sizeof(GpuLink);
  return {};
}

void AntiradianceGpuPass::dispatch(const engine::ShaderProgram& program, std::uint32_t items) {
  glProgramUniform1ui(program.id(), glGetUniformLocation(program.id(), "u_bins"), m_);
  glProgramUniform1ui(program.id(), glGetUniformLocation(program.id(), "u_items"), items);
  if (items == 0) return;
  program.use();
  const std::uint32_t groups = (items + kGroupSize - 1) / kGroupSize;
  const std::uint32_t gx = std::min(groups, kMaxGroupsPerDimension);
  const std::uint32_t gy = (groups + gx - 1) / gx;
  glDispatchCompute(gx, gy, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

void AntiradianceGpuPass::upload_leaves(std::span<const glm::vec3> direct) {
  std::vector<GpuLeaf> data(leaves_);
  for (std::size_t l = 0; l < leaves_; ++l) {
    const ElementNode& e = h_->nodes[static_cast<std::size_t>(h_->leaves[l])];
    data[l] = {glm::vec4(e.normal, e.area_m2), glm::vec4(e.albedo, 0.0f), glm::vec4(direct[l], 0.0f)};
  }
  glNamedBufferSubData(leaf_data_.id(), 0, static_cast<GLsizeiptr>(data.size() * sizeof(GpuLeaf)), data.data());
}

void AntiradianceGpuPass::warm_start(std::span<const glm::vec3> direct) {
  GI_EXPECTS(direct.size() == leaves_, "warm_start: one direct irradiance per leaf");
  upload_leaves(direct);  // the tables stay: the last solve's I_ex is the first iterate
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
}

void AntiradianceGpuPass::reset(std::span<const glm::vec3> direct) {
  GI_EXPECTS(direct.size() == leaves_, "reset: one direct irradiance per leaf");
  upload_leaves(direct);
  // The local pass over zero incident light writes I_L from the direct light, I_A = 0, E = 0.
  for (const engine::GlBuffer* b : {&l_in_, &i_a_, &i_ex_})
    glClearNamedBufferData(b->id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  local(true, true);
  pull();
}

void AntiradianceGpuPass::global() {
  glClearNamedBufferData(l_in_.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, runs_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, links_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, i_ex_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, l_in_.id());
  dispatch(global_, runs_count_);
}

void AntiradianceGpuPass::set_first(const engine::ShaderProgram& program, std::uint32_t first) {
  glProgramUniform1ui(program.id(), glGetUniformLocation(program.id(), "u_first"), first);
}

void AntiradianceGpuPass::push() {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, parents_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, by_level_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, l_in_.id());
  for (std::size_t d = 1; d + 1 < level_offsets_.size(); ++d) {
    set_first(push_, level_offsets_[d]);
    dispatch(push_, (level_offsets_[d + 1] - level_offsets_[d]) * m_);
  }
}

LocalPassSums AntiradianceGpuPass::local(bool radiance, bool antiradiance) {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, leaf_data_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, leaf_nodes_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, bins_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, l_in_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, i_l_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, i_a_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, i_ex_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, irradiance_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 8, residual_.id());
  glProgramUniform1ui(local_.id(), glGetUniformLocation(local_.id(), "u_radiance"), radiance ? 1u : 0u);
  glProgramUniform1ui(local_.id(), glGetUniformLocation(local_.id(), "u_antiradiance"), antiradiance ? 1u : 0u);
  dispatch(local_, leaves_);
  std::vector<glm::vec2> partial(leaves_);
  glGetNamedBufferSubData(residual_.id(), 0, static_cast<GLsizeiptr>(partial.size() * sizeof(glm::vec2)),
                          partial.data());
  LocalPassSums sums;
  for (const glm::vec2& p : partial) {
    sums.change += static_cast<double>(p.x);
    sums.magnitude += static_cast<double>(p.y);
  }
  return sums;
}

void AntiradianceGpuPass::pull() {
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, child_range_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, children_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, by_level_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, i_ex_.id());
  for (std::size_t d = level_offsets_.size() - 1; d-- > 0;) {
    set_first(pull_, level_offsets_[d]);
    dispatch(pull_, (level_offsets_[d + 1] - level_offsets_[d]) * m_);
  }
}

std::vector<glm::vec3> AntiradianceGpuPass::irradiance() const {
  std::vector<glm::vec4> data(leaves_);
  glGetNamedBufferSubData(irradiance_.id(), 0, static_cast<GLsizeiptr>(data.size() * sizeof(glm::vec4)), data.data());
  std::vector<glm::vec3> out(leaves_);
  for (std::size_t l = 0; l < out.size(); ++l) out[l] = glm::vec3(data[l]);
  return out;
}

std::vector<glm::vec3> AntiradianceGpuPass::exitant() const {
  std::vector<glm::vec3> out(static_cast<std::size_t>(nodes_) * m_);
  static_assert(sizeof(glm::vec3) == 12, "exitant() reads packed RGB floats");
  glGetNamedBufferSubData(i_ex_.id(), 0, static_cast<GLsizeiptr>(out.size() * sizeof(glm::vec3)), out.data());
  return out;
}

std::size_t AntiradianceGpuPass::gpu_bytes() const { return bytes_ + link_bytes_; }

}  // namespace gi
