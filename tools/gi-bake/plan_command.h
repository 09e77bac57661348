#pragma once
// gi-bake's use of the effect planner (gi/plan.h): `--plan` prints the plan, a bake without
// `--methods` bakes the plan's methods, and every bake records the plan in the manifest.
//   gi::EffectPlan p = gi::plan(scene, options);
//   std::vector<std::string> methods = tools::methods_from_plan(p, {"atlas", "prm"});

#include <engine/scene_asset.h>
#include <gi/plan.h>

#include <filesystem>
#include <string>
#include <vector>

namespace tools {

/// Prints gi::format_plan(plan) to stdout.
void print_plan(const gi::EffectPlan& plan);

/// The plan's enabled methods that this gi-bake can bake (`bakeable`), in plan order. Prints
/// one line for each enabled method it skips: not built in this build, or not in `bakeable`.
std::vector<std::string> methods_from_plan(const gi::EffectPlan& plan, const std::vector<std::string>& bakeable);

/// Writes the plan into DIR/manifest.json ("plan"). Returns false after printing an error.
bool record_plan(const std::filesystem::path& bundle_dir, const engine::SceneAsset& asset,
                 const std::string& scene_name, const gi::EffectPlan& plan);

}  // namespace tools
