#pragma once
// The basis-radiance-field interreflection on the GPU (Iwasaki et al. §5): the compute twin of
// gi::brf_interreflect (brf_runtime.h). Models (mesh, PCA basis, field) are uploaded once; a
// frame uploads the instances' transforms and albedos and the light arriving at their
// vertices, and compute shaders do the rest. Glossy models (BrfModel::glossy) carry K = 1 + glossy terms values per
// vertex ([k x V + j], brf_runtime.h), have fields with K x N channels and get K Phi rows per vertex as receivers:
//   - brf_phi.comp.glsl: the basis irradiance Phi of every (source, receiver) pair whose
//     relative pose changed (or the pose of an object in its way, brf_pair_occluders: Phi is
//     scaled per vertex by how much of the source it sees past their boxes, with
//     BrfUpdateSettings::occlusion), all such pairs in one dispatch (a group table maps work groups
//     to pairs); Phi stays on the GPU between frames, so a frame where nothing moved
//     evaluates no field (a pair culled for a while keeps its slot and is reused if its pose
//     is unchanged when it comes back);
//     Rows k' >= 1 of a glossy receiver are its g_k' cos lobes (BrdfSeparation::lobe_sh) in
//     the vertex's tangent frame, rotated into the source's space by a twin of ShRotation
//     (least squares over sh_rotation_tables(), frames from brf_tangent_frame uploaded per
//     model vertex); they depend on the relative pose only, so the cache holds for them too;
//   - brf_gather.comp.glsl: per bounce, E_r,k'(x_j) = sum_s sum_c w_s,c Phi_sr,(k',c)(x_j),
//     each source's k' = 0 sum clamped at 0 (the irradiance), the glossy terms signed;
//   - brf_fit.comp.glsl: per bounce, the next weights w_k = A^-1 Psi^T (reflect(E_k)) of
//     every instance in one dispatch (albedo x E_0, specular x E_k for k >= 1; the first
//     bounce's weights come from the CPU, which needs them anyway for the pair culling);
//   - static-world receivers: Phi per source (one row of C channels; kept while the source
//     does not move), the fit of each source's total light (all terms) and
//     brf_static_gather.comp.glsl.
// Pair culling is brf_pair_culling on the CPU with the same first weights as the CPU twin, so
// both evaluate the same pairs. Far pairs may use the level of detail (brf_lod.h,
// BrfUpdateSettings::lod_distance): Phi at the receiver's representative points (a kind-0 job
// into scratch after the slots), then brf_phi's BRF_LOD_ROWS variant (kind 2) for every vertex.
// Sources: brf_gpu_pass.cpp (create(), model tables and uploads, static receivers, outputs),
// brf_gpu_frame.cpp (run(): the frame's CPU side, the Phi slot table, the dispatches),
// brf_gpu_pass_detail.h (what both share).
//   auto pass = gi::BrfGpuPass::create(models).value();          // a GL context is current
//   pass.run(instances, incoming, {.bounces = 3});               // then bind pass.vertex_buffer(i)
//
// Precision: float32 throughout; the fits sum in float where the CPU sums in double. Relative
// RMSE against brf_interreflect is ~2e-7 on the test scenes (tests/gi/brf_gpu_pass_test.cpp).
//
// Limits: the Phi slots (receiver vertices V_r x receiver terms K_r x source channels
// C_s = K_s N_s, C_s padded to a multiple of 4) of the pairs in each other's reach
// (brf_pair_influence; every ordered pair with the influence limit off) live in one SSBO, at
// most 128 MiB (or GL_MAX_SHADER_STORAGE_BLOCK_SIZE): run() reports an error above it. A
// diffuse pair of 150 vertices and 16 basis functions takes 9.6 kB: about 13 900 pairs in
// reach, e.g. 200+ crates 1.2 m apart (~40 neighbours each); glossy pairs take K_r K_s times
// that. When the set of pairs in reach changes, the kept slots are copied into a new packed
// layout (a second buffer of the same size for the copy, released after it).
// Fields are grouped into buffers under the same limit (one Phi dispatch per buffer); one
// field above it is an error. A basis has at most 64 functions, a glossy lobe at most
// kMaxGlossyTerms terms (16 values per vertex with the diffuse one).
//
// GL state: create(), run(), set_static_receivers() and the read-backs need the creating
// context current; they change the bound program and shader-storage bindings 0-10 and texture units 0-6.

