#include "brf/brf_lighting.h"

#include <GL/glcorearb.h>
#include <engine/components.h>
#include <engine/finite.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>
#include <engine/runtime_limits.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "brf/brf_gpu_pass.h"
#include "brf/spherical_harmonics.h"
#include "bundle/light_signature.h"
#include "gpu/gi_shaders.h"
#include "io/content_hash.h"
#include "raytrace/ray_caster.h"
#include "transport/point_emitters.h"
#include "transport/static_scene.h"

namespace gi {

namespace {

constexpr std::uint32_t kGroupSize = 64;

// Every light together: any change to any of them changes the objects' direct light.
std::uint64_t lights_signature(const engine::Registry& registry) {
  ContentHash h;
  registry.view<engine::Light, engine::WorldTransform>().each(
      [&](engine::Entity e, const engine::Light& l, const engine::WorldTransform& wt) {
        h.add_value(light_signature(e, l, wt));
      });
  return h.value();
}

}  // namespace

struct BrfLighting::Impl {
  const engine::Registry* registry = nullptr;
  std::vector<BrfModel> models;
  // Per instance: its model, albedos and last usable world transform (all zero before the first).
  std::vector<BrfInstance> instances;
  std::vector<engine::Entity> entities;  // who draws each instance
  BrfWorldLink world;
  BrfLightingSettings settings;
  std::unordered_map<std::uint32_t, std::size_t> instance_of;  // entity id -> instance

  // GPU side, created on the first update (the GL context is current then).
  std::optional<BrfGpuPass> pass;
  engine::ShaderProgram sum_program, composite_program;
  GLint sum_count = -1, composite_count = -1, composite_width = -1;  // uniform locations
  GLint sum_first_glossy = -1, sum_specular = -1;
  // Per instance, K x V vec4s ([k x V + j]; K = 1 for a diffuse model): the world's light and
  // what the renderer reads (irradiance, then the glossy terms' E_k x the glossy colour).
  std::vector<engine::GlBuffer> world_light, total;
  std::vector<engine::GlBuffer> lobe_tables;  // per model: its h_k (glossy models only)
  engine::GlBuffer receiver_texels;
  bool gpu_failed = false;

  std::vector<std::vector<glm::vec3>> world_incoming;  // probe light per instance vertex
  std::uint64_t last_lights = 0;
  bool computed = false;
  // The probes' static light (as baked), kept when moving light is added on top of it.
  std::vector<std::array<glm::vec3, 9>> static_probe_sh;
  bool world_light_changed = false;  // set_moving_world_light since the last update
  Stats stats;

  // update()'s stages.
  /// Takes the entities' usable world transforms: per instance 1 when it moved (every
  /// instance on the first update). NaN or absurd transforms keep the last usable pose.
  std::vector<std::uint8_t> take_transforms(bool& any_moved);
  /// Re-reads instance i's world light (K x V values) from the probes and uploads it.
  void read_world_light(std::size_t i, const BrfObject& object, std::size_t values);
  /// Per vertex: world light + interreflected, into `total`.
  void sum_vertices();

  /// Turns the fields off for good, telling the host why. Returns false.
  bool disable(std::string reason) {
    stats.disabled = std::move(reason);
    if (settings.log) settings.log(LogLevel::Warning, "basis radiance fields disabled: " + stats.disabled);
    return false;
  }

  /// The GPU pass over this frame. When the pairs in reach need more Phi than one buffer
  /// holds (hundreds of objects crowded together), the reach (influence_scale) narrows until
  /// they fit, keeping each object's nearest neighbours, and stays narrowed; the host is told
  /// once per narrowing. Any other failure, or a reach below a tenth of the setting, turns
  /// the fields off.
  bool run_pass(std::span<const std::vector<glm::vec3>> incoming) {
    for (;;) {
      engine::Status s = pass->run(instances, incoming, settings.update);
      if (s) return true;
      const std::size_t needed = pass->stats().phi_bytes_needed, limit = pass->phi_limit_bytes();
      const float scale = settings.update.influence_scale;
      if (needed <= limit || !(scale > 0.0f) || scale < 0.1f * stats.influence_scale_setting) {
        gpu_failed = !disable("update failed: " + s.error().to_string());
        return false;
      }
      // Pairs grow about as the reach squared on a floor: aim a little below the limit.
      const float shrink =
          std::clamp(0.95f * std::sqrt(static_cast<float>(limit) / static_cast<float>(needed)), 0.5f, 0.95f);
      settings.update.influence_scale = scale * shrink;
      stats.influence_scale = settings.update.influence_scale;
      ++stats.reach_narrowings;
      if (settings.log)
        settings.log(LogLevel::Warning, "basis radiance fields: the pairs in reach need " + std::to_string(needed) +
                                            " bytes of Phi, above the limit of " + std::to_string(limit) +
                                            ": the reach narrows to x" +
                                            std::to_string(settings.update.influence_scale));
    }
  }

