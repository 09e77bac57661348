#include "brf/brf_gpu_pass.h"

#include <GL/glcorearb.h>
#include <engine/finite.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "brf/brf_lod.h"
#include "brf/brf_visibility.h"
#include "gpu/gi_shaders.h"

namespace gi {

namespace {

constexpr const char* kWhere = "BRF GPU pass";
constexpr std::size_t kSsboLimitBytes = std::size_t{128} << 20;  // DESIGN.md §4 (llvmpipe)
constexpr std::uint32_t kGroupSize = 64;                         // local_size_x of every brf_*.comp.glsl
constexpr std::uint32_t kMaxGroupsPerDimension = 65535;
// Texture units of brf_phi.comp.glsl's buffer textures (u_field, u_models, u_model_vertices,
// u_jobs, u_occluders).
constexpr GLuint kFieldTextureUnit = 0, kModelTextureUnit = 1, kVertexTextureUnit = 2, kJobTextureUnit = 3,
                 kOccluderTextureUnit = 4, kLodTextureUnit = 5, kLodRowsTextureUnit = 6;
constexpr int kMaxBasis = 64;  // kMaxChannels = 64 x 16 in brf_fit.comp.glsl
// sh_data_ layout (ShData in brf_phi.comp.glsl): 26 directions as vec4s, then the pinv of
// bands 1..3, then the glossy models' lobe SH and vertex frames.
constexpr std::size_t kShDirections = 26;
constexpr std::size_t kShTableFloats = 4 * kShDirections + (3 + 5 + 7) * kShDirections;

/// BrfModel in brf_common.glsl (std430).
struct GpuModel {
  glm::vec4 centre_inner{0.0f};
  float outer_radius = 0.0f;
  std::uint32_t spheres = 0, face_resolution = 0, sh_bands = 0;
  std::uint32_t basis_count = 0, vertex_offset = 0, vertex_count = 0, psi_offset = 0;
  std::uint32_t ainv_offset = 0, field_offset = 0, field_buffer = 0, terms = 1;
  glm::vec4 box_lo{0.0f}, box_hi{0.0f};
};
static_assert(sizeof(GpuModel) == 96, "must match BrfModel in brf_common.glsl (std430)");

/// BrfInstance in brf_common.glsl (std430).
struct GpuInstance {
  glm::vec4 albedo{0.0f}, specular{0.0f};
  std::uint32_t model = 0, vertex_offset = 0, vertex_count = 0, weight_offset = 0;
  std::uint32_t live_first = 0, live_count = 0, value_offset = 0, terms = 1;
};
static_assert(sizeof(GpuInstance) == 64, "must match BrfInstance in brf_common.glsl (std430)");

static_assert(sizeof(glm::uvec2) == 8 && sizeof(glm::uvec4) == 16 && sizeof(glm::vec4) == 16,
              "uvec2 / uvec4 / vec4 arrays are uploaded as std430 arrays");

engine::Error error(std::string message) { return engine::Error{"", kWhere, std::move(message)}; }

std::size_t gl_limit(GLenum name) {
  GLint64 value = 0;
  glGetInteger64v(name, &value);
  return value > 0 ? static_cast<std::size_t>(value) : 0;
}

bool same_pose(const glm::mat4& a, const glm::mat4& b, float tolerance) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (std::fabs(a[c][r] - b[c][r]) > tolerance * (1.0f + std::fabs(a[c][r]))) return false;
  return true;
}

/// 2-D grid of `groups` work groups (x wraps at 65535).
void dispatch_groups(std::uint32_t groups) {
  if (groups == 0) return;
  const std::uint32_t gx = std::min(groups, kMaxGroupsPerDimension);
  glDispatchCompute(gx, (groups + gx - 1) / gx, 1);
}

std::uint32_t u32(std::size_t v) { return static_cast<std::uint32_t>(v); }

/// Basis functions padded to a multiple of 4 (brf_padded in brf_common.glsl): Phi rows and
/// weight runs are read as vec4s.
// The xyz of the first `count` vec4s of a GL buffer.
std::vector<glm::vec3> read_back_vec4s(std::uint32_t buffer, std::size_t count) {
  std::vector<glm::vec4> v(count);
  if (count > 0) glGetNamedBufferSubData(buffer, 0, static_cast<GLsizeiptr>(count * sizeof(glm::vec4)), v.data());
  std::vector<glm::vec3> out(count);
  for (std::size_t j = 0; j < count; ++j) out[j] = glm::vec3(v[j]);
  return out;
}

std::uint32_t padded(std::uint32_t basis_count) { return (basis_count + 3u) & ~3u; }

/// The field as the GPU holds it: each channel's coefficients padded to a multiple of 4
/// floats (9 -> 12 for 3 bands), so brf_phi.comp.glsl reads them as vec4s. llvmpipe (Mesa 22)
/// runs every SSBO load as a loop over the SIMD lanes, so a vec4 costs about what one float
/// does: 3 loads per (sample, channel) instead of 9, 1 for the unclamped cosine's band 1.
std::size_t gpu_field_floats(const BasisRadianceField& f) {
  const std::size_t cc = static_cast<std::size_t>(f.coefficient_count());
  return f.coefficients.size() / cc * padded(static_cast<std::uint32_t>(cc));
}
std::size_t gpu_field_bytes(const BasisRadianceField& f) { return gpu_field_floats(f) * sizeof(float); }
std::vector<float> gpu_field(const BasisRadianceField& f) {
  const std::size_t cc = static_cast<std::size_t>(f.coefficient_count()), cc4 = padded(static_cast<std::uint32_t>(cc));
  std::vector<float> out(gpu_field_floats(f), 0.0f);
  for (std::size_t c = 0; c < f.coefficients.size() / cc; ++c)
    std::copy_n(f.coefficients.begin() + static_cast<std::ptrdiff_t>(c * cc), cc,
                out.begin() + static_cast<std::ptrdiff_t>(c * cc4));
  return out;
}

engine::Result<engine::ShaderProgram> build(const char* file) {
  return engine::ShaderProgramBuilder(gi_shader_files()).stage(engine::ShaderStage::Compute, file).build();
}

void bind(GLuint binding, GLuint buffer) { glBindBufferBase(GL_SHADER_STORAGE_BUFFER, binding, buffer); }

}  // namespace

/// PhiJob in brf_phi.comp.glsl (std430).
struct BrfPhiJob {
  glm::mat4 to_source{1.0f};
  glm::mat4 normal_to_source{1.0f};
  std::uint32_t source_model = 0, point_offset = 0, point_count = 0, phi_offset = 0;
  glm::mat4 frame_to_source{1.0f};  // glossy receiver: its object space's rotation into the source's
  std::uint32_t rows = 1, frame_offset = 0, lobe_offset = 0;
  // Level of detail (brf_lod.h): 0, or 1 + the receiver's first representative point (kind 0)
  // / first vertex entry (kind 2) in the lod table
  std::uint32_t lod_points = 0;
  std::uint32_t occluder_offset = 0, occluder_count = 0;  // into the occluder records
  std::uint32_t lod_rows = 0;  // kind 2: first vec4 of the representative points' rows in phi_
  std::uint32_t lod_shared = 0;  // BrfUpdateSettings::lod_shared_visibility (0 / 1)
};
static_assert(sizeof(BrfPhiJob) == 240, "must match PhiJob in brf_phi.comp.glsl (std430)");

/// BrfOccluderRecord in brf_phi.comp.glsl (std430): a box in the way of a pair, with the map
/// from the source's object space into the box's.
struct GpuOccluder {
  glm::mat4 to_occluder{1.0f};
  glm::vec4 lo{0.0f}, hi{0.0f};
};
static_assert(sizeof(GpuOccluder) == 96, "must match BrfOccluderRecord in brf_phi.comp.glsl (std430)");