#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>
#include <engine/result.h>

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "brf/brf_runtime.h"

namespace gi {

class RayCaster;
struct BrfPhiJob;  // one batched Phi evaluation (brf_gpu_pass.cpp)

struct BrfGpuPassOptions {
  /// Largest buffer bound as one SSBO (bytes). 0: GL_MAX_SHADER_STORAGE_BLOCK_SIZE, at most
  /// 128 MiB. Tests set it small to exercise field buffers split by model.
  std::size_t max_buffer_bytes = 0;
  /// Budget of the pairs' Phi (one buffer, bytes). 0: max_buffer_bytes. run() fails above it,
  /// with Stats::phi_bytes_needed set, so the caller may narrow the reach.
  std::size_t phi_budget_bytes = 0;
  /// Two poses (relative source-receiver pose, or a source's world transform) are the same
  /// when no matrix element differs by more than this x (1 + |element|).
  float pose_tolerance = 1e-6f;
  /// Level of detail (brf_lod.h): the far pairs' representative points (24 for a crate) of
  /// several pairs packed into one work group, one invocation per point (a per-invocation
  /// job table), rather than a 64-wide work group per pair. Off: the per-pair work groups (the
  /// same results bit for bit; tests compare the two).
  bool pack_lod_points = true;
};

/// Interreflection between rigid objects on the GPU. Move-only; owns its GL objects
/// (moved-from: empty).
///   auto pass = gi::BrfGpuPass::create(models).value();
///   pass.run(instances, incoming, settings);  // pass.vertex_buffer(i): vec4 per vertex
class BrfGpuPass {
 public:
  /// Compiles the shaders and uploads every model's vertices, basis and field. `models` are
  /// not copied: they must outlive the pass (run() reads their mesh, basis and field for the
  /// first fit and the pair culling). Errors: mesh / basis / field that do not belong together, a field whose terms do
  /// not match the model's glossy lobe (or a glossy field without one), non-finite data, a basis of more than 64
  /// functions, a field larger than the SSBO limit, shader build failure.
  static engine::Result<BrfGpuPass> create(std::span<const BrfModel> models, const BrfGpuPassOptions& options = {});

  BrfGpuPass() = default;
  BrfGpuPass(BrfGpuPass&&) noexcept = default;
  BrfGpuPass& operator=(BrfGpuPass&&) noexcept = default;
  BrfGpuPass(const BrfGpuPass&) = delete;
  BrfGpuPass& operator=(const BrfGpuPass&) = delete;
  ~BrfGpuPass() = default;

  /// Static-world receiver points (world space, unit normals), e.g. light-atlas texels;
  /// uploaded once, replacing earlier ones (empty: none). With `world` (the static scene, not
  /// owned, kept until the next call), each source's bounce at a receiver is scaled by the
  /// fraction of the source it sees past the world (brf_static_visibility, computed on the
  /// CPU when the source moves; receivers that see none of it are left out), as
  /// BrfStaticReceivers::world does for the CPU twin. Errors: sizes differ, non-finite.
  engine::Status set_static_receivers(std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                                      const RayCaster* world = nullptr);

  /// One frame. incoming[i][k x V + j]: light (W/m^2, RGB) arriving at instance i's vertex j
  /// from outside the objects (direct + world): k = 0 the irradiance, k >= 1 (glossy models
  /// only) the g_k-weighted irradiance E_k; V values for a diffuse model, K x V for a glossy
  /// one. Computes what brf_interreflect(objects,
  /// incoming, settings, receivers) computes into vertex_buffer(i) and
  /// static_receiver_buffer(). Errors (nothing is changed): a model index out of range,
  /// incoming sizes that do not match the instances' meshes, non-finite transforms, albedos
  /// or incoming light, Phi slots above the SSBO limit. Ends with a barrier for shader
  /// storage, vertex attribute and buffer reads.
  engine::Status run(std::span<const BrfInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                     const BrfUpdateSettings& settings);