  bool create_gpu() {
    auto p = BrfGpuPass::create(models, {.phi_budget_bytes = settings.phi_budget_bytes});
    auto sum = engine::ShaderProgramBuilder(gi_shader_files())
                   .stage(engine::ShaderStage::Compute, "brf_vertex_sum.comp.glsl")
                   .build();
    auto comp = engine::ShaderProgramBuilder(gi_shader_files())
                    .stage(engine::ShaderStage::Compute, "brf_world_composite.comp.glsl")
                    .build();
    if (!p || !sum || !comp) {
      return disable((!p ? p.error() : !sum ? sum.error() : comp.error()).to_string());
    }
    pass.emplace(std::move(p).value());
    sum_program = std::move(sum).value();
    composite_program = std::move(comp).value();
    sum_count = glGetUniformLocation(sum_program.id(), "u_count");
    sum_first_glossy = glGetUniformLocation(sum_program.id(), "u_first_glossy");
    sum_specular = glGetUniformLocation(sum_program.id(), "u_specular");
    composite_count = glGetUniformLocation(composite_program.id(), "u_count");
    composite_width = glGetUniformLocation(composite_program.id(), "u_atlas_width");
    if (!world.receiver_texels.empty()) {
      if (auto s = pass->set_static_receivers(world.receiver_positions, world.receiver_normals, world.caster.get());
          !s) {
        return disable(s.error().to_string());
      }
      receiver_texels =
          engine::GlBuffer::create(world.receiver_texels.size() * sizeof(std::uint32_t), world.receiver_texels.data());
    }
    for (const BrfModel& model : models) {
      if (!model.glossy) {
        lobe_tables.emplace_back();
        continue;
      }
      // What the renderer draws toward the eye: h rescaled to the lobe's directional albedo.
      const std::vector<float> h = model.glossy->albedo_corrected_h();
      lobe_tables.push_back(engine::GlBuffer::create(h.size() * sizeof(float), h.data(), 0));
    }
    for (const BrfInstance& b : instances) {
      const std::size_t terms = static_cast<std::size_t>(models[b.model].field.terms);
      const std::size_t bytes =
          std::max<std::size_t>(models[b.model].mesh.positions.size() * terms, 1) * sizeof(glm::vec4);
      const std::vector<glm::vec4> zeros(bytes / sizeof(glm::vec4), glm::vec4(0.0f));
      world_light.push_back(engine::GlBuffer::create(bytes, zeros.data(), GL_DYNAMIC_STORAGE_BIT));
      total.push_back(engine::GlBuffer::create(bytes, zeros.data(), 0));
    }
    return true;
  }
};

BrfLighting::BrfLighting(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BrfLighting::~BrfLighting() = default;

engine::Result<std::unique_ptr<BrfLighting>> BrfLighting::create(std::vector<BrfModel> models,
                                                                 std::vector<BrfInstance> instances,
                                                                 std::vector<engine::Entity> entities,
                                                                 const engine::Registry& registry, BrfWorldLink world,
                                                                 BrfLightingSettings settings) {
  for (const BrfModel& m : models)
    if (m.basis.vertex_count != m.mesh.positions.size() || m.field.basis_count != m.basis.basis_count)
      return engine::Error{.location = "basis radiance fields",
                           .message = "model '" + m.name + "': mesh, basis and field do not belong together"};
  if (entities.size() != instances.size())
    return engine::Error{.location = "basis radiance fields",
                         .message = std::to_string(instances.size()) + " instances but " +
                                    std::to_string(entities.size()) + " entities"};
  for (std::size_t i = 0; i < instances.size(); ++i)
    if (instances[i].model >= models.size())
      return engine::Error{.location = "basis radiance fields",
                           .message = "entity " + std::to_string(entities[i].id()) + " uses model " +
                                      std::to_string(instances[i].model) + " of " + std::to_string(models.size())};
  if (world.receiver_positions.size() != world.receiver_texels.size() ||
      world.receiver_normals.size() != world.receiver_texels.size())
    return engine::Error{.location = "basis radiance fields", .message = "static receiver arrays of different sizes"};
  auto impl = std::make_unique<Impl>();
  impl->registry = &registry;
  impl->models = std::move(models);
  impl->instances = std::move(instances);
  impl->entities = std::move(entities);
  impl->world = std::move(world);
  impl->settings = settings;
  for (std::size_t i = 0; i < impl->instances.size(); ++i) {
    impl->instance_of[impl->entities[i].id()] = i;
    impl->instances[i].object_to_world = glm::mat4(0.0f);
    impl->stats.vertices += impl->models[impl->instances[i].model].mesh.positions.size();
  }
  for (const BrfModel& m : impl->models)
    impl->stats.field_bytes += m.field.bytes() + m.basis.psi.size() * sizeof(float);
  impl->stats.instances = impl->instances.size();
  impl->stats.influence_scale = impl->stats.influence_scale_setting = settings.update.influence_scale;
  impl->stats.static_receivers = impl->world.receiver_texels.size();
  impl->world_incoming.resize(impl->instances.size());
  return std::unique_ptr<BrfLighting>(new BrfLighting(std::move(impl)));
}

std::vector<std::uint8_t> BrfLighting::Impl::take_transforms(bool& any_moved) {
  std::vector<std::uint8_t> moved(instances.size(), 0);
  any_moved = false;
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const auto* wt = registry->try_get<engine::WorldTransform>(entities[i]);
    if (wt == nullptr || engine::unusable_world_matrix(wt->matrix)) continue;
    if (!computed || wt->matrix != instances[i].object_to_world) {
      instances[i].object_to_world = wt->matrix;
      moved[i] = 1;
      any_moved = true;
    }
  }
  return moved;
}

void BrfLighting::Impl::read_world_light(std::size_t i, const BrfObject& object, std::size_t values) {
  const BrfWorldVertices v = brf_world_vertices(object);
  const std::size_t nv = v.positions.size();
  world_incoming[i].assign(values, glm::vec3(0.0f));
  if (world.probes)
    for (std::size_t j = 0; j < nv; ++j) {
      world_incoming[i][j] = world.probes->irradiance(v.positions[j], v.normals[j]);
      const BrdfSeparation* glossy = object.glossy;
      if (glossy == nullptr) continue;
      // A glossy vertex's E_k: the probes' radiance against g_k cos, turned from the
      // vertex's frame into the world's.
      std::array<glm::vec3, 9> radiance;
      if (!world.probes->radiance(v.positions[j], radiance)) continue;
      const ShRotation to_world(v.frames[j]);
      std::array<float, kMaxShCoefficients> lobe{};
      for (int k = 1; k <= glossy->terms; ++k) {
        to_world.apply(glossy->lobe_coefficients(k - 1), lobe, 3);
        glm::vec3 e(0.0f);
        for (std::size_t c = 0; c < 9; ++c) e += lobe[c] * radiance[c];
        world_incoming[i][static_cast<std::size_t>(k) * nv + j] = e;
      }
    }
  std::vector<glm::vec4> packed(std::max<std::size_t>(world_incoming[i].size(), 1), glm::vec4(0.0f));
  for (std::size_t j = 0; j < world_incoming[i].size(); ++j) packed[j] = glm::vec4(world_incoming[i][j], 0.0f);
  glNamedBufferSubData(world_light[i].id(), 0, static_cast<GLsizeiptr>(packed.size() * sizeof(glm::vec4)),
                       packed.data());
}

void BrfLighting::Impl::sum_vertices() {
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
  sum_program.use();
  for (std::size_t i = 0; i < instances.size(); ++i) {
    const BrfModel& model = models[instances[i].model];
    const auto vertices = static_cast<std::uint32_t>(model.mesh.positions.size());
    const auto count = vertices * static_cast<std::uint32_t>(model.field.terms);
    glProgramUniform1ui(sum_program.id(), sum_count, count);
    glProgramUniform1ui(sum_program.id(), sum_first_glossy, vertices);
    const glm::vec3 specular = instances[i].specular;
    glProgramUniform3f(sum_program.id(), sum_specular, specular.x, specular.y, specular.z);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, world_light[i].id());
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, pass->vertex_buffer(i));
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, total[i].id());
    glDispatchCompute((count + kGroupSize - 1) / kGroupSize, 1, 1);
  }
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_VERTEX_ATTRIB_ARRAY_BARRIER_BIT);
}

