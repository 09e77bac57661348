#pragma once
// The plan as JSON, for the bake manifest's "plan" section (gi::to_json is the text form).
//   nlohmann::json j = gi::plan_to_json_value(plan);
//   auto back = gi::plan_from_json_value(j, "out/level.gibake/manifest.json");

#include <engine/result.h>
#include <gi/plan.h>

#include <nlohmann/json.hpp>

namespace gi {

nlohmann::json plan_to_json_value(const EffectPlan& plan);

/// Errors name `file` and the field: missing, mistyped, an unknown method key.
engine::Result<EffectPlan> plan_from_json_value(const nlohmann::json& json, const std::string& file);

}  // namespace gi