  /// GL buffer of instance i of the last run: vec4 per vertex, xyz = interreflected
  /// irradiance (W/m^2), w = 0. A glossy instance's buffer goes on with the glossy terms
  /// (K x V vec4s, [k x V + j]). Owned by the pass; valid until the instance count changes.
  std::uint32_t vertex_buffer(std::size_t instance) const;
  /// GL buffer: vec4 per static receiver, xyz = irradiance from all objects (W/m^2).
  std::uint32_t static_receiver_buffer() const { return static_out_.buffer.id(); }
  /// GL buffer: float per static receiver, the share of its baked light the objects block
  /// (BrfResult::static_occlusion); computed on the CPU when a source moves.
  std::uint32_t static_occlusion_buffer() const { return static_occlusion_.buffer.id(); }
  /// static_occlusion_buffer() read back.
  std::vector<float> read_back_static_occlusion() const;
  /// vertex_buffer(i) read back (for tests and tools): the irradiance, V values.
  std::vector<glm::vec3> read_back_vertices(std::size_t instance) const;
  /// All terms of instance i, K x V values [k x V + j] as BrfResult::indirect holds them (V
  /// for a diffuse instance).
  std::vector<glm::vec3> read_back_terms(std::size_t instance) const;
  /// static_receiver_buffer() read back.
  std::vector<glm::vec3> read_back_static() const;

  struct Stats {
    std::size_t pairs_evaluated = 0;  ///< Live (not culled) pairs, as BrfResult counts them.
    std::size_t pairs_culled = 0;
    std::size_t pairs_reused = 0;  ///< Live pairs whose Phi was kept (relative pose unchanged).
    std::size_t pairs_lod = 0;     ///< Live pairs whose Phi uses the level of detail (BrfUpdateSettings::lod_distance).
    std::size_t pair_slots = 0;    ///< Pairs in reach holding a Phi slot (culled ones included).
    /// Far pairs' representative points evaluated packed (BrfGpuPassOptions::pack_lod_points).
    std::size_t lod_points_packed = 0;
    std::size_t static_sources_reused = 0;  ///< Sources whose static-receiver Phi was kept.
    /// Static receivers inside a moved source's field that see none of it past the world
    /// (set_static_receivers' world), so get none of its bounce; counted per source.
    std::size_t static_receivers_hidden = 0;
    double static_visibility_ms = 0.0;  ///< CPU time of their visibility rays.
    double cpu_ms = 0.0;                ///< Wall time of the last run() on the CPU.
    /// Bytes the pairs in reach need for their Phi (set even when run() fails because they
    /// are above max_buffer_bytes(): the caller may narrow the reach and run again).
    std::size_t phi_bytes_needed = 0;
  };
  const Stats& stats() const { return stats_; }
  /// GPU memory held by the pass (bytes): models, per-frame buffers, Phi caches.
  std::size_t gpu_bytes() const;
  /// The most the pairs' Phi may take (bytes): BrfGpuPassOptions::phi_budget_bytes, at most
  /// the largest buffer the pass binds.
  std::size_t phi_limit_bytes() const { return phi_limit_bytes_; }