bool BrfLighting::update() {
  Impl& m = *impl_;
  if (m.gpu_failed || m.instances.empty()) return false;
  if (!m.pass && !m.create_gpu()) {
    m.gpu_failed = true;
    return false;
  }
  using Clock = std::chrono::steady_clock;
  const auto t0 = Clock::now();
  // What changed: object transforms (GISystem warns once about unusable ones) and lights.
  bool any_moved = false;
  const std::vector<std::uint8_t> moved = m.take_transforms(any_moved);
  const std::uint64_t lights = lights_signature(*m.registry);
  const bool world_changed = m.world_light_changed;
  m.world_light_changed = false;
  if (m.computed && !any_moved && !world_changed && lights == m.last_lights) {
    ++m.stats.skipped;
    return false;
  }
  m.last_lights = lights;

  std::vector<BrfObject> objects;
  for (const BrfInstance& instance : m.instances) objects.push_back(brf_object(m.models[instance.model], instance));
  // Direct light from every enabled light (static and moving), shadowed by objects and world.
  std::vector<ReferenceLight> all = scene_lights(*m.registry, BakeLights::Static);
  for (ReferenceLight& l : scene_lights(*m.registry, BakeLights::Moving)) all.push_back(l);
  const std::vector<PointEmitter> emitters = light_point_emitters(all, m.settings.area_light_samples, 1);
  std::vector<std::vector<glm::vec3>> incoming = brf_direct_light(objects, emitters, m.world.caster.get());
  // The static world's light, re-read from the probes where an object moved (everywhere when
  // the probes' light changed).
  for (std::size_t i = 0; i < objects.size(); ++i) {
    if (moved[i] != 0 || world_changed) m.read_world_light(i, objects[i], incoming[i].size());
    for (std::size_t j = 0; j < incoming[i].size(); ++j) incoming[i][j] += m.world_incoming[i][j];
  }
  const auto t1 = Clock::now();
  if (!m.run_pass(incoming)) return false;
  m.sum_vertices();
  glFinish();
  const auto t2 = Clock::now();
  const auto& ps = m.pass->stats();
  m.stats.pairs_evaluated = ps.pairs_evaluated;
  m.stats.pairs_culled = ps.pairs_culled;
  m.stats.pairs_reused = ps.pairs_reused;
  m.stats.static_hidden = ps.static_receivers_hidden;
  m.stats.last_visibility_ms = ps.static_visibility_ms;
  m.stats.last_cpu_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  m.stats.last_gpu_ms = std::chrono::duration<double, std::milli>(t2 - t1).count();
  m.stats.gpu_bytes = m.pass->gpu_bytes();
  ++m.stats.updates;
  if (any_moved) ++m.stats.objects_moved;
  if (world_changed) ++m.stats.world_light_changes;
  m.computed = true;
  return true;
}

