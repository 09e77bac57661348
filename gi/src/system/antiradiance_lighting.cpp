#include "system/antiradiance_lighting.h"

#include <GL/glcorearb.h>

#include <engine/components.h>
#include <engine/runtime_limits.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <limits>
#include <string>

#include "bundle/atlas_layout_file.h"
#include "gpu/gi_shaders.h"

namespace gi {

namespace {

using TexelBlend = AntiradianceLighting::TexelBlendHost;
static_assert(sizeof(TexelBlend) == 48, "must match TexelBlend in antiradiance_composite.comp.glsl (std430)");

constexpr std::uint32_t kGroupSize = 64;

// Stored blends name texels inside `layout`, in increasing order (as computed).
bool blends_fit(const std::vector<TexelBlend>& blends, const AtlasLayout& layout) {
  const std::uint64_t texels = static_cast<std::uint64_t>(layout.width) * static_cast<std::uint64_t>(layout.height);
  for (std::size_t k = 0; k < blends.size(); ++k)
    if (blends[k].texel >= texels || (k > 0 && blends[k].texel <= blends[k - 1].texel)) return false;
  return true;
}

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

void AntiradianceLighting::create_near_sets(const BakeInput& input) {
  const AntiradianceSettings& s = region_->settings();
  if (!s.near_visibility) return;
  const auto t0 = std::chrono::steady_clock::now();
  const ElementHierarchy& h = region_->hierarchy();
  if (!region_->at_baked_pose())
    near_reason_ = "the scene's deforming nodes are not at the baked pose (the near sets' zero is that pose)";
  else if (h.corners.size() != 3 * h.nodes.size())
    near_reason_ = "the bake holds no element triangles to trace against";
  const NearDoorVisibilitySettings ns = near_door_settings(s);
  for (std::uint32_t door : h.deforming_instances) {
    if (!near_reason_.empty()) break;
    auto near = NearDoorVisibility::create(input, *region_, door, ns);
    if (!near) {
      near_reason_ = near.error().to_string();
      break;
    }
    NearSet set{door, std::make_unique<NearDoorVisibility>(std::move(near).value())};
    if (set.visibility->receivers() > 0) near_.push_back(std::move(set));
  }
  if (!near_reason_.empty()) {
    near_.clear();
    stats_.near_fell_back = true;
    if (log_) log_(LogLevel::Warning, "antiradiance: near-door visibility off, antiradiance alone: " + near_reason_);
    return;
  }
  stats_.near_visibility = !near_.empty();
  near_owner_.assign(h.leaf_count(), -1);
  for (std::size_t k = 0; k < near_.size(); ++k) {
    const std::vector<char>& receivers = near_[k].visibility->receiver_mask();
    for (std::size_t l = 0; l < near_owner_.size() && l < receivers.size(); ++l)
      if (receivers[l] && near_owner_[l] < 0) near_owner_[l] = static_cast<std::int32_t>(k);
  }
  for (const NearSet& n : near_) {
    stats_.near_receivers += n.visibility->receivers();
    stats_.near_table_bytes += n.visibility->table_bytes();
  }
  stats_.near_load_ms = ms_since(t0);
}

engine::Result<std::unique_ptr<AntiradianceLighting>> AntiradianceLighting::create(AntiradianceBake bake,
                                                                                   const BakeInput& input,
                                                                                   const AtlasLayout& layout,
                                                                                   const engine::Registry& registry,
                                                                                   LogCallback log) {
  // The bake's blends (read with it) serve when they cover this layout and the region sits
  // at its baked pose: they are then what antiradiance_texel_blends computes here.
  std::vector<TexelBlend> stored = std::move(bake.at_baked_pose.blends);
  const bool stored_fit = bake.at_baked_pose.present && bake.at_baked_pose.layout_fingerprint != 0 &&
                          bake.at_baked_pose.layout_fingerprint == atlas_layout_fingerprint(layout) &&
                          blends_fit(stored, layout);
  auto region = AntiradianceRegion::create(input, std::move(bake));
  if (!region) return region.error();
  std::unique_ptr<AntiradianceLighting> a(new AntiradianceLighting());
  a->region_ = std::make_unique<AntiradianceRegion>(std::move(region).value());
  a->registry_ = &registry;
  a->log_ = std::move(log);
  for (std::uint32_t i : a->region_->hierarchy().deforming_instances)
    a->deforming_.emplace_back(i, input.instances[i].entity);
  std::vector<TexelBlend> blends = stored_fit && a->region_->at_baked_pose()
                                       ? std::move(stored)
                                       : antiradiance_texel_blends(a->region_->hierarchy(), input, layout);
  a->blend_count_ = static_cast<std::uint32_t>(blends.size());
  a->width_ = layout.width;
  a->height_ = layout.height;
  a->stats_.elements = a->region_->hierarchy().nodes.size();
  a->stats_.covered_texels = blends.size();
  a->stats_.links = a->region_->links().links.size();
  a->blends_host_ = std::move(blends);  // uploaded on the first frame (GL context current)
  a->create_near_sets(input);           // after the region's first direct light (at create)
  return a;
}

bool AntiradianceLighting::ensure_gpu() {
  if (!disabled_.empty()) return false;
  if (gpu_) return true;
  auto program = engine::ShaderProgramBuilder(gi_shader_files())
                     .stage(engine::ShaderStage::Compute, "antiradiance_composite.comp.glsl")
                     .build();
  if (!program) {
    disabled_ = program.error().to_string();
    return false;
  }
  auto gpu = AntiradianceGpuPass::create(region_->hierarchy(), region_->bins(), region_->links());
  if (!gpu) {
    disabled_ = gpu.error().to_string();
    return false;
  }
  program_ = std::move(program).value();
  gpu_.emplace(std::move(gpu).value());
  blends_ = engine::GlBuffer::create();
  glNamedBufferData(blends_.id(),
                    static_cast<GLsizeiptr>(std::max<std::size_t>(blends_host_.size(), 1) * sizeof(TexelBlend)),
                    nullptr, GL_STATIC_DRAW);
  if (!blends_host_.empty())
    glNamedBufferSubData(blends_.id(), 0, static_cast<GLsizeiptr>(blends_host_.size() * sizeof(TexelBlend)),
                         blends_host_.data());
  delta_ = engine::GlBuffer::create();
  glNamedBufferData(delta_.id(),
                    static_cast<GLsizeiptr>(std::max<std::size_t>(region_->hierarchy().leaf_count(), 1) * 16), nullptr,
                    GL_DYNAMIC_DRAW);
  glClearNamedBufferData(delta_.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);  // baked pose: no change
  std::vector<glm::vec4> zero = leaf_baseline();
  zero.resize(std::max<std::size_t>(zero.size(), 1));
  baseline_ = engine::GlBuffer::create();
  glNamedBufferData(baseline_.id(), static_cast<GLsizeiptr>(zero.size() * sizeof(glm::vec4)), zero.data(),
                    GL_STATIC_DRAW);
  return true;
}

std::vector<glm::vec4> AntiradianceLighting::leaf_baseline() const {
  std::vector<glm::vec4> out(region_->hierarchy().leaf_count(), glm::vec4(0.0f));
  for (std::size_t l = 0; l < out.size() && l < region_->baseline().size(); ++l)
    out[l] = glm::vec4(region_->baseline()[l], 0.0f);
  for (std::size_t l = 0; l < out.size() && l < near_owner_.size(); ++l) {
    if (near_owner_[l] < 0) continue;
    const std::vector<glm::vec3>& zero = near_[static_cast<std::size_t>(near_owner_[l])].visibility->baseline();
    if (l < zero.size()) out[l] = glm::vec4(zero[l], 1.0f);
  }
  return out;
}

void AntiradianceLighting::near_change(const std::vector<std::pair<std::uint32_t, glm::mat4>>& moved) {
  // The receivers gather from every leaf, the others held at this GPU solve.
  region_->adopt_irradiance(solved_);
  for (std::size_t k = 0; k < near_.size(); ++k) {
    NearSet& n = near_[k];
    // Every moved instance, so each set's ray caster sees every door where it is now.
    std::vector<glm::vec3> e;
    for (const auto& [instance, m] : moved) {
      e = n.visibility->move(*region_, instance, m);
      stats_.near_ms += n.visibility->last_update_ms() + n.visibility->last_solve_ms();
      stats_.near_rays += n.visibility->last_rays();
      stats_.near_pairs += n.visibility->last_pairs();
    }
    stats_.near_iterations = std::max(stats_.near_iterations, n.visibility->last_iterations());
    const std::vector<glm::vec3>& zero = n.visibility->baseline();
    for (std::size_t l = 0; l < leaf_change_.size() && l < e.size() && l < near_owner_.size(); ++l)
      if (near_owner_[l] == static_cast<std::int32_t>(k))
        leaf_change_[l] = e[l] - zero[l];  // against the near set's own baked pose
  }
}

void AntiradianceLighting::upload_change(const std::vector<std::pair<std::uint32_t, glm::mat4>>& moved) {
  const std::vector<glm::vec3>& base = region_->baseline();
  leaf_change_.assign(solved_.size(), glm::vec3(0.0f));
  for (std::size_t l = 0; l < solved_.size(); ++l)
    leaf_change_[l] = solved_[l] - (l < base.size() ? base[l] : glm::vec3(0.0f));
  clear_near_stats();
  if (!near_.empty()) near_change(moved);
  std::vector<glm::vec4> d(leaf_change_.size());
  for (std::size_t l = 0; l < d.size(); ++l) d[l] = glm::vec4(leaf_change_[l], 0.0f);
  if (!d.empty()) glNamedBufferSubData(delta_.id(), 0, static_cast<GLsizeiptr>(d.size() * sizeof(glm::vec4)), d.data());
}

void AntiradianceLighting::clear_near_stats() {
  stats_.near_ms = 0.0;
  stats_.near_rays = stats_.near_pairs = 0;
  stats_.near_iterations = 0;
}

bool AntiradianceLighting::update() {
  if (!ensure_gpu()) return false;
  std::vector<std::pair<std::uint32_t, glm::mat4>> moved;
  for (const auto& [instance, entity] : deforming_) {
    const auto* wt = registry_->try_get<engine::WorldTransform>(entity);
    // NaN or absurd transforms keep the last usable pose (GISystem warns once).
    if (wt != nullptr && !engine::unusable_world_matrix(wt->matrix) &&
        region_->set_instance_transform(instance, wt->matrix))
      moved.emplace_back(instance, wt->matrix);
  }
  if (moved.empty()) return false;
  const auto t0 = std::chrono::steady_clock::now();
  region_->update(false);  // relink the moved groups, direct light at the elements
  ++stats_.updates;
  if (region_->posed_as_baked()) {
    // Back at the baked pose: the change is 0 (the atlas holds this pose). No solve; the GPU
    // tables keep the last pose's solution for the next warm start, the near sets their
    // couplings of the last pose (their next move recomputes what the door crossed since).
    glClearNamedBufferData(delta_.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
    glFinish();
    leaf_change_.assign(region_->hierarchy().leaf_count(), glm::vec3(0.0f));
    clear_near_stats();
    record(AntiradianceSolveReport{});
    stats_.last_ms = ms_since(t0);
    return true;
  }
  if (engine::Status st = gpu_->set_links(region_->links()); !st) {
    disabled_ = st.error().to_string();
    return false;
  }
  const bool warm = region_->settings().warm_start && gpu_warm_startable_;
  const AntiradianceSolveReport report =
      run_antiradiance(*gpu_, region_->direct(), region_->settings(), region_->hierarchy(),
                       warm ? AntiradianceStart::Warm : AntiradianceStart::Cold);
  // As the CPU region: only a converged solve starts the next (AntiradianceRegion::update).
  gpu_warm_startable_ = report.converged && !report.diverged && report.output_scale == 1.0f;
  solved_ = gpu_->irradiance();
  for (glm::vec3& v : solved_) v *= report.output_scale;
  upload_change(moved);
  glFinish();
  record(report);
  stats_.last_ms = ms_since(t0);
  return true;
}

void AntiradianceLighting::record(const AntiradianceSolveReport& report) {
  stats_.relinked_elements = region_->counters().relinked_elements;
  stats_.links = region_->counters().links;
  stats_.warm = report.warm;
  stats_.fell_back = report.fell_back;
  stats_.iterations = report.iterations;
  stats_.residual = report.residual;
  stats_.unconverged = report.budget_exhausted;
  if (report.budget_exhausted) {
    ++stats_.unconverged_updates;
    if (log_)
      log_(LogLevel::Warning, "antiradiance: the solve did not converge in " + std::to_string(report.iterations) +
                                  " iterations (residual " + std::to_string(report.residual) + ", tolerance " +
                                  std::to_string(region_->settings().residual_tolerance) +
                                  "); the door's change shows the last iterate");
  }
}

void AntiradianceLighting::composite(std::uint32_t base_texture, std::uint32_t out_texture) {
  glCopyImageSubData(base_texture, GL_TEXTURE_2D, 0, 0, 0, 0, out_texture, GL_TEXTURE_2D, 0, 0, 0, 0, width_, height_,
                     1);
  if (!ensure_gpu() || blend_count_ == 0) return;
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  program_.use();
  glProgramUniform1ui(program_.id(), glGetUniformLocation(program_.id(), "u_count"), blend_count_);
  glProgramUniform1ui(program_.id(), glGetUniformLocation(program_.id(), "u_width"), static_cast<GLuint>(width_));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, blends_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, delta_.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, baseline_.id());
  glBindImageTexture(0, out_texture, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, base_texture, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  const std::uint32_t groups = (blend_count_ + kGroupSize - 1) / kGroupSize;
  const std::uint32_t gx = std::min<std::uint32_t>(groups, 65535u);
  glDispatchCompute(gx, (groups + gx - 1) / gx, 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_FRAMEBUFFER_BARRIER_BIT | GL_PIXEL_BUFFER_BARRIER_BIT);
}

}  // namespace gi
