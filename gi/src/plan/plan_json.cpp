#include "plan/plan_json.h"

#include "io/json_fields.h"

namespace gi {

nlohmann::json plan_to_json_value(const EffectPlan& p) {
  nlohmann::json j = nlohmann::json::object();
  j["scene"] = p.scene;
  j["preset"] = p.preset;
  j["glossy_roughness"] = p.glossy_roughness;
  j["glossy_roughness_min"] = p.glossy_roughness_min;
  j["facts"] = {{"static_lights", p.facts.static_lights},     {"moving_lights", p.facts.moving_lights},
                {"disabled_lights", p.facts.disabled_lights}, {"emissive_surfaces", p.facts.emissive_surfaces},
                {"static_meshes", p.facts.static_meshes},     {"dynamic_meshes", p.facts.dynamic_meshes},
                {"static_area_m2", p.facts.static_area_m2},   {"static_albedo", p.facts.static_albedo}};
  nlohmann::json effects = nlohmann::json::array();
  for (const PlannedEffect& e : p.effects) {
    effects.push_back({{"method", std::string(effect_key(e.method))},
                       {"enabled", e.enabled},
                       {"available", e.available},
                       {"reason", e.reason},
                       {"targets", e.targets},
                       {"estimate",
                        {{"bake_seconds", e.estimate.bake_seconds},
                         {"runtime_bytes", e.estimate.runtime_bytes},
                         {"work_units", e.estimate.work_units},
                         {"basis", e.estimate.basis}}}});
  }
  j["effects"] = std::move(effects);
  j["warnings"] = p.warnings;
  j["bake"] = p.methods_to_bake();
  return j;
}

engine::Result<EffectPlan> plan_from_json_value(const nlohmann::json& json, const std::string& file) {
  JsonFields f(json, file, "plan");
  EffectPlan p;
  p.scene = f.get<std::string>("scene");
  p.preset = f.get<std::string>("preset");
  p.glossy_roughness = f.get<float>("glossy_roughness");
  p.glossy_roughness_min = f.get<float>("glossy_roughness_min");
  p.facts.static_lights = f.get<int>("facts.static_lights");
  p.facts.moving_lights = f.get<int>("facts.moving_lights");
  p.facts.disabled_lights = f.get<int>("facts.disabled_lights");
  p.facts.emissive_surfaces = f.get<int>("facts.emissive_surfaces");
  p.facts.static_meshes = f.get<int>("facts.static_meshes");
  p.facts.dynamic_meshes = f.get<int>("facts.dynamic_meshes");
  p.facts.static_area_m2 = f.get<double>("facts.static_area_m2");
  p.facts.static_albedo = f.get<double>("facts.static_albedo");
  if (f.error()) return *f.error();
  const auto strings = [&](const nlohmann::json& arr,
                           const std::string& where) -> engine::Result<std::vector<std::string>> {
    std::vector<std::string> out;
    if (!arr.is_array()) return engine::Error{file, where, "must be an array of strings"};
    for (const nlohmann::json& s : arr) {
      if (!s.is_string()) return engine::Error{file, where, "must be an array of strings"};
      out.push_back(s.get<std::string>());
    }
    return out;
  };
  if (!json.contains("effects") || !json["effects"].is_array())
    return engine::Error{file, "plan.effects", "missing or not an array"};
  for (std::size_t i = 0; i < json["effects"].size(); ++i) {
    const std::string where = "plan.effects[" + std::to_string(i) + "]";
    const nlohmann::json& ej = json["effects"][i];
    JsonFields ef(ej, file, where);
    PlannedEffect e;
    const std::string key = ef.get<std::string>("method");
    e.enabled = ef.get<bool>("enabled");
    e.available = ef.get<bool>("available");
    e.reason = ef.get<std::string>("reason");
    e.estimate.bake_seconds = ef.get<double>("estimate.bake_seconds");
    e.estimate.runtime_bytes = ef.get<std::uint64_t>("estimate.runtime_bytes");
    e.estimate.work_units = ef.get<std::uint64_t>("estimate.work_units");
    e.estimate.basis = ef.get<std::string>("estimate.basis");
    if (ef.error()) return *ef.error();
    // "atlas": the light atlas's key in plans stored before the one-name rule (issue 34).
    const auto method = key == "atlas" ? std::optional(EffectMethod::LightAtlas) : effect_from_key(key);
    if (!method) return engine::Error{file, where + ".method", "unknown method '" + key + "'"};
    e.method = *method;
    if (!ej.contains("targets")) return engine::Error{file, where + ".targets", "missing field"};
    auto targets = strings(ej["targets"], where + ".targets");
    if (!targets) return targets.error();
    e.targets = std::move(targets).value();
    p.effects.push_back(std::move(e));
  }
  if (json.contains("warnings")) {
    auto warnings = strings(json["warnings"], "plan.warnings");
    if (!warnings) return warnings.error();
    p.warnings = std::move(warnings).value();
  }
  return p;
}

std::string to_json(const EffectPlan& plan) { return plan_to_json_value(plan).dump(2); }

engine::Result<EffectPlan> plan_from_json(std::string_view text) {
  nlohmann::json j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) return engine::Error{"", "plan", "malformed JSON"};
  if (!j.is_object()) return engine::Error{"", "plan", "must be a JSON object"};
  return plan_from_json_value(j, "");
}

}  // namespace gi
