#include <GL/glcorearb.h>
#include <engine/components.h>
#include <engine/runtime_limits.h>
#include <gi/gi_system.h>
#include <gi/plan.h>

#include <chrono>
#include <sstream>
#include <unordered_set>

#include "bundle/manifest.h"
#include "plan/plan_json.h"
#include "system/method_table.h"
#include "system/sky_visibility.h"

namespace gi {

namespace {

// The frame handed to the renderer: the atlas texture plus what the methods give per entity.
struct SystemFrame final : engine::IndirectLightFrame {
  const std::vector<std::unique_ptr<MethodRuntime>>* methods = nullptr;
  engine::SsboHandle<engine::VertexIrradiance> vertex_irradiance_buffer(engine::Entity e) const override {
    for (const auto& m : *methods)
      if (engine::SsboHandle<engine::VertexIrradiance> b = m->vertex_irradiance_buffer(e)) return b;
    return {};
  }
  // A glossy dynamic object's view-dependent indirect light (BRF glossy terms).
  VertexRadianceLobes vertex_radiance_lobes(engine::Entity e) const override {
    for (const auto& m : *methods)
      if (VertexRadianceLobes l = m->vertex_radiance_lobes(e); l.terms > 0) return l;
    return {};
  }
  // The sky's occlusion on dynamic entities (system/sky_visibility.h), under a sky only.
  const SkyVisibility* sky = nullptr;
  bool sky_visibility(engine::Entity e, float (&axes)[6]) const override { return sky && sky->get(e, axes); }
};

// The manifest's methods that the table runs, and whose runtime another one replaces.
std::vector<EffectMethod> superseded_in(const Manifest& manifest) {
  std::vector<EffectMethod> out;
  for (const MethodRuntimeEntry& e : method_runtimes())
    if (e.supersedes && in_manifest(manifest, e.method)) out.push_back(*e.supersedes);
  return out;
}

// What the scene called for when it was baked (the plan the bake stored in the manifest)
// next to what the bundle holds. Not re-planned here: load reads what the bake wrote.
std::string plan_text(const std::filesystem::path& bundle_dir, const Manifest& manifest) {
  if (manifest.plan.is_null()) return "plan: not in the bundle's manifest (baked before plans were stored)\n";
  auto stored = plan_from_json_value(manifest.plan, (bundle_dir / kManifestFileName).string());
  if (!stored) return "plan: unreadable in the manifest: " + stored.error().to_string() + "\n";
  std::ostringstream text;
  for (const PlannedEffect& e : stored->effects)
    text << "plan " << effect_key(e.method) << ": "
         << (!e.enabled                        ? "off"
             : !e.available                    ? "needed, not built"
             : in_manifest(manifest, e.method) ? "on"
                                               : "needed, NOT IN THE BUNDLE (re-bake)")
         << " - " << e.reason << '\n';
  return text.str();
}

}  // namespace

struct GISystem::Impl {
  std::vector<std::unique_ptr<MethodRuntime>> methods;  // in the table's order (system/method_table.h)
  std::vector<std::string> method_names;                // their names in Stats::disabled
  std::vector<bool> reported_off;                       // told in Stats::disabled already
  std::unique_ptr<SkyVisibility> sky;                   // dynamic entities' sky occlusion, when the scene has a sky
  SystemFrame frame;
  Stats stats;
  std::string label;
  std::string description;
  const engine::Registry* registry = nullptr;
  LogCallback log;
  std::unordered_set<std::uint32_t> warned;  // entities skipped and told, while they stay unusable

  // Lights and dynamic objects the providers leave out this frame (engine/runtime_limits.h):
  // counted, and each told once when it starts being skipped.
  void check_runtime_inputs() {
    std::unordered_set<std::uint32_t> now;
    const auto skip = [&](engine::Entity e, const char* what, const char* why) {
      now.insert(e.id());
      if (warned.contains(e.id()) || !log) return;
      const auto* name = registry->try_get<engine::Name>(e);
      log(LogLevel::Warning, std::string("GI: ") + what + " '" +
                                 (name ? name->value : "entity " + std::to_string(e.id())) + "' skipped: " + why);
    };
    registry->view<engine::Light, engine::WorldTransform>().each(
        [&](engine::Entity e, const engine::Light& l, const engine::WorldTransform& wt) {
          if (!l.enabled) return;
          if (const char* why = engine::unusable_light(l, wt.matrix)) skip(e, "light", why);
        });
    registry->view<engine::DynamicTag, engine::WorldTransform>().each(
        [&](engine::Entity e, const engine::DynamicTag&, const engine::WorldTransform& wt) {
          if (const char* why = engine::unusable_world_matrix(wt.matrix)) skip(e, "dynamic object", why);
        });
    stats.skipped_entities = now.size();
    warned = std::move(now);
  }