 private:
  /// A GL buffer that grows on demand (glNamedBufferData), never shrinks.
  struct Buffer {
    engine::GlBuffer buffer;
    std::size_t bytes = 0;
    /// Ensures at least `size` bytes (>= 16); contents are lost when it grows.
    void reserve(std::size_t size);
    /// reserve(size) then upload.
    void upload(const void* data, std::size_t size);
  };
  struct ModelInfo {
    std::uint32_t first_vertex = 0;  ///< In the model-vertex buffer.
    std::uint32_t vertex_count = 0;
    std::uint32_t basis_count = 0;
    std::uint32_t terms = 1;         ///< K: 1 + glossy terms.
    std::uint32_t frame_offset = 0;  ///< Glossy: first float of its vertex frames / lobes in sh_data_.
    std::uint32_t lobe_offset = 0;
    std::uint32_t field_buffer = 0;
    float outer_radius = 0.0f;
    glm::vec3 field_centre{0.0f};
    BrfBox box;                       ///< brf_object_box of the mesh (once, not per pair and frame).
    const BrfModel* model = nullptr;  ///< create()'s model: the CPU first fit and pair culling (BrfObject).
    /// Level of detail (brf_lod.h): its representative vertices (lod_point_count uvec4s from
    /// lod_point_offset in lod_table_) and per vertex 2 uvec4s from lod_entry_offset; 0 points: none.
    std::uint32_t lod_point_offset = 0, lod_point_count = 0, lod_entry_offset = 0;
    std::uint32_t channels() const { return terms * basis_count; }
  };
  /// One ordered (source, receiver) pair's cached Phi.
  struct PairSlot {
    std::uint32_t phi_offset = 0;  ///< First float in phi_.
    bool valid = false;            ///< Phi holds the basis irradiance at `pose`.
    glm::mat4 pose{1.0f};          ///< inverse(M_source) x M_receiver when computed.
    std::uint8_t lod = 0;          ///< Computed with the level of detail (brf_lod.h): 1, 2 with shared visibility.
    /// Receivers with a level-of-detail table: first float in phi_ of the representative
    /// points' rows (scratch for one frame, after the slots).
    std::uint32_t lod_rows = 0;
    std::vector<std::uint32_t> occluders;   ///< Instances in the way (brf_pair_occluders) when computed.
    std::vector<glm::mat4> occluder_poses;  ///< inverse(M_occluder) x M_source of each.
  };
  /// One source's static-receiver Phi.
  struct StaticSlot {
    bool valid = false;
    glm::mat4 pose{1.0f};                  ///< M_source when computed.
    std::vector<std::uint32_t> receivers;  ///< Static receivers inside its outermost sphere (that see it).
    std::vector<float> visibility;         ///< Per receiver, the fraction of the source it sees (1 without a world).
    std::vector<float> occlusion;          ///< Per receiver, visibility x the source box's form factor.
    std::uint32_t index_offset = 0;        ///< First entry in static_indices_.
    std::uint32_t phi_offset = 0;          ///< First float in static_phi_.
  };
  struct Programs {
    engine::ShaderProgram phi, phi_glossy, fit, gather, static_gather;  ///< phi_glossy: jobs of K_r > 1 rows
    engine::ShaderProgram phi_lod;  ///< brf_phi's BRF_LOD_ROWS variant: kind 2 (level of detail)
  };

  struct ModelData;  ///< create()'s model tables on the CPU before upload (brf_gpu_pass.cpp).
  struct FrameData;  ///< run()'s per-frame CPU data: first weights, culling, Phi jobs (brf_gpu_pass.cpp).

  // create()'s stages, in order (after the models are checked).
  /// Compiles the compute programs (phi, fit, gather, static gather, then glossy phi).
  engine::Status build_programs();
  /// Appends one checked model to the CPU tables (field grouped under `limit`) and to models_.
  void add_model(const BrfModel& model, std::size_t limit, ModelData& data);
  /// Uploads the tables once, the fields into their buffers; reserves the static buffers.
  void upload_models(std::span<const BrfModel> models, const ModelData& data);