void BrfGpuPass::Buffer::reserve(std::size_t size) {
  size = std::max<std::size_t>(size, 16);
  if (!buffer.empty() && bytes >= size) return;
  if (buffer.empty()) buffer = engine::GlBuffer::create();
  glNamedBufferData(buffer.id(), static_cast<GLsizeiptr>(size), nullptr, GL_DYNAMIC_DRAW);
  bytes = size;
}

void BrfGpuPass::Buffer::upload(const void* data, std::size_t size) {
  reserve(size);
  if (size > 0) glNamedBufferSubData(buffer.id(), 0, static_cast<GLsizeiptr>(size), data);
}

namespace {

/// create()'s checks of model m (pointers, sizes, glossy terms, field settings, limit, finite data).
engine::Status check_model(const BrfGpuModel& model, std::size_t m, std::size_t limit) {
  const std::string which = "model " + std::to_string(m) + ": ";
  if (model.mesh == nullptr || model.basis == nullptr || model.field == nullptr)
    return error(which + "mesh, basis and field must all be given");
  const BrfMesh& mesh = *model.mesh;
  const BrfBasis& basis = *model.basis;
  const BasisRadianceField& f = *model.field;
  const std::size_t nv = mesh.positions.size();
  if (mesh.normals.size() != nv || basis.vertex_count != nv)
    return error(which + "the mesh has " + std::to_string(nv) + " positions, " + std::to_string(mesh.normals.size()) +
                 " normals, the basis " + std::to_string(basis.vertex_count) + " vertices");
  if (basis.basis_count < 1 || basis.basis_count > kMaxBasis)
    return error(which + "basis of " + std::to_string(basis.basis_count) + " functions (1 to " +
                 std::to_string(kMaxBasis) + " supported)");
  const auto nb = static_cast<std::size_t>(basis.basis_count);
  if (basis.psi.size() != nb * nv || basis.a_inverse.size() != nb * nb)
    return error(which + "basis arrays do not match its size");
  if (f.basis_count != basis.basis_count) return error(which + "the field was computed for another basis");
  if (model.glossy == nullptr && f.terms != 1)
    return error(which + "a glossy field (" + std::to_string(f.terms) + " BRDF terms) but no glossy lobe");
  if (model.glossy != nullptr) {
    const BrdfSeparation& g = *model.glossy;
    if (g.terms < 1 || g.terms > kMaxGlossyTerms || f.terms != 1 + g.terms)
      return error(which + "the field has " + std::to_string(f.terms) + " BRDF terms, the glossy lobe " +
                   std::to_string(g.terms) + " (+1 diffuse)");
    if (g.lobe_sh.size() != static_cast<std::size_t>(g.terms) * kMaxShCoefficients)
      return error(which + "the glossy lobe's SH do not match its terms");
    for (float v : g.lobe_sh)
      if (!std::isfinite(v)) return error(which + "non-finite glossy lobe SH");
  }
  const std::size_t channels = nb * static_cast<std::size_t>(f.terms);
  if ((f.sh_bands != 3 && f.sh_bands != 4) || f.spheres < 1 || f.face_resolution < 1 || !(f.inner_radius > 0.0f) ||
      !(f.outer_radius >= f.inner_radius) || !std::isfinite(f.outer_radius) || !engine::all_finite(f.centre))
    return error(which + "field settings out of range");
  const std::size_t points = static_cast<std::size_t>(f.spheres) * 6 * static_cast<std::size_t>(f.face_resolution) *
                             static_cast<std::size_t>(f.face_resolution);
  if (f.coefficients.size() != points * channels * static_cast<std::size_t>(f.coefficient_count()))
    return error(which + "field holds " + std::to_string(f.coefficients.size()) + " floats, expected " +
                 std::to_string(points * channels * static_cast<std::size_t>(f.coefficient_count())));
  if (gpu_field_bytes(f) > limit)
    return error(which + "field of " + std::to_string(gpu_field_bytes(f)) + " bytes (channels padded to vec4s) is above the SSBO limit of " +
                 std::to_string(limit));
  for (std::size_t j = 0; j < nv; ++j)
    if (!engine::all_finite(mesh.positions[j]) || !engine::all_finite(mesh.normals[j]))
      return error(which + "non-finite vertex " + std::to_string(j));
  for (float v : basis.psi)
    if (!std::isfinite(v)) return error(which + "non-finite basis value");
  for (float v : basis.a_inverse)
    if (!std::isfinite(v)) return error(which + "non-finite A^-1 value");
  for (float v : f.coefficients)
    if (!std::isfinite(v)) return error(which + "non-finite field coefficient");
  return {};
}

/// The head of sh_data_: the SH rotation directions as vec4s, then the pinv of bands 1..3.
std::vector<float> sh_rotation_data() {
  const ShRotationTables& rotation = sh_rotation_tables();
  GI_EXPECTS(rotation.directions.size() == kShDirections, "ShRotation uses 26 fixed directions");
  std::vector<float> sh_data;
  for (const glm::vec3& d : rotation.directions) sh_data.insert(sh_data.end(), {d.x, d.y, d.z, 0.0f});
  for (int l = 1; l < kMaxShBands; ++l)
    sh_data.insert(sh_data.end(), rotation.pinv[static_cast<std::size_t>(l)].begin(),
                   rotation.pinv[static_cast<std::size_t>(l)].end());
  GI_EXPECTS(sh_data.size() == kShTableFloats, "SH rotation table layout");
  return sh_data;
}

}  // namespace

/// The model data create() gathers on the CPU before uploading it (one GL buffer each).
struct BrfGpuPass::ModelData {
  std::vector<GpuModel> table;
  std::vector<glm::vec4> vertices;  ///< Position, normal per model vertex.
  std::vector<float> psi, a_inverse;
  std::vector<std::size_t> field_group_bytes;  ///< Fields grouped into buffers under the limit.
  std::vector<float> sh_data;                  ///< SH rotation tables first (kPinvOffset), then per glossy model.
  /// Level-of-detail tables (brf_lod.h): per model its representative vertices (uvec4(vertex,
  /// 0, 0, 0) each), then per vertex uvec4(from a, b, c (indices into the points), 0) and
  /// uvec4(weight bits, 0).
  std::vector<glm::uvec4> lod_table;
};

engine::Result<BrfGpuPass> BrfGpuPass::create(std::span<const BrfGpuModel> models, const BrfGpuPassOptions& options) {
  // Check the data before acquiring anything.
  std::size_t limit = std::min(kSsboLimitBytes, gl_limit(GL_MAX_SHADER_STORAGE_BLOCK_SIZE));
  // The fields are read through RGBA32F buffer textures too (field_textures_).
  limit = std::min(limit, gl_limit(GL_MAX_TEXTURE_BUFFER_SIZE) * 16);
  if (options.max_buffer_bytes > 0) limit = std::min(limit, options.max_buffer_bytes);
  if (!(options.pose_tolerance >= 0.0f)) return error("pose tolerance must be >= 0");
  for (std::size_t m = 0; m < models.size(); ++m)
    if (auto s = check_model(models[m], m, limit); !s) return s.error();

  BrfGpuPass pass;
  pass.max_buffer_bytes_ = limit;
  pass.pose_tolerance_ = options.pose_tolerance;
  if (auto s = pass.build_programs(); !s) return s.error();

  // Model tables, vertices, bases; fields grouped into buffers under the limit.
  ModelData data;
  data.sh_data = sh_rotation_data();
  for (const BrfGpuModel& model : models) pass.add_model(model, limit, data);
  pass.upload_models(models, data);
  if (glGetError() == GL_OUT_OF_MEMORY) return error("out of GPU memory uploading the models");
  return pass;
}