  // What runs: every method's label, less those that turned off.
  void relabel() {
    label.clear();
    for (const auto& m : methods)
      if (m->disabled().empty()) label += (label.empty() ? "" : " + ") + m->label();
  }
  // A method that turned off has told the host through the log already; the stats keep it.
  void note_turned_off() {
    bool changed = false;
    for (std::size_t i = 0; i < methods.size(); ++i) {
      if (reported_off[i]) continue;
      const std::string why = methods[i]->disabled();
      if (why.empty()) continue;
      stats.disabled.push_back(method_names[i] + ": " + why);
      reported_off[i] = true;
      changed = true;
    }
    if (changed) relabel();
  }
};

GISystem::GISystem(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GISystem::~GISystem() = default;

engine::Result<std::unique_ptr<GISystem>> GISystem::load(const std::filesystem::path& bundle_dir, engine::Scene& scene,
                                                         GISystemSettings settings) {
  const auto t0 = std::chrono::steady_clock::now();
  auto manifest = read_manifest(bundle_dir);
  if (!manifest) return manifest.error();
  bool any = false;
  for (const MethodRuntimeEntry& e : method_runtimes())
    any = any || (e.stands_alone && in_manifest(*manifest, e.method));
  if (!any)
    return engine::Error{(bundle_dir / "manifest.json").string(), "methods",
                         "the bundle holds no light atlas, PRM, basis radiance fields or directional light maps"};
  auto impl = std::make_unique<Impl>();
  // The scene as the bakers saw it: hashes, layouts and BRF sources are checked against it.
  const BakeInput input = bake_input_from(scene);
  std::ostringstream text;
  text << plan_text(bundle_dir, *manifest);
  MethodLoad load{.bundle_dir = bundle_dir,
                  .input = input,
                  .scene = scene,
                  .settings = settings,
                  .stats = impl->stats,
                  .frame = impl->frame,
                  .text = text,
                  .superseded = superseded_in(*manifest)};
  for (const MethodRuntimeEntry& e : method_runtimes()) {
    if (!in_manifest(*manifest, e.method)) continue;
    auto runtime = e.load(load);
    if (!runtime) return runtime.error();
    if (!*runtime) continue;  // superseded: its bake went to the method that replaces it
    impl->methods.push_back(std::move(runtime).value());
    impl->method_names.push_back(std::string(effect_name(e.method)));
  }
  impl->reported_off.assign(impl->methods.size(), false);
  impl->registry = &scene.registry;
  impl->log = settings.log;
  impl->relabel();
  impl->description = text.str();
  impl->frame.methods = &impl->methods;
  if (engine::sky_lit(scene.assets.environment.sky_radiance, scene.assets.environment.sky_gradient)) {
    auto caster = load.static_world();
    if (!caster) return caster.error();
    auto sky = SkyVisibility::create(scene, std::move(caster).value());  // the renderer's sky term on dynamic entities
    if (!sky) return sky.error();
    impl->sky = std::move(sky).value();
    impl->frame.sky = impl->sky.get();
  }
  impl->stats.load_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return std::unique_ptr<GISystem>(new GISystem(std::move(impl)));
}

const engine::IndirectLightFrame& GISystem::frame() {
  Impl& m = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  ++m.stats.frames;
  m.check_runtime_inputs();
  FrameState state{.stats = m.stats, .frame = m.frame};
  for (const auto& method : m.methods) method->frame(state);
  m.note_turned_off();
  m.frame.irradiance_atlas_texture = {state.atlas_texture};
  if (m.sky) m.sky->update();
  if (!state.work) ++m.stats.idle_frames;
  if (m.stats.frames == 1) {
    glFinish();  // the uploads are done, not only queued
    m.stats.first_frame_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  return m.frame;
}

const char* GISystem::label() const { return impl_->label.c_str(); }
std::span<const engine::AtlasMesh> GISystem::atlas_meshes() const {
  for (const auto& m : impl_->methods)
    if (std::span<const engine::AtlasMesh> a = m->atlas_meshes(); !a.empty()) return a;
  return {};
}
const GISystem::Stats& GISystem::stats() const { return impl_->stats; }
std::string GISystem::describe() const { return impl_->description; }

}  // namespace gi