  // run()'s stages, in order (reset_layout() when the instances' models changed).
  /// The frame's checks (sizes, model indices, finite and non-singular data); changes nothing.
  engine::Status check_frame(std::span<const BrfInstance> instances,
                             std::span<const std::vector<glm::vec3>> incoming) const;
  /// The first bounce's weights and the culled pairs on the CPU, as brf_interreflect.
  void fit_first_and_cull(std::span<const BrfInstance> instances, std::span<const std::vector<glm::vec3>> incoming,
                          float cull_threshold, float influence_scale, FrameData& frame) const;
  /// Phi slots for this frame's pairs in reach: when they changed, a new packed layout, the
  /// kept pairs' Phi copied over (through a spare buffer). Errors: slots above the SSBO limit.
  engine::Status layout_pairs(std::size_t instance_count, const FrameData& frame);
  /// The slot of pair key source x n + receiver (it must be in reach).
  PairSlot& pair_slot(std::uint64_t key);
  /// Instance table, live sources per receiver, Phi jobs of moved pairs; updates pairs_, stats_.
  void plan_pairs(std::span<const BrfInstance> instances, FrameData& frame);
  /// plan_pairs' Phi job of pair (s, r) at pose `relative` (its kind-2 job too when `far`),
  /// with the boxes of `occluders` at `occluder_poses` (relative to the source).
  void queue_phi_job(std::span<const BrfInstance> instances, std::size_t s, std::size_t r, const PairSlot& slot,
                     const glm::mat4& relative, const glm::mat3& frame_to_source,
                     std::span<const std::uint32_t> occluders, std::span<const glm::mat4> occluder_poses, bool far,
                     FrameData& frame) const;
  /// Uploads the incoming light, instance table, first weights and live lists; clears indirect_.
  void upload_frame(std::span<const std::vector<glm::vec3>> incoming, const FrameData& frame);
  /// One brf_fit.comp.glsl dispatch over all instances (u_mode 0: last bounce, 1: incoming + indirect).
  void dispatch_fit(std::uint32_t mode, std::size_t instance_count);
  /// One bounce's brf_gather.comp.glsl dispatch over all instance vertices.
  void dispatch_gather(std::size_t instance_count);
  /// Static receivers: update_static(), the fit of all light, brf_static_gather.comp.glsl.
  engine::Status gather_static(std::span<const BrfInstance> instances);
  /// Copies each instance's terms from indirect_ into its vertex buffer; the final barriers.
  void copy_outputs(std::size_t instance_count);

  engine::Status reset_layout(std::span<const BrfInstance> instances);
  /// Static receivers' Phi of the sources that moved, the per-receiver source lists.
  engine::Status update_static(std::span<const BrfInstance> instances);
  // update_static()'s stages, in order.
  /// Per source, 1 when its static-receiver Phi must be evaluated again; counts the reused ones.
  std::vector<std::uint8_t> static_sources_moved(std::span<const BrfInstance> instances);
  /// Per source, the static receivers in its outermost sphere that see it (kept for unmoved
  /// ones) and, in `visibility`, how much of it they see; adds their Phi floats.
  std::vector<std::vector<std::uint32_t>> static_receivers_inside(std::span<const BrfInstance> instances,
                                                                  std::span<const std::uint8_t> moved,
                                                                  std::vector<std::vector<float>>& visibility,
                                                                  std::size_t& total_floats);
  /// Static Phi in its new layout: unmoved sources' copied over, moved ones' evaluated.
  void relayout_static_phi(std::span<const BrfInstance> instances, std::span<const std::uint8_t> moved,
                           std::span<std::vector<std::uint32_t>> inside, std::span<std::vector<float>> visibility,
                           std::size_t total_floats);
  /// Per touched static receiver, its sources in instance order (static_touched_, static_entries_).
  void upload_static_lists(std::span<const BrfInstance> instances);
  /// Evaluates `jobs` (one dispatch per field buffer) into phi_ or, for kind 1 (static
  /// receivers), static_phi_;
  /// kind 2: the level-of-detail pairs' rows from their representative points' (brf_lod.h).
  void dispatch_phi(std::span<const BrfPhiJob> jobs, std::uint32_t kind);

  Programs programs_;
  std::vector<ModelInfo> models_;
  std::size_t max_buffer_bytes_ = 0;
  std::size_t phi_limit_bytes_ = 0;  ///< min(phi_budget_bytes, max_buffer_bytes_)
  float pose_tolerance_ = 1e-6f;
  bool pack_lod_points_ = true;  ///< BrfGpuPassOptions::pack_lod_points.

