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

}  // namespace

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
  return true;
}

void AntiradianceLighting::upload_delta(const std::vector<glm::vec3>& irradiance, float scale) {
  const std::vector<glm::vec3>& base = region_->baseline();
  std::vector<glm::vec4> d(irradiance.size());
  for (std::size_t l = 0; l < d.size(); ++l)
    d[l] = glm::vec4(scale * irradiance[l] - (l < base.size() ? base[l] : glm::vec3(0.0f)), 0.0f);
  if (!d.empty()) glNamedBufferSubData(delta_.id(), 0, static_cast<GLsizeiptr>(d.size() * sizeof(glm::vec4)), d.data());
}

bool AntiradianceLighting::update() {
  if (!ensure_gpu()) return false;
  bool moved = false;
  for (const auto& [instance, entity] : deforming_) {
    const auto* wt = registry_->try_get<engine::WorldTransform>(entity);
    // NaN or absurd transforms keep the last usable pose (GISystem warns once).
    if (wt != nullptr && !engine::unusable_world_matrix(wt->matrix) &&
        region_->set_instance_transform(instance, wt->matrix))
      moved = true;
  }
  if (!moved) return false;
  const auto t0 = std::chrono::steady_clock::now();
  region_->update(false);  // relink the moved groups, direct light at the elements
  ++stats_.updates;
  if (region_->posed_as_baked()) {
    // Back at the baked pose: the change is 0 (the atlas holds this pose). No solve; the GPU
    // tables keep the last pose's solution for the next warm start.
    glClearNamedBufferData(delta_.id(), GL_R32F, GL_RED, GL_FLOAT, nullptr);
    glFinish();
    record(AntiradianceSolveReport{});
    stats_.last_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
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
  upload_delta(gpu_->irradiance(), report.output_scale);
  glFinish();
  record(report);
  stats_.last_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
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
  glBindImageTexture(0, out_texture, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glBindImageTexture(1, base_texture, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
  const std::uint32_t groups = (blend_count_ + kGroupSize - 1) / kGroupSize;
  const std::uint32_t gx = std::min<std::uint32_t>(groups, 65535u);
  glDispatchCompute(gx, (groups + gx - 1) / gx, 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT |
                  GL_FRAMEBUFFER_BARRIER_BIT | GL_PIXEL_BUFFER_BARRIER_BIT);
}

}  // namespace gi
