#pragma once
// The effect planner (DESIGN.md §3 "Effects on demand"): reads a scene and says which of the
// five GI methods it calls for, why, what each would target, whether this build can bake it,
// and roughly what it would cost (bake seconds, runtime memory) at a quality preset.
//   gi::EffectPlan p = gi::plan(scene, {.preset = "preview"});
//   std::fputs(gi::format_plan(p).c_str(), stdout);   // or gi::to_json(p) for a manifest
//
// Rules (docs/plan.md):
//   - no light (no enabled light, no emissive static surface) -> nothing;
//   - static lights (or emissive static surfaces) and static meshes -> light atlas ("light_atlas");
//   - a light moves (Light::moves / glTF gi.light_moves, a light on or under a dynamic node,
//     or named in PlanOptions::moving_lights) and static meshes -> PRM ("prm");
//   - a static surface with roughness in [PlanOptions::glossy_roughness_min, glossy_roughness) -> directional
//     light maps ("dlm");
//   - nodes flagged gi.region "deforming" -> antiradiance ("antiradiance") for them;
//   - dynamic mesh entities -> basis radiance fields ("brf") for their meshes only.
// Estimates are models of the bakers' work (texels, VPLs, path nodes, rays) with cost
// constants measured on this project's scenes (the table in gi/src/plan/plan_cost.cpp);
// they are meant to be right within a factor of about 2, not more.

#include <engine/result.h>
#include <engine/scene.h>
#include <gi/bake_input.h>
#include <gi/methods.h>

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace gi {

/// The method's key (gi/methods.h) as gi-bake --methods and the manifest spell it: "light_atlas", "prm", "dlm",
/// "antiradiance", "brf".
std::string_view effect_key(EffectMethod method);
/// The method whose key is `key`, or nullopt.
std::optional<EffectMethod> effect_from_key(std::string_view key);

/// What a method would cost at the plan's preset. Zero with an empty `basis` when there is
/// no model (a method this build cannot bake).
struct EffectEstimate {
  double bake_seconds = 0.0;        ///< Wall time of the bake on this machine kind (2 threads).
  std::uint64_t runtime_bytes = 0;  ///< GPU-resident data the runtime keeps (textures, panes, fields).
  std::uint64_t work_units = 0;     ///< The model's main quantity: atlas texels, path nodes, field samples.
  std::string basis;                ///< One line: the scene quantities and settings the numbers come from.
};

/// One method's entry in a plan.
struct PlannedEffect {
  EffectMethod method = EffectMethod::LightAtlas;
  bool enabled = false;              ///< The scene calls for it.
  bool available = false;            ///< This build can bake it (all five methods today).
  std::string reason;                ///< One line naming the facts ("light 'swinging_lamp' moves").
  std::vector<std::string> targets;  ///< Entity names (atlas, prm, dlm, antiradiance) or mesh names (brf).
  EffectEstimate estimate;           ///< Filled when enabled and available.
};

/// The facts of the scene the rules read (also printed and stored).
struct SceneFacts {
  int static_lights = 0;        ///< Enabled lights that do not move.
  int moving_lights = 0;        ///< Enabled lights that move.
  int disabled_lights = 0;      ///< Switched off: ignored.
  int emissive_surfaces = 0;    ///< Static mesh entities with an emissive material.
  int static_meshes = 0;        ///< Mesh entities without DynamicTag.
  int dynamic_meshes = 0;       ///< Mesh entities with DynamicTag.
  double static_area_m2 = 0.0;  ///< World-space area of the static meshes.
  double static_albedo = 0.0;   ///< Area-weighted mean albedo (luminance) of the static meshes.
};

/// gi::plan's answer: one entry per method, in EffectMethod order.
struct EffectPlan {
  std::string scene;   ///< SceneAsset::source (file), informative.
  std::string preset;  ///< The preset the estimates are for.
  float glossy_roughness = 0.0f;
  float glossy_roughness_min = 0.0f;
  SceneFacts facts;
  std::vector<PlannedEffect> effects;  ///< kEffectMethodCount entries.
  std::vector<std::string> warnings;   ///< Facts a bake would treat differently from the plan.

  const PlannedEffect& effect(EffectMethod method) const;
  /// Keys of the enabled and available methods, in EffectMethod order: what gi-bake bakes.
  std::vector<std::string> methods_to_bake() const;
};

struct PlanOptions {
  std::string preset = "medium";  ///< preview | medium | high (the bakers' presets).
  /// Static surfaces with a roughness factor in [glossy_roughness_min, glossy_roughness) get
  /// directional light maps: each roughness goes to exactly one method (docs/plan.md, "Routing").
  /// The top is where the maps stop beating the atlas's direction-less specular term against the
  /// path tracer (docs/dlm.md, "The regime", measured to 0.8); sharper surfaces than the bottom,
  /// the reflection probes' limit (kReflectionProbeMaxRoughness, 0.3), are the probes', which win
  /// on the demo corridor from 0.1 to 0.3 and whose specular the renderer draws there anyway.
  float glossy_roughness = 0.8f;
  float glossy_roughness_min = 0.3f;
  /// Lights (by name) the game moves or scripts although the file does not flag them.
  std::vector<std::string> moving_lights;
  /// Overrides of the preset, as gi-bake's --density / --vpls / --samples / --bounces (0: preset).
  float texels_per_metre = 0.0f;
  int vpls = 0;
  int samples_per_vpl = 0;
  int bounces = 0;
};

/// Plans the effects of `input` (gi/bake_input.h). Cheap: no ray is traced. An unknown
/// preset gives a plan without estimates and a warning saying so.
EffectPlan plan(const BakeInput& input, const PlanOptions& options = {});

/// plan(bake_input_from(scene), options): world transforms must be current, as
/// engine::instantiate leaves them.
EffectPlan plan(const engine::Scene& scene, const PlanOptions& options = {});

/// The plan as console text: one block per method (state, reason, targets, estimate).
std::string format_plan(const EffectPlan& plan);

/// The plan as a JSON object (text), the manifest's "plan" section (docs/plan.md).
std::string to_json(const EffectPlan& plan);
/// Reads what to_json wrote. Errors: malformed JSON, missing or mistyped fields.
engine::Result<EffectPlan> plan_from_json(std::string_view json);

/// "1.2 s", "340 ms"; "14.2 MB", "9.6 kB" (decimal units), for reasons and the console.
std::string format_seconds(double seconds);
std::string format_bytes(std::uint64_t bytes);

}  // namespace gi
