#pragma once
// The methods gi::bake_bundle bakes, in bake order: one row per method naming its baker. A
// method's baker is its own file, bake/<key>_baker.cpp: it maps the options onto its
// settings (bake/bake_options.h), bakes (or merges a distributed bake's shards), logs and
// saves into the staged bundle. Adding a method to the bake: its baker file and one row in
// method_bakers.cpp; bake_bundle.cpp does not change (Architecture.BakeBundleKnowsNoMethodOnlyTheTable).

#include <engine/result.h>
#include <gi/bake.h>
#include <gi/methods.h>

#include <filesystem>
#include <span>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "bake/bake_sharding.h"

namespace gi {

/// What a method's bake cost, for bake_stats.json (stage name -> seconds).
using Timings = nlohmann::json;

/// One method's bake: what bake_bundle hands its baker.
struct MethodBake {
  const BakeInput& input;
  const std::filesystem::path& dir;  ///< The staged bundle the baker saves into.
  const BakeOptions& options;
  const BakeHost& host;
  const MergedParts* merged;  ///< A distributed bake's merge: every shard's parts; else nullptr.
  Timings& timings;           ///< The baker's stages, filled for bake_stats.json.
  /// Every method this bake bakes (keys): the DLM leaves the probes' surfaces to them when both are baked.
  const std::vector<std::string>& methods;
};

struct MethodBakerEntry {
  EffectMethod method;  ///< Its key in the manifest and its name: gi/methods.h.
  engine::Status (*bake)(const MethodBake& bake);
};

/// In bake order (the PRM and antiradiance after the light atlas, whose layout they read).
std::span<const MethodBakerEntry> method_bakers();

/// The row of `m` (every method of gi/methods.h has one).
const MethodBakerEntry& method_baker(EffectMethod m);

// Each method's baker, in its file.
engine::Status bake_light_atlas_method(const MethodBake& bake);
engine::Status bake_prm_method(const MethodBake& bake);
engine::Status bake_dlm_method(const MethodBake& bake);
engine::Status bake_brf_method(const MethodBake& bake);
engine::Status bake_antiradiance_method(const MethodBake& bake);
engine::Status bake_reflection_probes_method(const MethodBake& bake);

}  // namespace gi
