#pragma once
// One GI method at run time, the shape all five share (issue 34). GISystem loads, in the
// order of the method table (system/method_table.h), every method the bundle's manifest
// holds; on each frame it runs them in that order, each reading what the ones before it
// left in the FrameState and adding its part. GISystem knows no method's fields: a method is
// one adapter file, system/<key>_method.cpp, and one row of the table.
//
//   load:  light_atlas -> prm -> brf -> dlm -> antiradiance    (MethodLoad: the shared bakes)
//   frame: the static world's irradiance atlas texture flows down the same order; the light
//          atlas (or the PRM, which supersedes it) makes it, BRF adds the objects' bounce,
//          antiradiance the deforming region's change; DLM adds the glossy bins beside it.

#include <engine/gpu/gl_objects.h>
#include <engine/indirect_light.h>
#include <engine/result.h>
#include <engine/scene.h>
#include <gi/gi_system.h>
#include <gi/plan.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string>

#include "light_atlas/light_atlas.h"

namespace gi {

struct Manifest;
struct AtlasLayout;
class RayCaster;
class PrmLighting;

/// What loading shares between methods. A method reads its own files from `bundle_dir` and
/// may publish what later methods need (the static world's layout, the moving lights).
struct MethodLoad {
  std::filesystem::path bundle_dir;
  const BakeInput& input;  ///< The scene as the bakers saw it (hashes, layouts, BRF sources).
  engine::Scene& scene;
  const GISystemSettings& settings;
  GISystem::Stats& stats;
  engine::IndirectLightFrame& frame;  ///< What the static world's atlas holds (atlas_holds_*).
  std::ostringstream& text;           ///< describe(): one line (or two) per method.
  /// The bundle's methods whose runtime another method of the bundle replaces: their
  /// loader reads and publishes their bake, and returns no runtime.
  std::vector<EffectMethod> superseded;

  // --- Published by the methods, read by later ones.
  std::optional<LightAtlasBake> atlas_bake;  ///< The light atlas's bake, kept until load ends.
  const AtlasLayout* layout = nullptr;       ///< The static world's atlas layout (light atlas or PRM).
  int atlas_width = 0;
  int atlas_height = 0;
  const PrmLighting* moving_lights = nullptr;  ///< The PRM's runtime: entry points, moving lights' light.

  bool is_superseded(EffectMethod m) const;
  /// The one ray caster over the static world every method at run time shares, built on
  /// first request (none is built when no method traces rays).
  engine::Result<std::shared_ptr<const RayCaster>> static_world();
  std::shared_ptr<const RayCaster> caster;
};

/// One frame's state, handed down the methods in table order.
struct FrameState {
  GISystem::Stats& stats;
  std::uint32_t atlas_texture = 0;  ///< The static world's irradiance so far (0: none yet).
  bool atlas_changed = false;       ///< ... differs from last frame's.
  bool objects_changed = false;     ///< The dynamic objects' light changed (their bounce into the atlas).
  bool work = false;                ///< Something was recomputed this frame.
  engine::IndirectLightFrame& frame;
  const PrmLighting* moving_lights = nullptr;  ///< Set by the PRM for the BRF's probes.
};

class MethodRuntime {
 public:
  virtual ~MethodRuntime() = default;
  /// This frame's part (GL context current).
  virtual void frame(FrameState& state) = 0;
  /// For GISystem::label(): "light atlas", "light atlas + PRM", "BRF", ...
  virtual std::string label() const = 0;
  /// Why the method turned off at run time (told once to the log by the method); empty while
  /// it runs. A method that turned off keeps its frame() a no-op.
  virtual std::string disabled() const { return {}; }
  /// The dynamic objects' light, asked by the renderer through the frame (BRF).
  virtual engine::SsboHandle<engine::VertexIrradiance> vertex_irradiance_buffer(engine::Entity) const { return {}; }
  virtual engine::IndirectLightFrame::VertexRadianceLobes vertex_radiance_lobes(engine::Entity) const { return {}; }
  /// The static meshes with the atlas's TEXCOORD_1, for the renderer (the method that makes
  /// the static world's atlas: the light atlas, or the PRM).
  virtual std::span<const engine::AtlasMesh> atlas_meshes() const { return {}; }
};

/// The GL texture the methods that add into the atlas write to: RGBA32F, linear, clamped, of
/// `source`'s size; created on first use.
std::uint32_t atlas_target_like(std::uint32_t source, engine::GlTexture& target);

}  // namespace gi