engine::Status BrfGpuPass::build_programs() {
  for (auto [program, file] :
       {std::pair{&programs_.phi, "brf_phi.comp.glsl"}, std::pair{&programs_.fit, "brf_fit.comp.glsl"},
        std::pair{&programs_.gather, "brf_gather.comp.glsl"},
        std::pair{&programs_.static_gather, "brf_static_gather.comp.glsl"}}) {
    auto built = build(file);
    if (!built) return built.error();
    *program = std::move(built).value();
  }
  auto built = engine::ShaderProgramBuilder(gi_shader_files())
                   .define("BRF_GLOSSY_RECEIVER 1")
                   .stage(engine::ShaderStage::Compute, "brf_phi.comp.glsl")
                   .build();
  if (!built) return built.error();
  programs_.phi_glossy = std::move(built).value();
  auto lod = engine::ShaderProgramBuilder(gi_shader_files())
                 .define("BRF_LOD_ROWS 1")
                 .stage(engine::ShaderStage::Compute, "brf_phi.comp.glsl")
                 .build();
  if (!lod) return lod.error();
  programs_.phi_lod = std::move(lod).value();
  return {};
}

void BrfGpuPass::add_model(const BrfGpuModel& model, std::size_t limit, ModelData& data) {
  const BasisRadianceField& f = *model.field;
  GpuModel g;
  g.centre_inner = glm::vec4(f.centre, f.inner_radius);
  g.outer_radius = f.outer_radius;
  const BrfBox box = brf_object_box(*model.mesh);
  g.box_lo = glm::vec4(box.lo, 0.0f);
  g.box_hi = glm::vec4(box.hi, 0.0f);
  g.spheres = u32(static_cast<std::size_t>(f.spheres));
  g.face_resolution = u32(static_cast<std::size_t>(f.face_resolution));
  g.sh_bands = u32(static_cast<std::size_t>(f.sh_bands));
  g.basis_count = u32(static_cast<std::size_t>(model.basis->basis_count));
  g.vertex_offset = u32(data.vertices.size() / 2);
  g.vertex_count = u32(model.mesh->positions.size());
  g.psi_offset = u32(data.psi.size());
  g.ainv_offset = u32(data.a_inverse.size());
  std::vector<std::size_t>& groups = data.field_group_bytes;
  if (groups.empty() || groups.back() + gpu_field_bytes(f) > limit) groups.push_back(0);
  g.field_buffer = u32(groups.size() - 1);
  g.terms = u32(static_cast<std::size_t>(f.terms));
  g.field_offset = u32(groups.back() / sizeof(float));
  groups.back() += gpu_field_bytes(f);
  data.table.push_back(g);
  for (std::size_t j = 0; j < model.mesh->positions.size(); ++j) {
    data.vertices.emplace_back(model.mesh->positions[j], 1.0f);
    data.vertices.emplace_back(model.mesh->normals[j], 0.0f);
  }
  data.psi.insert(data.psi.end(), model.basis->psi.begin(), model.basis->psi.end());
  data.a_inverse.insert(data.a_inverse.end(), model.basis->a_inverse.begin(), model.basis->a_inverse.end());
  ModelInfo info;
  info.first_vertex = g.vertex_offset;
  info.vertex_count = g.vertex_count;
  info.basis_count = g.basis_count;
  info.terms = g.terms;
  info.field_buffer = g.field_buffer;
  info.outer_radius = f.outer_radius;
  info.field_centre = f.centre;
  info.basis = model.basis;
  info.mesh = model.mesh;
  info.field = model.field;
  info.glossy = model.glossy;
  if (model.glossy != nullptr) {  // lobe SH (local frame), object-space tangent frames (columns t, b, n)
    std::vector<float>& sh_data = data.sh_data;
    info.lobe_offset = u32(sh_data.size());
    sh_data.insert(sh_data.end(), model.glossy->lobe_sh.begin(), model.glossy->lobe_sh.end());
    info.frame_offset = u32(sh_data.size());
    for (const glm::vec3& nrm : model.mesh->normals) {
      const glm::mat3 frame = brf_tangent_frame(nrm);
      for (int c = 0; c < 3; ++c) sh_data.insert(sh_data.end(), {frame[c].x, frame[c].y, frame[c].z});
    }
  }
  if (model.glossy == nullptr) {  // glossy receivers are evaluated in full
    const BrfLodPoints lod = brf_lod_points(*model.mesh);
    if (!lod.empty()) {
      info.lod_point_offset = u32(data.lod_table.size());
      info.lod_point_count = u32(lod.points.size());
      for (std::uint32_t p : lod.points) data.lod_table.emplace_back(p, 0u, 0u, 0u);
      info.lod_entry_offset = u32(data.lod_table.size());
      for (std::size_t j = 0; j < lod.from.size(); ++j) {
        data.lod_table.emplace_back(lod.from[j], 0u);
        data.lod_table.emplace_back(glm::floatBitsToUint(lod.weights[j]), 0u);
      }
    }
  }
  models_.push_back(info);
}

void BrfGpuPass::upload_models(std::span<const BrfGpuModel> models, const ModelData& data) {
  const auto upload_once = [this](const auto& v) {
    using T = typename std::decay_t<decltype(v)>::value_type;
    std::vector<T> padded(v);
    padded.resize(std::max<std::size_t>(padded.size(), (16 + sizeof(T) - 1) / sizeof(T)));
    model_bytes_ += padded.size() * sizeof(T);
    return engine::GlBuffer::create(padded.size() * sizeof(T), padded.data());
  };
  model_table_ = upload_once(data.table);
  model_vertices_ = upload_once(data.vertices);
  psi_ = upload_once(data.psi);
  a_inverse_ = upload_once(data.a_inverse);
  sh_data_ = upload_once(data.sh_data);
  lod_table_ = upload_once(data.lod_table);
  for (std::size_t bytes : data.field_group_bytes) {
    fields_.push_back(engine::GlBuffer::create(std::max<std::size_t>(bytes, 16), nullptr, GL_DYNAMIC_STORAGE_BIT));
    model_bytes_ += std::max<std::size_t>(bytes, 16);
  }
  for (std::size_t m = 0; m < models.size(); ++m) {
    const BasisRadianceField& f = *models[m].field;
    glNamedBufferSubData(fields_[data.table[m].field_buffer].id(),
                         static_cast<GLintptr>(data.table[m].field_offset * sizeof(float)),
                         static_cast<GLsizeiptr>(gpu_field_bytes(f)), gpu_field(f).data());
  }
  if (fields_.empty()) fields_.push_back(engine::GlBuffer::create(16, nullptr, GL_DYNAMIC_STORAGE_BIT));
  for (const engine::GlBuffer& b : fields_) {
    field_textures_.push_back(engine::GlTexture::create(GL_TEXTURE_BUFFER));
    glTextureBuffer(field_textures_.back().id(), GL_RGBA32F, b.id());
  }
  model_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  glTextureBuffer(model_texture_.id(), GL_RGBA32UI, model_table_.id());
  vertex_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  glTextureBuffer(vertex_texture_.id(), GL_RGBA32F, model_vertices_.id());
  job_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  for (engine::GlTexture& t : gather_textures_) t = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  for (engine::GlTexture& t : fit_textures_) t = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  occluder_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  lod_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  glTextureBuffer(lod_texture_.id(), GL_RGBA32UI, lod_table_.id());
  lod_rows_texture_ = engine::GlTexture::create(GL_TEXTURE_BUFFER);
  static_out_.reserve(16);
  static_points_.reserve(16);
}