std::uint32_t BrfLighting::vertex_buffer(engine::Entity e) const {
  const Impl& m = *impl_;
  const auto it = m.instance_of.find(e.id());
  if (it == m.instance_of.end() || it->second >= m.total.size() || !m.computed) return 0;
  return m.total[it->second].id();
}

engine::IndirectLightFrame::VertexRadianceLobes BrfLighting::vertex_lobes(engine::Entity e) const {
  const Impl& m = *impl_;
  const auto it = m.instance_of.find(e.id());
  if (it == m.instance_of.end() || it->second >= m.total.size() || !m.computed) return {};
  const BrfModel& model = m.models[m.instances[it->second].model];
  if (!model.glossy || model.glossy->terms <= 0) return {};
  const int vertices = static_cast<int>(model.mesh.positions.size());
  return {.coefficient_buffer = {m.total[it->second].id()},
          .lobe_buffer = {m.lobe_tables[m.instances[it->second].model].id()},
          .first = vertices,
          .stride = vertices,
          .terms = model.glossy->terms,
          .resolution = model.glossy->resolution};
}

bool BrfLighting::set_moving_world_light(std::span<const std::array<glm::vec3, 9>> radiance_sh) {
  Impl& m = *impl_;
  if (!m.world.probes || radiance_sh.size() != m.world.probes->probe_count()) return false;
  if (m.static_probe_sh.empty()) m.static_probe_sh = m.world.probes->radiance_sh;
  for (std::size_t k = 0; k < radiance_sh.size(); ++k)
    for (std::size_t j = 0; j < 9; ++j) m.world.probes->radiance_sh[k][j] = m.static_probe_sh[k][j] + radiance_sh[k][j];
  m.world_light_changed = true;
  return true;
}

bool BrfLighting::has_static_receivers() const { return !impl_->world.receiver_texels.empty(); }

void BrfLighting::composite_world(std::uint32_t base_texture, std::uint32_t composite_texture) const {
  const Impl& m = *impl_;
  glCopyImageSubData(base_texture, GL_TEXTURE_2D, 0, 0, 0, 0, composite_texture, GL_TEXTURE_2D, 0, 0, 0, 0,
                     m.world.atlas_width, m.world.atlas_height, 1);
  if (!m.pass || m.world.receiver_texels.empty() || !m.computed) return;
  const auto count = static_cast<std::uint32_t>(m.world.receiver_texels.size());
  glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
  m.composite_program.use();
  glProgramUniform1ui(m.composite_program.id(), m.composite_count, count);
  glProgramUniform1ui(m.composite_program.id(), m.composite_width, static_cast<GLuint>(m.world.atlas_width));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, m.receiver_texels.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, m.pass->static_receiver_buffer());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, m.pass->static_occlusion_buffer());
  glBindImageTexture(0, composite_texture, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
  glDispatchCompute((count + kGroupSize - 1) / kGroupSize, 1, 1);
  glMemoryBarrier(GL_TEXTURE_FETCH_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_UPDATE_BARRIER_BIT);
}

const BrfLighting::Stats& BrfLighting::stats() const { return impl_->stats; }

}  // namespace gi
