#include "plan_command.h"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include "bundle/geometry_hash.h"
#include "bundle/manifest.h"
#include "plan/plan_json.h"

namespace tools {

void print_plan(const gi::EffectPlan& plan) { std::fputs(gi::format_plan(plan).c_str(), stdout); }

std::vector<std::string> methods_from_plan(const gi::EffectPlan& plan, const std::vector<std::string>& bakeable) {
  std::vector<std::string> out;
  for (const gi::PlannedEffect& e : plan.effects) {
    if (!e.enabled) continue;
    const std::string key(gi::effect_key(e.method));
    if (!e.available) {
      std::printf("gi-bake: skipping %s: the scene calls for it (%s) but this build cannot bake it\n", key.c_str(),
                  e.reason.c_str());
    } else if (std::find(bakeable.begin(), bakeable.end(), key) == bakeable.end()) {
      std::printf("gi-bake: skipping %s: the scene calls for it (%s) but this gi-bake has no %s baker\n", key.c_str(),
                  e.reason.c_str(), key.c_str());
    } else {
      out.push_back(key);
    }
  }
  return out;
}

bool record_plan(const std::filesystem::path& bundle_dir, const engine::SceneAsset& asset,
                 const std::string& scene_name, const gi::EffectPlan& plan) {
  auto status =
      gi::update_manifest_plan(bundle_dir, gi::scene_geometry_hash(asset), scene_name, gi::plan_to_json_value(plan));
  if (!status) {
    std::cerr << "gi-bake: " << status.error().to_string() << '\n';
    return false;
  }
  return true;
}

}  // namespace tools