  // Uploaded once at create().
  engine::GlBuffer model_table_, model_vertices_, psi_, a_inverse_;
  /// SH rotation tables, then the glossy models' lobe SH and object-space vertex frames.
  engine::GlBuffer sh_data_;
  std::vector<engine::GlBuffer> fields_;
  /// Per field buffer, a GL_RGBA32F buffer texture over it: brf_phi.comp.glsl reads the field
  /// through texelFetch (llvmpipe gathers texels as vectors; its SSBO loads loop over the lanes).
  std::vector<engine::GlTexture> field_textures_;
  /// Buffer textures over the model table, the model vertices (both at create()), the Phi jobs
  /// and their occluder records (attached at each dispatch): brf_phi.comp.glsl's read-only data.
  engine::GlTexture model_texture_, vertex_texture_, job_texture_, occluder_texture_;
  /// Level-of-detail tables of every model (ModelInfo::lod_*), uvec4s, and a buffer texture
  /// over them (brf_phi's u_lod); a buffer texture over phi_ (u_lod_rows: the representative rows).
  engine::GlBuffer lod_table_;
  engine::GlTexture lod_texture_, lod_rows_texture_;
  /// brf_gather.comp.glsl's inputs (instance table, live sources, weights, Phi), attached at each dispatch.
  engine::GlTexture gather_textures_[4];
  /// brf_fit.comp.glsl's inputs (Psi, A^-1, incoming, gathered, indirect), attached at each dispatch.
  engine::GlTexture fit_textures_[5];
  std::size_t model_bytes_ = 0;

  // Static receivers.
  Buffer static_points_;
  std::size_t static_count_ = 0;
  std::vector<glm::vec3> static_positions_;  ///< CPU copy for the inside-the-field test.
  std::vector<glm::vec3> static_normals_;    ///< CPU copy for the visibility rays.
  const RayCaster* static_world_ = nullptr;  ///< Occludes sources from static receivers (not owned).

  // Per layout (instance count and models).
  std::vector<std::uint32_t> layout_models_;
  std::vector<std::uint32_t> vertex_offsets_;  ///< Per instance, plus the total.
  std::vector<std::uint32_t> gather_offsets_;  ///< Per instance its first brf_gather invocation, plus the total.
  std::vector<std::uint32_t> value_offsets_;   ///< Per instance (K x V values each), plus the total.
  std::vector<std::uint32_t> weight_offsets_;
  /// The pairs in each other's reach (brf_pair_influence), sorted by key source x n +
  /// receiver, and their Phi slots (packed in key order in phi_): memory follows the pairs in
  /// reach, not n^2. A pair culled by its bound keeps its slot; one that leaves reach loses it.
  std::vector<std::uint64_t> pair_keys_;
  std::vector<PairSlot> pairs_;
  std::size_t phi_floats_ = 0;  ///< Floats of phi_ the slots use (and the level of detail's scratch).
  bool layout_lod_ = false;     ///< The layout has the level of detail's scratch (PairSlot::lod_rows).
  std::vector<StaticSlot> static_slots_;
  std::vector<engine::GlBuffer> outputs_;  ///< Per instance: vec4 per vertex.
  std::size_t output_bytes_ = 0;
  Buffer occluders_;  ///< This frame's Phi jobs' occluder records.
  Buffer instance_table_, incoming_, gathered_, indirect_, weights_, phi_, live_, jobs_, groups_;
  Buffer phi_spare_;         ///< layout_pairs()'s copy target, released after the swap.
  Buffer static_occlusion_;  ///< Per static receiver, the objects' occlusion of its baked light.
  Buffer static_indices_, static_visibility_, static_phi_, static_phi_spare_, static_touched_, static_entries_,
      static_out_;
  std::uint32_t static_touched_count_ = 0;

  Stats stats_;
};

}  // namespace gi
