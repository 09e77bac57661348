#include "brf/brf_gpu_pass.h"

#include <GL/glcorearb.h>
#include <engine/finite.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "brf/brf_gpu_pass_detail.h"
#include "brf/brf_lod.h"
#include "brf/brf_visibility.h"
#include "gpu/gi_shaders.h"

namespace gi {

using namespace brf_gpu_detail;

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

/// create()'s checks of model m (sizes, glossy terms, field settings, limit, finite data).
engine::Status check_model(const BrfModel& model, std::size_t m, std::size_t limit) {
  const std::string which = "model " + std::to_string(m) + ": ";
  const BrfMesh& mesh = model.mesh;
  const BrfBasis& basis = model.basis;
  const BasisRadianceField& f = model.field;
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
  if (!model.glossy && f.terms != 1)
    return error(which + "a glossy field (" + std::to_string(f.terms) + " BRDF terms) but no glossy lobe");
  if (model.glossy) {
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
    return error(which + "field of " + std::to_string(gpu_field_bytes(f)) +
                 " bytes (channels padded to vec4s) is above the SSBO limit of " + std::to_string(limit));
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

engine::Result<BrfGpuPass> BrfGpuPass::create(std::span<const BrfModel> models, const BrfGpuPassOptions& options) {
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
  pass.phi_limit_bytes_ = options.phi_budget_bytes > 0 ? std::min(limit, options.phi_budget_bytes) : limit;
  pass.pose_tolerance_ = options.pose_tolerance;
  pass.pack_lod_points_ = options.pack_lod_points;
  if (auto s = pass.build_programs(); !s) return s.error();

  // Model tables, vertices, bases; fields grouped into buffers under the limit.
  ModelData data;
  data.sh_data = sh_rotation_data();
  for (const BrfModel& model : models) pass.add_model(model, limit, data);
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

// Long because it appends one model to every GPU table at once (model entry, vertices,
// basis, field group, glossy frames, LOD table), each offset taken from a table's size as it goes.
void BrfGpuPass::add_model(const BrfModel& model, std::size_t limit, ModelData& data) {
  const BasisRadianceField& f = model.field;
  GpuModel g;
  g.centre_inner = glm::vec4(f.centre, f.inner_radius);
  g.outer_radius = f.outer_radius;
  const BrfBox box = brf_object_box(model.mesh);
  g.box_lo = glm::vec4(box.lo, 0.0f);
  g.box_hi = glm::vec4(box.hi, 0.0f);
  g.spheres = u32(static_cast<std::size_t>(f.spheres));
  g.face_resolution = u32(static_cast<std::size_t>(f.face_resolution));
  g.sh_bands = u32(static_cast<std::size_t>(f.sh_bands));
  g.basis_count = u32(static_cast<std::size_t>(model.basis.basis_count));
  g.vertex_offset = u32(data.vertices.size() / 2);
  g.vertex_count = u32(model.mesh.positions.size());
  g.psi_offset = u32(data.psi.size());
  g.ainv_offset = u32(data.a_inverse.size());
  std::vector<std::size_t>& groups = data.field_group_bytes;
  if (groups.empty() || groups.back() + gpu_field_bytes(f) > limit) groups.push_back(0);
  g.field_buffer = u32(groups.size() - 1);
  g.terms = u32(static_cast<std::size_t>(f.terms));
  g.field_offset = u32(groups.back() / sizeof(float));
  groups.back() += gpu_field_bytes(f);
  data.table.push_back(g);
  for (std::size_t j = 0; j < model.mesh.positions.size(); ++j) {
    data.vertices.emplace_back(model.mesh.positions[j], 1.0f);
    data.vertices.emplace_back(model.mesh.normals[j], 0.0f);
  }
  data.psi.insert(data.psi.end(), model.basis.psi.begin(), model.basis.psi.end());
  data.a_inverse.insert(data.a_inverse.end(), model.basis.a_inverse.begin(), model.basis.a_inverse.end());
  ModelInfo info;
  info.first_vertex = g.vertex_offset;
  info.vertex_count = g.vertex_count;
  info.basis_count = g.basis_count;
  info.terms = g.terms;
  info.field_buffer = g.field_buffer;
  info.outer_radius = f.outer_radius;
  info.field_centre = f.centre;
  info.box = box;
  info.model = &model;
  if (model.glossy) {  // lobe SH (local frame), object-space tangent frames (columns t, b, n)
    std::vector<float>& sh_data = data.sh_data;
    info.lobe_offset = u32(sh_data.size());
    sh_data.insert(sh_data.end(), model.glossy->lobe_sh.begin(), model.glossy->lobe_sh.end());
    info.frame_offset = u32(sh_data.size());
    for (const glm::vec3& nrm : model.mesh.normals) {
      const glm::mat3 frame = brf_tangent_frame(nrm);
      for (int c = 0; c < 3; ++c) sh_data.insert(sh_data.end(), {frame[c].x, frame[c].y, frame[c].z});
    }
  }
  if (!model.glossy) {  // glossy receivers are evaluated in full
    const BrfLodPoints lod = brf_lod_points(model.mesh);
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

void BrfGpuPass::upload_models(std::span<const BrfModel> models, const ModelData& data) {
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
    const BasisRadianceField& f = models[m].field;
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

engine::Status BrfGpuPass::reset_layout(std::span<const BrfInstance> instances) {
  const std::size_t n = instances.size();
  std::vector<std::uint32_t> vertex_offsets(n + 1, 0), value_offsets(n + 1, 0), weight_offsets(n + 1, 0),
      gather_offsets(n + 1, 0);
  for (std::size_t i = 0; i < n; ++i) {
    const ModelInfo& m = models_[instances[i].model];
    vertex_offsets[i + 1] = vertex_offsets[i] + m.vertex_count;
    gather_offsets[i + 1] = gather_offsets[i] + (m.vertex_count + kGatherVertices - 1) / kGatherVertices;
    value_offsets[i + 1] = value_offsets[i] + m.terms * m.vertex_count;
    weight_offsets[i + 1] = weight_offsets[i] + padded(m.channels());  // rgb vec4 per channel
  }
  if (static_cast<std::size_t>(value_offsets[n]) * sizeof(glm::vec4) > max_buffer_bytes_)
    return error("the instances' vertices exceed the SSBO limit");

  layout_models_.resize(n);
  for (std::size_t i = 0; i < n; ++i) layout_models_[i] = instances[i].model;
  vertex_offsets_ = std::move(vertex_offsets);
  gather_offsets_ = std::move(gather_offsets);
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

engine::Status BrfGpuPass::update_static(std::span<const BrfInstance> instances) {
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

std::vector<std::uint8_t> BrfGpuPass::static_sources_moved(std::span<const BrfInstance> instances) {
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

std::vector<std::vector<std::uint32_t>> BrfGpuPass::static_receivers_inside(std::span<const BrfInstance> instances,
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
        std::array<glm::vec3, kBrfVisibilityTargets> targets = brf_visibility_targets(model.box);
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

void BrfGpuPass::relayout_static_phi(std::span<const BrfInstance> instances, std::span<const std::uint8_t> moved,
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
      const BrfBox box = model.box;
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

void BrfGpuPass::upload_static_lists(std::span<const BrfInstance> instances) {
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

engine::Status BrfGpuPass::gather_static(std::span<const BrfInstance> instances) {
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
        &groups_, &occluders_, &static_occlusion_, &static_indices_, &static_visibility_, &static_phi_,
        &static_phi_spare_, &static_touched_, &static_entries_, &static_out_})
    bytes += b->bytes;
  return bytes;
}

}  // namespace gi
