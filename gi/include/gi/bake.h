#pragma once
// Baking a scene's GI data into a bake bundle: the API gi-bake is written on, for a
// studio's own pipeline. It plans (gi::plan), bakes each method the plan calls for (or the
// ones asked for) at a quality preset, writes one file per method plus manifest.json into
// the bundle directory (docs/bake-bundle.md) and records the plan there. GISystem loads the
// result (gi/gi_system.h).
//   gi::BakeInput input = gi::bake_input_from(scene);              // or filled by hand
//   auto report = gi::bake_bundle(input, "out/level.gibake", {.preset = "medium"},
//                                 {.progress = draw_bar, .log = print_line});
//   if (!report) std::cerr << report.error().to_string() << '\n';   // kind: Invalid, Cancelled, Failure
//
// Methods (gi::effect_key, gi/methods.h): "light_atlas" (light atlas, static lights), "prm" (precomputed
// radiance maps, moving lights), "brf" (basis radiance fields, one per distinct dynamic
// mesh), "dlm" (directional light maps of the glossy static surfaces, docs/dlm.md). "light_atlas",
// "prm" and "dlm" share one uv1 layout (the preset's atlas density). Methods the
// plan calls for that this build cannot bake ("antiradiance") are reported as
// skipped, never silently dropped. Byte-identical files for any thread count and run (but
// bake_stats.json, see below).

#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/log.h>
#include <gi/plan.h>
#include <gi/progress.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace gi {

/// What to bake and at what quality. Overrides of the preset are used when positive.
struct BakeOptions {
  std::string preset = "medium";     ///< preview | medium | high (docs/sweeps/README.md).
  std::vector<std::string> methods;  ///< Method keys to bake; empty: what gi::plan calls for.
  float texels_per_metre = 0.0f;     ///< Atlas density (atlas and PRM).
  int vpls = 0;                      ///< Light atlas: VPL count.
  int bounces = 0;                   ///< Light atlas: indirect bounces.
  int samples_per_vpl = 0;           ///< Light atlas: sample points per VPL.
  int brf_basis = 0;                 ///< BRF: basis functions N.
  int brf_spheres = 0;               ///< BRF: field spheres.
  int dlm_directions = 0;            ///< DLM: directions per texel (8..256).
  std::uint64_t dlm_photons = 0;     ///< DLM: photon paths.
  std::string dlm_bins;              ///< DLM: "tangent" (each texel's frame, the presets'), "global"; "": preset.
  /// Light atlas: also hold the static lights' direct light (the renderer then draws none
  /// of theirs on the static world). Without it the atlas holds the indirect light and the
  /// direct light the renderer does not draw: the sky's, shadowed by the level, and that of
  /// emissive surfaces no light stands for (docs/scene-format.md, "What is baked and what is
  /// drawn live").
  bool include_direct = false;
  std::vector<std::string> moving_lights;  ///< Lights (by name) the game moves although not flagged (PlanOptions).
  unsigned threads = 0;                    ///< Worker threads; 0: all hardware threads. Does not change the result.
  std::uint64_t seed = 1;
  /// Distributed bakes (docs/distributed-bake.md). shard_count > 0 and !merge_shards: bake
  /// only shard `shard_index` (0-based) of `shard_count` of the sharded methods' work (light
  /// atlas final gather, PRM panes, by texel blocks) into shard_directory(bundle_dir) /
  /// shard_file_name(I, N); no bundle is written. merge_shards: check that every shard
  /// 0..N-1 is there once, of this scene and these options, and write the bundle from them
  /// (the other methods baked here) through the same staging + swap as a whole bake: byte-
  /// identical files to a one-process bake. shard_count = 0 with merge_shards: N from the shards.
  std::uint32_t shard_index = 0;
  std::uint32_t shard_count = 0;
  bool merge_shards = false;
};

/// Where the shards of the bundle `bundle_dir` go: a directory beside it, "<bundle>.shards".
std::filesystem::path shard_directory(const std::filesystem::path& bundle_dir);
/// "shard-0003-of-0007.gishard" for shard 3 of 7.
std::string shard_file_name(std::uint32_t index, std::uint32_t count);

/// The host's side of a bake: progress per stage (returning false cancels, and the bake
/// returns an ErrorKind::Cancelled error) and a line per stage of what was done.
struct BakeHost {
  StageProgressCallback progress;
  LogCallback log;
};

/// The bundle's one informative file: per method, when, where, with how many threads and
/// how long each stage took. No loader reads it; it is the only file that differs between
/// two bakes of the same scene, options and seed (any thread count, any machine).
inline constexpr const char* kBakeStatsFileName = "bake_stats.json";

/// One method written into the bundle.
struct BakedMethod {
  std::string method;       ///< Its key: "light_atlas", "prm", "dlm", "brf" or "antiradiance".
  double seconds = 0.0;     ///< Wall time of its bake and save.
  std::uint64_t bytes = 0;  ///< Size of the files it wrote.
};

struct BakeReport {
  EffectPlan plan;                   ///< The plan the bake followed (also in the manifest).
  std::vector<BakedMethod> baked;    ///< In the order baked.
  std::vector<std::string> skipped;  ///< Keys the plan calls for that this build cannot bake.
};

/// The method keys this build can bake, in gi::EffectMethod order.
std::vector<std::string> bakeable_methods();

/// Bakes `input` into `bundle_dir` (created if needed; files of other methods already there
/// are kept when the geometry is the same). The bake writes into a staging copy next to it
/// (".<name>.staging") that replaces the bundle in one atomic exchange at the end: after an
/// error, a cancel or a killed process the previous bundle is exactly as it was. Errors:
/// invalid input (validate_bake_input), an unknown preset or method key or an override out
/// of range (ErrorKind::Invalid), a baker or file failure, cancellation.
engine::Result<BakeReport> bake_bundle(const BakeInput& input, const std::filesystem::path& bundle_dir,
                                       const BakeOptions& options = {}, const BakeHost& host = {});

}  // namespace gi