engine::Status BrfGpuPass::set_static_receivers(std::span<const glm::vec3> positions,
                                                std::span<const glm::vec3> normals, const RayCaster* world) {
  GI_EXPECTS(!programs_.phi.empty(), "BrfGpuPass::set_static_receivers on an empty (default or moved-from) pass");
  if (positions.size() != normals.size())
    return error(std::to_string(positions.size()) + " static receiver positions but " + std::to_string(normals.size()) +
                 " normals");
  if (positions.size() >= (std::size_t{1} << 31)) return error("too many static receivers");
  for (std::size_t t = 0; t < positions.size(); ++t)
    if (!engine::all_finite(positions[t]) || !engine::all_finite(normals[t]))
      return error("static receiver " + std::to_string(t) + " is not finite");
  std::vector<glm::vec4> points;
  points.reserve(2 * positions.size());
  for (std::size_t t = 0; t < positions.size(); ++t) {
    points.emplace_back(positions[t], 1.0f);
    points.emplace_back(normals[t], 0.0f);
  }
  static_points_.upload(points.data(), points.size() * sizeof(glm::vec4));
  static_positions_.assign(positions.begin(), positions.end());
  static_normals_.assign(normals.begin(), normals.end());
  static_world_ = world;
  static_count_ = positions.size();
  static_out_.reserve(static_count_ * sizeof(glm::vec4));
  glClearNamedBufferData(static_out_.buffer.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  static_occlusion_.reserve(std::max<std::size_t>(static_count_, 4) * sizeof(float));
  glClearNamedBufferData(static_occlusion_.buffer.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  for (StaticSlot& s : static_slots_) s = StaticSlot{};
  static_touched_count_ = 0;
  return {};
}

engine::Status BrfGpuPass::reset_layout(std::span<const BrfGpuInstance> instances) {
  const std::size_t n = instances.size();
  std::vector<std::uint32_t> vertex_offsets(n + 1, 0), value_offsets(n + 1, 0), weight_offsets(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const ModelInfo& m = models_[instances[i].model];
    vertex_offsets[i + 1] = vertex_offsets[i] + m.vertex_count;
    value_offsets[i + 1] = value_offsets[i] + m.terms * m.vertex_count;
    weight_offsets[i + 1] = weight_offsets[i] + padded(m.channels());  // rgb vec4 per channel
  }
  if (static_cast<std::size_t>(value_offsets[n]) * sizeof(glm::vec4) > max_buffer_bytes_)
    return error("the instances' vertices exceed the SSBO limit");

  layout_models_.resize(n);
  for (std::size_t i = 0; i < n; ++i) layout_models_[i] = instances[i].model;
  vertex_offsets_ = std::move(vertex_offsets);
  value_offsets_ = std::move(value_offsets);
  weight_offsets_ = std::move(weight_offsets);
  pair_keys_.clear();  // the Phi slots follow the pairs in reach (layout_pairs)
  pairs_.clear();
  phi_floats_ = 0;
  phi_.reserve(0);  // bound even with no pair in reach
  static_slots_.assign(n, StaticSlot{});
  static_touched_count_ = 0;
  const std::size_t value_bytes = static_cast<std::size_t>(value_offsets_[n]) * sizeof(glm::vec4);
  for (Buffer* b : {&incoming_, &gathered_, &indirect_}) b->reserve(value_bytes);
  weights_.reserve(weight_offsets_[n] * sizeof(glm::vec4));
  outputs_.clear();
  output_bytes_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t bytes = std::max<std::size_t>(
        static_cast<std::size_t>(value_offsets_[i + 1] - value_offsets_[i]) * sizeof(glm::vec4), 16);
    outputs_.push_back(engine::GlBuffer::create(bytes, nullptr, GL_DYNAMIC_STORAGE_BIT));
    glClearNamedBufferData(outputs_.back().id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
    output_bytes_ += bytes;
  }
  return {};
}

void BrfGpuPass::dispatch_phi(std::span<const BrfPhiJob> jobs, std::uint32_t kind) {
  const bool static_kind = kind == 1;
  if (jobs.empty()) return;
  // Work groups sorted by program (one-row jobs, glossy receivers) and the source's field
  // buffer: one dispatch per (program, buffer).
  std::vector<glm::uvec2> groups;
  const std::size_t nf = fields_.size();
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(2 * nf, {0u, 0u});
  for (std::size_t v = 0; v < 2; ++v)
    for (std::size_t b = 0; b < nf; ++b) {
      ranges[v * nf + b].first = u32(groups.size());
      for (std::size_t j = 0; j < jobs.size(); ++j) {
        if (models_[jobs[j].source_model].field_buffer != b || (jobs[j].rows > 1) != (v == 1)) continue;
        for (std::uint32_t first = 0; first < jobs[j].point_count; first += kGroupSize)
          groups.emplace_back(u32(j), first);
      }
      ranges[v * nf + b].second = u32(groups.size()) - ranges[v * nf + b].first;
    }
  jobs_.upload(jobs.data(), jobs.size() * sizeof(BrfPhiJob));
  groups_.upload(groups.data(), groups.size() * sizeof(glm::uvec2));

  if (occluders_.buffer.empty()) occluders_.reserve(16);
  glTextureBuffer(job_texture_.id(), GL_RGBA32UI, jobs_.buffer.id());
  glTextureBuffer(occluder_texture_.id(), GL_RGBA32UI, occluders_.buffer.id());
  glBindTextureUnit(kModelTextureUnit, model_texture_.id());
  glBindTextureUnit(kVertexTextureUnit, vertex_texture_.id());
  glBindTextureUnit(kJobTextureUnit, job_texture_.id());
  glBindTextureUnit(kOccluderTextureUnit, occluder_texture_.id());
  glBindTextureUnit(kLodTextureUnit, lod_texture_.id());
  glTextureBuffer(lod_rows_texture_.id(), GL_RGBA32F, phi_.buffer.id());
  glBindTextureUnit(kLodRowsTextureUnit, lod_rows_texture_.id());
  if (kind == 2)  // the representative rows were written as storage by the previous dispatch
    glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  bind(2, static_points_.buffer.id());
  bind(3, static_indices_.buffer.empty() ? static_points_.buffer.id() : static_indices_.buffer.id());
  bind(5, groups_.buffer.id());
  bind(7, static_kind ? static_phi_.buffer.id() : phi_.buffer.id());
  bind(8, sh_data_.id());
  bind(9, static_visibility_.buffer.empty() ? static_points_.buffer.id() : static_visibility_.buffer.id());
  for (std::size_t v = 0; v < 2; ++v) {
    const engine::ShaderProgram& program = kind == 2 ? programs_.phi_lod : v == 0 ? programs_.phi : programs_.phi_glossy;
    const GLuint id = program.id();
    program.use();
    glProgramUniform1ui(id, glGetUniformLocation(id, "u_kind"), kind);
    for (std::size_t b = 0; b < nf; ++b) {
      const auto [first, count] = ranges[v * nf + b];
      if (count == 0) continue;
      glBindTextureUnit(kFieldTextureUnit, field_textures_[b].id());
      glProgramUniform1ui(id, glGetUniformLocation(id, "u_first_group"), first);
      glProgramUniform1ui(id, glGetUniformLocation(id, "u_group_count"), count);
      dispatch_groups(count);
    }
  }
}

engine::Status BrfGpuPass::update_static(std::span<const BrfGpuInstance> instances) {
  const std::vector<std::uint8_t> moved = static_sources_moved(instances);
  if (std::none_of(moved.begin(), moved.end(), [](std::uint8_t m) { return m != 0; })) return {};
  std::size_t total_floats = 0;
  std::vector<std::vector<float>> visibility;
  std::vector<std::vector<std::uint32_t>> inside = static_receivers_inside(instances, moved, visibility, total_floats);
  if (total_floats * sizeof(float) > max_buffer_bytes_)
    return error("static receivers need " + std::to_string(total_floats * sizeof(float)) +
                 " bytes of Phi, above the SSBO limit of " + std::to_string(max_buffer_bytes_));
  relayout_static_phi(instances, moved, inside, visibility, total_floats);
  upload_static_lists(instances);
  return {};
}

std::vector<std::uint8_t> BrfGpuPass::static_sources_moved(std::span<const BrfGpuInstance> instances) {
  const std::size_t n = instances.size();
  stats_.static_sources_reused = 0;
  std::vector<std::uint8_t> moved(n, 0);
  for (std::size_t s = 0; s < n; ++s) {
    StaticSlot& slot = static_slots_[s];
    const glm::mat4& m = instances[s].object_to_world;
    if (slot.valid && same_pose(slot.pose, m, pose_tolerance_)) {
      ++stats_.static_sources_reused;
      continue;
    }
    moved[s] = 1;
  }
  return moved;
}

std::vector<std::vector<std::uint32_t>> BrfGpuPass::static_receivers_inside(std::span<const BrfGpuInstance> instances,
                                                                            std::span<const std::uint8_t> moved,
                                                                            std::vector<std::vector<float>>& visibility,
                                                                            std::size_t& total_floats) {
  // Which receivers lie inside each moved source's outermost sphere (as brf_interreflect tests it).
  const std::size_t n = instances.size();
  std::vector<std::vector<std::uint32_t>> inside(n);
  visibility.assign(n, {});
  std::vector<glm::vec3> pos, nrm;
  for (std::size_t s = 0; s < n; ++s) {
    const ModelInfo& model = models_[instances[s].model];
    if (moved[s] != 0) {
      const glm::mat4& m = instances[s].object_to_world;
      const glm::vec3 centre = glm::vec3(m * glm::vec4(model.field_centre, 1.0f));
      const float scale = glm::length(glm::vec3(m[0]));
      const float reach = model.outer_radius * scale;
      for (std::size_t t = 0; t < static_count_; ++t)
        if (glm::length(static_positions_[t] - centre) <= reach) inside[s].push_back(u32(t));
      visibility[s].assign(inside[s].size(), 1.0f);
      if (static_world_ != nullptr && !inside[s].empty()) {
        const auto t0 = std::chrono::steady_clock::now();
        // What each receiver sees of the source past the static world; those that see
        // nothing are dropped (their Phi would be scaled to 0).
        std::array<glm::vec3, kBrfVisibilityTargets> targets = brf_visibility_targets(brf_object_box(*model.mesh));
        for (glm::vec3& t : targets) t = glm::vec3(m * glm::vec4(t, 1.0f));
        pos.clear();
        nrm.clear();
        for (std::uint32_t t : inside[s]) {
          pos.push_back(static_positions_[t]);
          nrm.push_back(static_normals_[t]);
        }
        brf_static_visibility(*static_world_, targets, pos, nrm, visibility[s]);
        std::size_t kept = 0;
        for (std::size_t k = 0; k < inside[s].size(); ++k)
          if (visibility[s][k] > 0.0f) {
            inside[s][kept] = inside[s][k];
            visibility[s][kept++] = visibility[s][k];
          }
        stats_.static_receivers_hidden += inside[s].size() - kept;
        inside[s].resize(kept);
        visibility[s].resize(kept);
        stats_.static_visibility_ms +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      }
    } else {
      inside[s] = static_slots_[s].receivers;
      visibility[s] = static_slots_[s].visibility;
    }
    total_floats += inside[s].size() * padded(model.channels());
  }
  return inside;
}

void BrfGpuPass::relayout_static_phi(std::span<const BrfGpuInstance> instances, std::span<const std::uint8_t> moved,
                                     std::span<std::vector<std::uint32_t>> inside,
                                     std::span<std::vector<float>> visibility, std::size_t total_floats) {
  // New layout; unmoved sources' Phi is copied over, moved ones are evaluated.
  const std::size_t n = instances.size();
  static_phi_spare_.reserve(total_floats * sizeof(float));
  std::vector<std::uint32_t> indices;
  std::vector<float> vis;
  std::vector<BrfPhiJob> jobs;
  std::uint32_t phi_offset = 0;
  for (std::size_t s = 0; s < n; ++s) {
    StaticSlot& slot = static_slots_[s];
    const ModelInfo& model = models_[instances[s].model];
    const std::size_t count = inside[s].size();
    if (moved[s] == 0 && count > 0)
      glCopyNamedBufferSubData(static_phi_.buffer.id(), static_phi_spare_.buffer.id(),
                               static_cast<GLintptr>(slot.phi_offset * sizeof(float)),
                               static_cast<GLintptr>(phi_offset * sizeof(float)),
                               static_cast<GLsizeiptr>(count * padded(model.channels()) * sizeof(float)));
    slot.index_offset = u32(indices.size());
    slot.phi_offset = phi_offset;
    if (moved[s] != 0) {
      slot.valid = true;
      slot.pose = instances[s].object_to_world;
      slot.receivers = std::move(inside[s]);
      slot.visibility = std::move(visibility[s]);
      const BrfBox box = brf_object_box(*model.mesh);
      slot.occlusion.resize(slot.receivers.size());
      for (std::size_t k = 0; k < slot.receivers.size(); ++k)
        slot.occlusion[k] = slot.visibility[k] * brf_box_form_factor(box, instances[s].object_to_world,
                                                                     static_positions_[slot.receivers[k]],
                                                                     static_normals_[slot.receivers[k]]);
      if (count > 0) {
        BrfPhiJob job;
        job.to_source = glm::inverse(instances[s].object_to_world);
        job.normal_to_source = glm::mat4(glm::mat3(job.to_source));
        job.source_model = instances[s].model;
        job.point_offset = slot.index_offset;
        job.point_count = u32(count);
        job.phi_offset = phi_offset;
        jobs.push_back(job);
      }
    }
    indices.insert(indices.end(), slot.receivers.begin(), slot.receivers.end());
    vis.insert(vis.end(), slot.visibility.begin(), slot.visibility.end());
    phi_offset += u32(count * padded(model.channels()));
  }
  std::swap(static_phi_, static_phi_spare_);
  static_indices_.upload(indices.data(), indices.size() * sizeof(std::uint32_t));
  static_visibility_.upload(vis.data(), vis.size() * sizeof(float));
  dispatch_phi(jobs, 1);
}

void BrfGpuPass::upload_static_lists(std::span<const BrfGpuInstance> instances) {
  // Per touched receiver, its sources in instance order.
  const std::size_t n = instances.size();
  std::vector<std::uint32_t> count(static_count_, 0);
  for (std::size_t s = 0; s < n; ++s)
    for (std::uint32_t t : static_slots_[s].receivers) ++count[t];
  std::vector<glm::uvec4> touched;
  std::vector<std::uint32_t> next(static_count_, 0);
  std::uint32_t first = 0;
  for (std::size_t t = 0; t < static_count_; ++t) {
    if (count[t] == 0) continue;
    touched.emplace_back(u32(t), first, count[t], 0u);
    next[t] = first;
    first += count[t];
  }
  std::vector<glm::uvec4> entries(first);
  for (std::size_t s = 0; s < n; ++s) {
    const StaticSlot& slot = static_slots_[s];
    const std::uint32_t nb = padded(models_[instances[s].model].channels());
    for (std::size_t k = 0; k < slot.receivers.size(); ++k)
      entries[next[slot.receivers[k]]++] =
          glm::uvec4(weight_offsets_[s], (slot.phi_offset + u32(k) * nb) / 4, nb / 4, u32(s));
  }
  static_touched_.upload(touched.data(), touched.size() * sizeof(glm::uvec4));
  // The objects' occlusion of the baked light, summed per receiver in instance order.
  std::vector<float> occlusion(std::max<std::size_t>(static_count_, 1), 0.0f);
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t k = 0; k < static_slots_[s].receivers.size(); ++k)
      occlusion[static_slots_[s].receivers[k]] += static_slots_[s].occlusion[k];
  for (float& o : occlusion) o = std::min(o, 1.0f);
  static_occlusion_.upload(occlusion.data(), occlusion.size() * sizeof(float));
  static_entries_.upload(entries.data(), entries.size() * sizeof(glm::uvec4));
  static_touched_count_ = u32(touched.size());
}

/// run()'s CPU-side frame: the first weights, the culled pairs, the instance table, the live
/// sources per receiver and the Phi jobs of the pairs that moved.
struct BrfGpuPass::FrameData {
  std::vector<glm::vec4> weights;    ///< First bounce's weights, rgb vec4 per channel; pads stay 0.
  std::vector<std::uint8_t> culled;  ///< [source * n + receiver], as brf_pair_culling.
  std::vector<std::uint64_t> in_reach;  ///< Keys source x n + receiver of the pairs in reach, sorted.
  std::vector<GpuInstance> table;
  std::vector<glm::uvec4> live;  ///< (source's first weight vec4, first Phi vec4, C4 / 4, source)
  std::vector<BrfPhiJob> jobs;
  std::vector<GpuOccluder> occluders;  ///< The jobs' occluder records.
  std::vector<BrfPhiJob> lod_jobs;     ///< Kind 2: the level-of-detail pairs' rows from their points'.
  bool occlusion = true;               ///< BrfUpdateSettings::occlusion.
  float lod_distance = 0.0f;           ///< BrfUpdateSettings::lod_distance.
  bool lod_shared = false;             ///< BrfUpdateSettings::lod_shared_visibility.
};

engine::Status BrfGpuPass::run(std::span<const BrfGpuInstance> instances,
                               std::span<const std::vector<glm::vec3>> incoming, const BrfUpdateSettings& settings) {
  GI_EXPECTS(!programs_.phi.empty(), "BrfGpuPass::run on an empty (default or moved-from) pass");
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t n = instances.size();
  if (auto s = check_frame(instances, incoming); !s) return s;
  bool same_layout = layout_models_.size() == n;
  for (std::size_t i = 0; same_layout && i < n; ++i) same_layout = layout_models_[i] == instances[i].model;
  if (!same_layout)
    if (auto s = reset_layout(instances); !s) return s;

  stats_ = Stats{};
  if (n == 0) {
    if (static_count_ > 0) {
      glClearNamedBufferData(static_out_.buffer.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
      glClearNamedBufferData(static_occlusion_.buffer.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
    }
    stats_.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return {};
  }

  FrameData frame;
  frame.occlusion = settings.occlusion;
  frame.lod_distance = settings.lod_distance;
  frame.lod_shared = settings.lod_shared_visibility;
  fit_first_and_cull(instances, incoming, settings.cull_threshold, settings.influence_scale, frame);
  if (auto s = layout_pairs(n, frame); !s) return s;
  plan_pairs(instances, frame);
  occluders_.upload(frame.occluders.data(), frame.occluders.size() * sizeof(GpuOccluder));
  dispatch_phi(frame.jobs, 0);
  dispatch_phi(frame.lod_jobs, 2);
  upload_frame(incoming, frame);
  for (int bounce = 0; bounce < settings.bounces; ++bounce) {
    if (bounce > 0) dispatch_fit(0, n);
    dispatch_gather(n);
  }
  if (static_count_ > 0)
    if (auto s = gather_static(instances); !s) return s;
  copy_outputs(n);
  stats_.cpu_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return {};
}

engine::Status BrfGpuPass::check_frame(std::span<const BrfGpuInstance> instances,
                                       std::span<const std::vector<glm::vec3>> incoming) const {
  const std::size_t n = instances.size();
  if (incoming.size() != n)
    return error("incoming light for " + std::to_string(incoming.size()) + " instances, " + std::to_string(n) +
                 " given");
  if (n >= (std::size_t{1} << 16)) return error("too many instances");
  for (std::size_t i = 0; i < n; ++i) {
    const BrfGpuInstance& inst = instances[i];
    const std::string which = "instance " + std::to_string(i) + ": ";
    if (inst.model >= models_.size())
      return error(which + "model " + std::to_string(inst.model) + " does not exist (" +
                   std::to_string(models_.size()) + " models)");
    if (!engine::all_finite(inst.object_to_world)) return error(which + "non-finite transform");
    const float det = glm::determinant(glm::mat3(inst.object_to_world));
    if (!(std::fabs(det) > 0.0f) || !std::isfinite(det)) return error(which + "singular transform");
    if (!engine::all_finite(inst.albedo)) return error(which + "non-finite albedo");
    if (!engine::all_finite(inst.specular)) return error(which + "non-finite specular colour");
    const ModelInfo& m = models_[inst.model];
    if (incoming[i].size() != static_cast<std::size_t>(m.terms) * m.vertex_count)
      return error(which + "incoming light of " + std::to_string(incoming[i].size()) + " values, the model needs " +
                   std::to_string(m.terms) + " x " + std::to_string(m.vertex_count) + " (terms x vertices)");
    for (const glm::vec3& e : incoming[i])
      if (!engine::all_finite(e)) return error(which + "non-finite incoming light");
  }
  return {};
}

void BrfGpuPass::fit_first_and_cull(std::span<const BrfGpuInstance> instances,
                                    std::span<const std::vector<glm::vec3>> incoming, float cull_threshold,
                                    float influence_scale, FrameData& frame) const {
  // First weights and pair culling on the CPU, exactly as brf_interreflect decides them.
  const std::size_t n = instances.size();
  std::vector<BrfObject> objects(n);
  std::vector<std::array<std::vector<float>, 3>> first_weights(n);
  std::vector<glm::vec3> light;
  frame.weights.assign(weight_offsets_[n], glm::vec4(0.0f));  // pads stay 0
  for (std::size_t i = 0; i < n; ++i) {
    const ModelInfo& m = models_[instances[i].model];
    objects[i] = {
        m.mesh, m.basis, m.field, instances[i].object_to_world, instances[i].albedo, m.glossy, instances[i].specular};
    light.resize(incoming[i].size());  // reflect() of brf_runtime.cpp: albedo x E_0, specular x E_k
    for (std::size_t j = 0; j < light.size(); ++j)
      light[j] = (j < m.vertex_count ? instances[i].albedo : instances[i].specular) * incoming[i][j];
    first_weights[i] = brf_fit_rgb(*m.basis, light);
    for (std::size_t k = 0; k < m.channels(); ++k)
      frame.weights[weight_offsets_[i] + k] =
          glm::vec4(first_weights[i][0][k], first_weights[i][1][k], first_weights[i][2][k], 0.0f);
  }
  // As brf_interreflect: the influence grid, then the bounds of the pairs inside (threshold > 0 or NaN).
  frame.culled = brf_pair_culling(objects, first_weights, cull_threshold, influence_scale);
  // The pairs that hold a Phi slot: those in reach, culled by their bound or not.
  const std::vector<std::uint8_t> outside = brf_pair_influence(objects, influence_scale);
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t r = 0; r < n; ++r)
      if (outside[s * n + r] == 0) frame.in_reach.push_back(std::uint64_t{s} * n + r);
}

engine::Status BrfGpuPass::layout_pairs(std::size_t instance_count, const FrameData& frame) {
  stats_.pair_slots = frame.in_reach.size();
  const bool lod = frame.lod_distance > 0.0f && std::isfinite(frame.lod_distance);
  if (frame.in_reach == pair_keys_ && lod == layout_lod_) return {};
  // New packed layout in key order; kept pairs keep their state and Phi (copied below).
  const std::size_t n = instance_count;
  std::vector<PairSlot> slots(frame.in_reach.size());
  std::size_t floats = 0;
  struct Copy {
    std::size_t from, to, count;
  };
  std::vector<Copy> copies;
  std::size_t old = 0;
  for (std::size_t k = 0; k < frame.in_reach.size(); ++k) {
    const std::uint64_t key = frame.in_reach[k];
    const std::size_t s = key / n, r = key % n;
    const ModelInfo& mr = models_[layout_models_[r]];
    const std::size_t size =
        static_cast<std::size_t>(mr.vertex_count) * mr.terms * padded(models_[layout_models_[s]].channels());
    while (old < pair_keys_.size() && pair_keys_[old] < key) ++old;
    if (old < pair_keys_.size() && pair_keys_[old] == key && pairs_[old].valid) {
      slots[k] = std::move(pairs_[old]);
      if (!copies.empty() && copies.back().from + copies.back().count == slots[k].phi_offset &&
          copies.back().to + copies.back().count == floats)
        copies.back().count += size;  // runs of kept slots move as one copy
      else
        copies.push_back({slots[k].phi_offset, floats, size});
    }
    slots[k].phi_offset = u32(floats);
    floats += size;
  }
  // With the level of detail on, scratch after the slots for the representative points' rows
  // of receivers with a table (used only in the frames where the pair is far and moved).
  for (std::size_t k = 0; lod && k < frame.in_reach.size(); ++k) {
    const std::size_t s = frame.in_reach[k] / n, r = frame.in_reach[k] % n;
    const ModelInfo& mr = models_[layout_models_[r]];
    slots[k].lod_rows = u32(floats);
    floats += static_cast<std::size_t>(mr.lod_point_count) * padded(models_[layout_models_[s]].channels());
  }
  if (floats * sizeof(float) > max_buffer_bytes_)
    return error(std::to_string(frame.in_reach.size()) + " pairs in reach need " +
                 std::to_string(floats * sizeof(float)) + " bytes of pair Phi, above the SSBO limit of " +
                 std::to_string(max_buffer_bytes_));
  if (copies.empty()) {
    phi_.reserve(floats * sizeof(float));
  } else {
    phi_spare_.reserve(floats * sizeof(float));
    for (const Copy& c : copies)
      glCopyNamedBufferSubData(phi_.buffer.id(), phi_spare_.buffer.id(), static_cast<GLintptr>(c.from * sizeof(float)),
                               static_cast<GLintptr>(c.to * sizeof(float)),
                               static_cast<GLsizeiptr>(c.count * sizeof(float)));
    std::swap(phi_, phi_spare_);
    phi_spare_ = Buffer{};
  }
  pair_keys_ = frame.in_reach;
  layout_lod_ = lod;
  pairs_ = std::move(slots);
  phi_floats_ = floats;
  return {};
}

BrfGpuPass::PairSlot& BrfGpuPass::pair_slot(std::uint64_t key) {
  const auto it = std::lower_bound(pair_keys_.begin(), pair_keys_.end(), key);
  GI_EXPECTS(it != pair_keys_.end() && *it == key, "BrfGpuPass: a live pair without a Phi slot");
  return pairs_[static_cast<std::size_t>(it - pair_keys_.begin())];
}

void BrfGpuPass::plan_pairs(std::span<const BrfGpuInstance> instances, FrameData& frame) {
  // Pairs whose relative pose changed (or never computed): Phi jobs; live sources per receiver.
  const std::size_t n = instances.size();
  frame.table.assign(n, GpuInstance{});
  std::vector<glm::mat4> to_source(n);
  std::vector<glm::mat3> pure_to_source(n);  // uniform scale removed, as brf_basis_irradiance
  std::vector<BrfSphere> spheres(n), inner(n);
  for (std::size_t s = 0; s < n; ++s) {
    to_source[s] = glm::inverse(instances[s].object_to_world);
    const glm::mat3 rot = glm::mat3(to_source[s]);
    pure_to_source[s] = rot / glm::length(rot[0]);
    spheres[s] = brf_bounding_sphere(brf_object_box(*models_[instances[s].model].mesh), instances[s].object_to_world);
    // The innermost field sphere in world space, as brf_interreflect places it (brf_pair_far).
    const glm::mat4& m = instances[s].object_to_world;
    const BasisRadianceField& f = *models_[instances[s].model].field;
    inner[s] = {glm::vec3(m * glm::vec4(f.centre, 1.0f)), f.inner_radius * glm::length(glm::vec3(m[0]))};
  }
  std::vector<std::uint32_t> ids;
  std::vector<glm::mat4> poses;
  for (std::size_t r = 0; r < n; ++r) {
    const ModelInfo& mr = models_[instances[r].model];
    GpuInstance& g = frame.table[r];
    g.albedo = glm::vec4(instances[r].albedo, 0.0f);
    g.specular = glm::vec4(instances[r].specular, 0.0f);
    g.model = instances[r].model;
    g.vertex_offset = vertex_offsets_[r];
    g.vertex_count = mr.vertex_count;
    g.weight_offset = weight_offsets_[r];
    g.value_offset = value_offsets_[r];
    g.terms = mr.terms;
    // A glossy receiver's frames: rot(M_r) x brf_tangent_frame(n), as brf_world_vertices.
    const glm::mat3 receiver_rot =
        glm::mat3(instances[r].object_to_world) / glm::length(glm::vec3(instances[r].object_to_world[0]));
    g.live_first = u32(frame.live.size());
    for (std::size_t s = 0; s < n; ++s) {
      if (s == r) continue;
      if (frame.culled[s * n + r] != 0) {
        ++stats_.pairs_culled;
        continue;
      }
      ++stats_.pairs_evaluated;
      PairSlot& slot = pair_slot(std::uint64_t{s} * n + r);
      const glm::mat4 relative = to_source[s] * instances[r].object_to_world;
      frame.live.emplace_back(weight_offsets_[s], slot.phi_offset / 4,
                              padded(models_[instances[s].model].channels()) / 4, u32(s));
      // The objects in the way and their poses relative to the source: the pair's Phi is
      // kept only while these are unchanged too.
      ids.clear();
      poses.clear();
      if (frame.occlusion)
        for (std::uint32_t o : brf_pair_occluders(spheres, s, r)) {
          ids.push_back(o);
          poses.push_back(to_source[o] * instances[s].object_to_world);
        }
      bool same_occluders = slot.occluders == ids;
      for (std::size_t k = 0; same_occluders && k < ids.size(); ++k)
        same_occluders = same_pose(slot.occluder_poses[k], poses[k], pose_tolerance_);
      // Level of detail (brf_lod.h): diffuse receivers with a table, far from the source.
      const bool far = mr.lod_point_count > 0 && brf_pair_far(spheres[r], inner[s], frame.lod_distance);
      const std::uint8_t lod = far ? (frame.lod_shared ? 2 : 1) : 0;
      if (far) ++stats_.pairs_lod;
      if (slot.valid && same_pose(slot.pose, relative, pose_tolerance_) && same_occluders && slot.lod == lod) {
        ++stats_.pairs_reused;
        continue;
      }
      BrfPhiJob job;
      job.to_source = relative;
      job.normal_to_source = glm::mat4(glm::transpose(glm::inverse(glm::mat3(relative))));
      job.source_model = instances[s].model;
      job.point_offset = mr.first_vertex;  // receiver vertices in the model-vertex buffer
      job.point_count = mr.vertex_count;
      job.phi_offset = slot.phi_offset;
      job.rows = mr.terms;
      if (mr.glossy != nullptr) {
        job.frame_to_source = glm::mat4(pure_to_source[s] * receiver_rot);
        job.frame_offset = mr.frame_offset;
        job.lobe_offset = mr.lobe_offset;
      }
      job.occluder_offset = u32(frame.occluders.size());
      job.occluder_count = u32(ids.size());
      for (std::size_t k = 0; k < ids.size(); ++k) {
        const BrfBox box = brf_object_box(*models_[instances[ids[k]].model].mesh);
        frame.occluders.push_back({poses[k], glm::vec4(box.lo, 0.0f), glm::vec4(box.hi, 0.0f)});
      }
      if (far) {
        job.lod_shared = frame.lod_shared ? 1u : 0u;
        // Kind 2 (after the kind-0 dispatch): every vertex's own side and visibility, its row
        // interpolated from the representative points' rows, which this kind-0 job writes
        // (field part only) into the slot's scratch.
        BrfPhiJob rows = job;
        rows.frame_offset = padded(models_[instances[s].model].channels()) / 4;  // vec4s per row
        rows.lod_points = 1u + mr.lod_entry_offset;
        rows.lod_rows = slot.lod_rows / 4;
        frame.lod_jobs.push_back(rows);
        job.lod_points = 1u + mr.lod_point_offset;
        job.point_count = mr.lod_point_count;
        job.phi_offset = slot.lod_rows;
      }
      frame.jobs.push_back(job);
      slot.valid = true;
      slot.pose = relative;
      slot.lod = lod;
      slot.occluders = ids;
      slot.occluder_poses = poses;
    }
    g.live_count = u32(frame.live.size()) - g.live_first;
  }
}

void BrfGpuPass::upload_frame(std::span<const std::vector<glm::vec3>> incoming, const FrameData& frame) {
  const std::size_t n = incoming.size();
  std::vector<glm::vec4> in4(value_offsets_[n]);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < incoming[i].size(); ++j) in4[value_offsets_[i] + j] = glm::vec4(incoming[i][j], 0.0f);
  incoming_.upload(in4.data(), in4.size() * sizeof(glm::vec4));
  instance_table_.upload(frame.table.data(), frame.table.size() * sizeof(GpuInstance));
  weights_.upload(frame.weights.data(), frame.weights.size() * sizeof(glm::vec4));
  live_.upload(frame.live.data(), frame.live.size() * sizeof(glm::uvec4));
  glClearNamedBufferData(indirect_.buffer.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void BrfGpuPass::dispatch_fit(std::uint32_t mode, std::size_t instance_count) {
  const GLuint id = programs_.fit.id();
  programs_.fit.use();
  glProgramUniform1ui(id, glGetUniformLocation(id, "u_mode"), mode);
  bind(0, instance_table_.buffer.id());
  bind(1, model_table_.id());
  bind(7, weights_.buffer.id());
  // The looped-over inputs through buffer textures (units 0-4; the per-frame buffers may have been re-created).
  const std::pair<GLuint, GLenum> inputs[5] = {{psi_.id(), GL_R32F},
                                               {a_inverse_.id(), GL_R32F},
                                               {incoming_.buffer.id(), GL_RGBA32F},
                                               {gathered_.buffer.id(), GL_RGBA32F},
                                               {indirect_.buffer.id(), GL_RGBA32F}};
  for (GLuint u = 0; u < 5; ++u) {
    glTextureBuffer(fit_textures_[u].id(), inputs[u].second, inputs[u].first);
    glBindTextureUnit(u, fit_textures_[u].id());
  }
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);  // gathered and indirect were written as storage
  glDispatchCompute(u32(instance_count), 1, 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

void BrfGpuPass::dispatch_gather(std::size_t instance_count) {
  const std::uint32_t vertex_total = vertex_offsets_[instance_count];
  const GLuint id = programs_.gather.id();
  programs_.gather.use();
  glProgramUniform1ui(id, glGetUniformLocation(id, "u_instance_count"), u32(instance_count));
  glProgramUniform1ui(id, glGetUniformLocation(id, "u_vertex_total"), vertex_total);
  // Inputs through buffer textures (units 0-3; their buffers may have been re-created).
  const std::pair<const Buffer*, GLenum> inputs[4] = {
      {&instance_table_, GL_RGBA32UI}, {&live_, GL_RGBA32UI}, {&weights_, GL_RGBA32F}, {&phi_, GL_RGBA32F}};
  for (GLuint u = 0; u < 4; ++u) {
    glTextureBuffer(gather_textures_[u].id(), inputs[u].second, inputs[u].first->buffer.id());
    glBindTextureUnit(u, gather_textures_[u].id());
  }
  bind(5, gathered_.buffer.id());
  bind(6, indirect_.buffer.id());
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT);  // Phi and weights were written as storage
  dispatch_groups((vertex_total + kGroupSize - 1) / kGroupSize);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

engine::Status BrfGpuPass::gather_static(std::span<const BrfGpuInstance> instances) {
  if (auto s = update_static(instances); !s) return s;
  dispatch_fit(1, instances.size());
  glClearNamedBufferData(static_out_.buffer.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  const GLuint id = programs_.static_gather.id();
  programs_.static_gather.use();
  glProgramUniform1ui(id, glGetUniformLocation(id, "u_touched_count"), static_touched_count_);
  bind(0, static_touched_.buffer.id());
  bind(1, static_entries_.buffer.id());
  bind(2, instance_table_.buffer.id());
  bind(3, model_table_.id());
  bind(4, weights_.buffer.id());
  bind(5, static_phi_.buffer.id());
  bind(6, static_out_.buffer.id());
  dispatch_groups((static_touched_count_ + kGroupSize - 1) / kGroupSize);
  return {};
}

void BrfGpuPass::copy_outputs(std::size_t instance_count) {
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  for (std::size_t i = 0; i < instance_count; ++i) {
    const std::size_t bytes = static_cast<std::size_t>(value_offsets_[i + 1] - value_offsets_[i]) * sizeof(glm::vec4);
    if (bytes > 0)
      glCopyNamedBufferSubData(indirect_.buffer.id(), outputs_[i].id(),
                               static_cast<GLintptr>(value_offsets_[i] * sizeof(glm::vec4)), 0,
                               static_cast<GLsizeiptr>(bytes));
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
}

std::uint32_t BrfGpuPass::vertex_buffer(std::size_t instance) const {
  GI_EXPECTS(instance < outputs_.size(), "BrfGpuPass::vertex_buffer: instance out of range of the last run");
  return outputs_[instance].id();
}

std::vector<glm::vec3> BrfGpuPass::read_back_vertices(std::size_t instance) const {
  GI_EXPECTS(instance < outputs_.size(), "BrfGpuPass::read_back_vertices: instance out of range of the last run");
  return read_back_vec4s(outputs_[instance].id(), vertex_offsets_[instance + 1] - vertex_offsets_[instance]);
}

std::vector<glm::vec3> BrfGpuPass::read_back_terms(std::size_t instance) const {
  GI_EXPECTS(instance < outputs_.size(), "BrfGpuPass::read_back_terms: instance out of range of the last run");
  return read_back_vec4s(outputs_[instance].id(), value_offsets_[instance + 1] - value_offsets_[instance]);
}

std::vector<glm::vec3> BrfGpuPass::read_back_static() const {
  GI_EXPECTS(!static_out_.buffer.empty(), "BrfGpuPass::read_back_static on an empty (default or moved-from) pass");
  return read_back_vec4s(static_out_.buffer.id(), static_count_);
}

std::vector<float> BrfGpuPass::read_back_static_occlusion() const {
  std::vector<float> out(static_count_, 0.0f);
  if (!out.empty())
    glGetNamedBufferSubData(static_occlusion_.buffer.id(), 0, static_cast<GLsizeiptr>(out.size() * sizeof(float)),
                            out.data());
  return out;
}

std::size_t BrfGpuPass::gpu_bytes() const {
  std::size_t bytes = model_bytes_ + output_bytes_;
  for (const Buffer* b :
       {&static_points_, &instance_table_, &incoming_, &gathered_, &indirect_, &weights_, &phi_, &live_, &jobs_,
        &groups_, &occluders_, &static_occlusion_, &static_indices_, &static_visibility_, &static_phi_, &static_phi_spare_, &static_touched_, &static_entries_, &static_out_})
    bytes += b->bytes;
  return bytes;
}

}  // namespace gi
