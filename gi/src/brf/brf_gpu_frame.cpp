#include <GL/glcorearb.h>
#include <engine/finite.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>

#include "brf/brf_gpu_pass.h"
#include "brf/brf_gpu_pass_detail.h"
#include "brf/brf_lod.h"
#include "brf/brf_visibility.h"

// BrfGpuPass's frame (brf_gpu_pass.h): run() and its stages, the Phi slot table and the
// dispatches; create(), the uploads and the static receivers are in brf_gpu_pass.cpp.

namespace gi {

using namespace brf_gpu_detail;

// Long because it is one dispatch sequence: sort the jobs' work groups by (class,
// field buffer), upload them, bind the buffers, then one dispatch per range the sort produced.
void BrfGpuPass::dispatch_phi(std::span<const BrfPhiJob> jobs, std::uint32_t kind) {
  const bool static_kind = kind == 1;
  if (jobs.empty()) return;
  // Work groups sorted by program (one-row jobs, glossy receivers) and the source's field
  // buffer: one dispatch per (program, buffer). Class 2 (kind 0, pack_lod_points): the
  // level-of-detail jobs' representative points, packed: one table entry (job, point) per
  // invocation, so a work group serves several far pairs (a crate has 24 points: a work
  // group per pair left 40 of its 64 invocations idle).
  std::vector<glm::uvec2> groups;
  const std::size_t nf = fields_.size();
  constexpr std::size_t kClasses = 3;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> ranges(kClasses * nf, {0u, 0u});
  const bool pack = kind == 0 && pack_lod_points_;
  for (std::size_t v = 0; v < kClasses; ++v)
    for (std::size_t b = 0; b < nf; ++b) {
      ranges[v * nf + b].first = u32(groups.size());
      for (std::size_t j = 0; j < jobs.size(); ++j) {
        const bool packed = pack && jobs[j].lod_points != 0 && jobs[j].rows == 1;
        const std::size_t job_class = packed ? 2 : jobs[j].rows > 1 ? 1 : 0;
        if (models_[jobs[j].source_model].field_buffer != b || job_class != v) continue;
        if (packed)
          for (std::uint32_t point = 0; point < jobs[j].point_count; ++point) groups.emplace_back(u32(j), point);
        else
          for (std::uint32_t first = 0; first < jobs[j].point_count; first += kGroupSize)
            groups.emplace_back(u32(j), first);
      }
      ranges[v * nf + b].second = u32(groups.size()) - ranges[v * nf + b].first;
      if (v == 2) stats_.lod_points_packed += ranges[v * nf + b].second;
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
  for (std::size_t v = 0; v < kClasses; ++v) {
    const engine::ShaderProgram& program = kind == 2 ? programs_.phi_lod
                                           : v == 1  ? programs_.phi_glossy
                                                     : programs_.phi;
    const GLuint id = program.id();
    program.use();
    glProgramUniform1ui(id, glGetUniformLocation(id, "u_kind"), kind);
    if (kind != 2) glProgramUniform1ui(id, glGetUniformLocation(id, "u_packed"), v == 2 ? 1u : 0u);
    for (std::size_t b = 0; b < nf; ++b) {
      const auto [first, count] = ranges[v * nf + b];
      if (count == 0) continue;
      glBindTextureUnit(kFieldTextureUnit, field_textures_[b].id());
      glProgramUniform1ui(id, glGetUniformLocation(id, "u_first_group"), first);
      glProgramUniform1ui(id, glGetUniformLocation(id, "u_group_count"), count);  // packed: invocations
      dispatch_groups(v == 2 ? (count + kGroupSize - 1) / kGroupSize : count);
    }
  }
}

/// run()'s CPU-side frame: the first weights, the culled pairs, the instance table, the live
/// sources per receiver and the Phi jobs of the pairs that moved.
struct BrfGpuPass::FrameData {
  std::vector<glm::vec4> weights;       ///< First bounce's weights, rgb vec4 per channel; pads stay 0.
  std::vector<std::uint8_t> culled;     ///< [source * n + receiver], as brf_pair_culling.
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

engine::Status BrfGpuPass::run(std::span<const BrfInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                               const BrfUpdateSettings& settings) {
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

engine::Status BrfGpuPass::check_frame(std::span<const BrfInstance> instances,
                                       std::span<const std::vector<glm::vec3>> incoming) const {
  const std::size_t n = instances.size();
  if (incoming.size() != n)
    return error("incoming light for " + std::to_string(incoming.size()) + " instances, " + std::to_string(n) +
                 " given");
  if (n >= (std::size_t{1} << 16)) return error("too many instances");
  for (std::size_t i = 0; i < n; ++i) {
    const BrfInstance& inst = instances[i];
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

void BrfGpuPass::fit_first_and_cull(std::span<const BrfInstance> instances,
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
    objects[i] = brf_object(*m.model, instances[i]);
    light.resize(incoming[i].size());  // reflect() of brf_runtime.cpp: albedo x E_0, specular x E_k
    for (std::size_t j = 0; j < light.size(); ++j)
      light[j] = (j < m.vertex_count ? instances[i].albedo : instances[i].specular) * incoming[i][j];
    first_weights[i] = brf_fit_rgb(m.model->basis, light);
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

namespace {

/// layout_pairs' refusal: the pairs in reach need more Phi than the budget (or the SSBO limit) allows.
std::string phi_over_limit(std::size_t pairs, std::size_t bytes, std::size_t limit, std::size_t buffer_limit) {
  return std::to_string(pairs) + " pairs in reach need " + std::to_string(bytes) + " bytes of pair Phi, above " +
         (limit < buffer_limit ? "the budget of " : "the SSBO limit of ") + std::to_string(limit);
}

}  // namespace

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
  stats_.phi_bytes_needed = floats * sizeof(float);
  if (floats * sizeof(float) > phi_limit_bytes_)
    return error(phi_over_limit(frame.in_reach.size(), floats * sizeof(float), phi_limit_bytes_, max_buffer_bytes_));
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

namespace {

/// Per instance, what plan_pairs derives from its pose.
struct FramePoses {
  std::vector<glm::mat4> to_source;       ///< inverse(M)
  std::vector<glm::mat3> pure_to_source;  ///< its rotation, uniform scale removed, as brf_basis_irradiance
  std::vector<BrfSphere> spheres;         ///< bounding spheres (world space)
  std::vector<BrfSphere> inner;           ///< innermost field spheres (world space)
};

}  // namespace

void BrfGpuPass::queue_phi_job(std::span<const BrfInstance> instances, std::size_t s, std::size_t r,
                               const PairSlot& slot, const glm::mat4& relative, const glm::mat3& frame_to_source,
                               std::span<const std::uint32_t> occluders, std::span<const glm::mat4> occluder_poses,
                               bool far, FrameData& frame) const {
  const ModelInfo& mr = models_[instances[r].model];
  BrfPhiJob job;
  job.to_source = relative;
  job.normal_to_source = glm::mat4(glm::transpose(glm::inverse(glm::mat3(relative))));
  job.source_model = instances[s].model;
  job.point_offset = mr.first_vertex;  // receiver vertices in the model-vertex buffer
  job.point_count = mr.vertex_count;
  job.phi_offset = slot.phi_offset;
  job.rows = mr.terms;
  if (mr.model->glossy) {
    job.frame_to_source = glm::mat4(frame_to_source);
    job.frame_offset = mr.frame_offset;
    job.lobe_offset = mr.lobe_offset;
  }
  job.occluder_offset = u32(frame.occluders.size());
  job.occluder_count = u32(occluders.size());
  for (std::size_t k = 0; k < occluders.size(); ++k) {
    const BrfBox& box = models_[instances[occluders[k]].model].box;
    frame.occluders.push_back({occluder_poses[k], glm::vec4(box.lo, 0.0f), glm::vec4(box.hi, 0.0f)});
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
}

// Long because it is one walk over the (source, receiver) pairs deciding whether each
// pair's Phi is reused or queued; the frame's poses and the pair slot's state are read and set together.
void BrfGpuPass::plan_pairs(std::span<const BrfInstance> instances, FrameData& frame) {
  // Pairs whose relative pose changed (or never computed): Phi jobs; live sources per receiver.
  const std::size_t n = instances.size();
  frame.table.assign(n, GpuInstance{});
  FramePoses fp{std::vector<glm::mat4>(n), std::vector<glm::mat3>(n), std::vector<BrfSphere>(n),
                std::vector<BrfSphere>(n)};
  for (std::size_t s = 0; s < n; ++s) {
    fp.to_source[s] = glm::inverse(instances[s].object_to_world);
    const glm::mat3 rot = glm::mat3(fp.to_source[s]);
    fp.pure_to_source[s] = rot / glm::length(rot[0]);
    fp.spheres[s] = brf_bounding_sphere(models_[instances[s].model].box, instances[s].object_to_world);
    // The innermost field sphere in world space, as brf_interreflect places it (brf_pair_far).
    const glm::mat4& m = instances[s].object_to_world;
    const BasisRadianceField& f = models_[instances[s].model].model->field;
    fp.inner[s] = {glm::vec3(m * glm::vec4(f.centre, 1.0f)), f.inner_radius * glm::length(glm::vec3(m[0]))};
  }
  std::vector<std::uint32_t> ids;
  std::vector<glm::mat4> poses;
  for (std::size_t r = 0; r < n; ++r) {
    const ModelInfo& mr = models_[instances[r].model];
    GpuInstance& g = frame.table[r];
    g.albedo = glm::vec4(instances[r].albedo, 0.0f);
    g.specular = instances[r].specular;
    g.gather_first = gather_offsets_[r];
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
      const glm::mat4 relative = fp.to_source[s] * instances[r].object_to_world;
      frame.live.emplace_back(weight_offsets_[s], slot.phi_offset / 4,
                              padded(models_[instances[s].model].channels()) / 4, u32(s));
      // The objects in the way and their poses relative to the source: the pair's Phi is
      // kept only while these are unchanged too.
      ids.clear();
      poses.clear();
      if (frame.occlusion)
        for (std::uint32_t o : brf_pair_occluders(fp.spheres, s, r)) {
          ids.push_back(o);
          poses.push_back(fp.to_source[o] * instances[s].object_to_world);
        }
      bool same_occluders = slot.occluders == ids;
      for (std::size_t k = 0; same_occluders && k < ids.size(); ++k)
        same_occluders = same_pose(slot.occluder_poses[k], poses[k], pose_tolerance_);
      // Level of detail (brf_lod.h): diffuse receivers with a table, far from the source.
      const bool far = mr.lod_point_count > 0 && brf_pair_far(fp.spheres[r], fp.inner[s], frame.lod_distance);
      const std::uint8_t lod = far ? (frame.lod_shared ? 2 : 1) : 0;
      if (far) ++stats_.pairs_lod;
      if (slot.valid && same_pose(slot.pose, relative, pose_tolerance_) && same_occluders && slot.lod == lod) {
        ++stats_.pairs_reused;
        continue;
      }
      queue_phi_job(instances, s, r, slot, relative, fp.pure_to_source[s] * receiver_rot, ids, poses, far, frame);
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
  const std::uint32_t invocations = gather_offsets_[instance_count];
  const GLuint id = programs_.gather.id();
  programs_.gather.use();
  glProgramUniform1ui(id, glGetUniformLocation(id, "u_instance_count"), u32(instance_count));
  glProgramUniform1ui(id, glGetUniformLocation(id, "u_invocation_total"), invocations);
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
  dispatch_groups((invocations + kGroupSize - 1) / kGroupSize);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
}

}  // namespace gi
