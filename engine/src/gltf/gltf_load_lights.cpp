// Lights, cameras and the "gi" node extras of the glTF loader.
// KHR_lights_punctual lights are converted from photometric glTF units to the engine's
// radiometric ones (engine/units.h); the "gi" extras schema is in docs/scene-format.md.

#include <engine/log.h>
#include <engine/sun.h>
#include <engine/units.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtx/quaternion.hpp>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {
namespace {

constexpr double kMaxLightIntensity = 1e15;  // cd or lux

/// A fixed-size array of finite numbers, e.g. a colour.
template <int N>
Result<glm::vec<N, float>> number_array(const Context& ctx, const Json& value, const std::string& where,
                                        const char* name) {
  if (!value.is_array() || value.size() != static_cast<std::size_t>(N)) {
    return ctx.error(where, std::string("'") + name + "' must be an array of " + std::to_string(N) + " numbers");
  }
  glm::vec<N, float> out(0.0f);
  for (int i = 0; i < N; ++i) {
    const Json& v = value[static_cast<std::size_t>(i)];
    if (!v.is_number()) {
      return ctx.error(where, std::string("'") + name + "' must be an array of " + std::to_string(N) + " numbers");
    }
    out[i] = static_cast<float>(v.get<double>());
    if (!std::isfinite(out[i])) return ctx.error(where, std::string("'") + name + "' is not finite (NaN or Inf)");
  }
  return out;
}

/// One KHR_lights_punctual light definition.
// Long because it reads the light's members as KHR_lights_punctual lists them (type,
// intensity, color, range, spot cone), each a check and its error: a flat list read against the spec.
Result<NamedLight> convert_light(const Context& ctx, const Json& src, const std::string& where) {
  if (!src.is_object()) return ctx.error(where, "must be an object");
  NamedLight out;
  if (const Json* name = find_member(src, "name"); name != nullptr && name->is_string())
    out.name = name->get<std::string>();
  const Json* type = find_member(src, "type");
  if (type == nullptr || !type->is_string()) return ctx.error(where, "'type' is required and must be a string");
  const std::string t = type->get<std::string>();
  auto intensity = number_member(ctx, src, "intensity", 1.0, where);
  if (!intensity) return intensity.error();
  if (!std::isfinite(*intensity) || *intensity < 0.0) {
    return ctx.error(where, "intensity " + std::to_string(*intensity) + " is negative or not finite");
  }
  // Finite as a double can still be infinite as a float, and squared distances and sums of
  // lights multiply it further: far above any real light (the sun is 1.2e5 lux) is refused.
  if (*intensity > kMaxLightIntensity) {
    return ctx.error(where, "intensity " + std::to_string(*intensity) + " is beyond any real light (at most 1e15)");
  }
  if (const Json* color = find_member(src, "color")) {
    auto c = number_array<3>(ctx, *color, where, "color");
    if (!c) return c.error();
    if (c->x < 0.0f || c->y < 0.0f || c->z < 0.0f) return ctx.error(where, "color has a negative component");
    out.light.color = *c;
  }
  if (t == "point" || t == "spot") {
    // KHR_lights_punctual: point and spot intensity is luminous intensity in candela.
    out.light.type = t == "point" ? LightType::Point : LightType::Spot;
    out.light.intensity = units::candela_to_w_per_sr(static_cast<float>(*intensity));
  } else if (t == "directional") {
    // Directional intensity is illuminance in lux.
    out.light.type = LightType::Directional;
    out.light.intensity = units::lux_to_w_per_m2(static_cast<float>(*intensity));
  } else {
    return ctx.error(where, "unknown light type '" + t + "'");
  }
  if (find_member(src, "range") != nullptr) {
    auto range = number_member(ctx, src, "range", 0.0, where);
    if (!range) return range.error();
    if (!std::isfinite(*range) || *range <= 0.0) return ctx.error(where, "range must be > 0");
    if (out.light.type != LightType::Directional) out.light.range_m = static_cast<float>(*range);
  }
  if (out.light.type == LightType::Spot) {
    // KHR_lights_punctual: a spot light has a "spot" object (its members have defaults).
    const Json* spot = find_member(src, "spot");
    if (spot == nullptr || !spot->is_object()) return ctx.error(where, "spot light needs a 'spot' object");
    const Json& s = *spot;
    auto inner = number_member(ctx, s, "innerConeAngle", 0.0, where + " spot");
    if (!inner) return inner.error();
    auto outer = number_member(ctx, s, "outerConeAngle", std::numbers::pi / 4.0, where + " spot");
    if (!outer) return outer.error();
    // KHR_lights_punctual: 0 <= innerConeAngle < outerConeAngle <= pi/2.
    if (!(*inner >= 0.0) || !(*outer > 0.0) || *outer > std::numbers::pi / 2.0 + 1e-6) {
      return ctx.error(where, "spot cone angles must satisfy 0 <= inner < outer <= pi/2");
    }
    if (*inner > *outer) {
      return ctx.error(where, "spot innerConeAngle " + std::to_string(*inner) + " is greater than outerConeAngle " +
                                  std::to_string(*outer));
    }
    out.light.inner_cone_rad = static_cast<float>(*inner);
    out.light.outer_cone_rad = static_cast<float>(*outer);
  }
  return out;
}

}  // namespace

Result<std::vector<NamedLight>> convert_punctual_lights(const Context& ctx, const Json& doc) {
  std::vector<NamedLight> lights;
  const Json* exts = find_member(doc, "extensions");
  const Json* ext = exts != nullptr ? find_member(*exts, "KHR_lights_punctual") : nullptr;
  if (ext == nullptr) return lights;
  const Json* list = find_member(*ext, "lights");
  if (list == nullptr || !list->is_array() || list->empty()) {
    return ctx.error("KHR_lights_punctual", "'lights' must be a non-empty array");
  }
  for (std::size_t i = 0; i < list->size(); ++i) {
    auto light = convert_light(ctx, (*list)[i], "light " + std::to_string(i));
    if (!light) return light.error();
    lights.push_back(std::move(light.value()));
  }
  return lights;
}

Result<std::vector<NamedCamera>> convert_cameras(const Context& ctx, const ParsedFile& file,
                                                 std::vector<int>& index_map) {
  std::vector<NamedCamera> cameras;
  index_map.assign(file.model.cameras.size(), -1);
  for (std::size_t i = 0; i < file.model.cameras.size(); ++i) {
    const tinygltf::Camera& src = file.model.cameras[i];
    const std::string where = "camera " + std::to_string(i);
    if (src.type == "orthographic") {
      log_message(LogLevel::Warning,
                  ctx.file + ": " + where + ": orthographic camera skipped (the engine has perspective cameras only)");
      continue;
    }
    if (src.type != "perspective") return ctx.error(where, "unknown camera type '" + src.type + "'");
    // §5.13: yfov > 0, znear > 0, zfar > znear when present (absent: infinite; the engine uses 500 m).
    const tinygltf::PerspectiveCamera& p = src.perspective;
    if (!(p.yfov > 0.0) || !std::isfinite(p.yfov)) return ctx.error(where, "yfov must be > 0");
    if (!(p.znear > 0.0) || !std::isfinite(p.znear)) return ctx.error(where, "znear must be > 0");
    if (p.zfar != 0.0 && !(p.zfar > p.znear && std::isfinite(p.zfar))) return ctx.error(where, "zfar must be > znear");
    if (p.aspectRatio < 0.0 || !std::isfinite(p.aspectRatio)) return ctx.error(where, "aspectRatio must be > 0");
    NamedCamera cam;
    cam.name = src.name;
    cam.camera.yfov_rad = static_cast<float>(p.yfov);
    cam.camera.znear_m = static_cast<float>(p.znear);
    cam.camera.zfar_m = p.zfar == 0.0 ? 500.0f : static_cast<float>(p.zfar);
    cam.camera.aspect = static_cast<float>(p.aspectRatio);
    index_map[i] = static_cast<int>(cameras.size());
    cameras.push_back(std::move(cam));
  }
  return cameras;
}

Result<GiExtras> parse_gi_extras(const Context& ctx, const Json& node, const std::string& location) {
  GiExtras out;
  const Json* extras = find_member(node, "extras");
  const Json* gi = extras != nullptr ? find_member(*extras, "gi") : nullptr;
  if (gi == nullptr) return out;
  const std::string where = location + " extras.gi";
  if (!gi->is_object()) return ctx.error(where, "must be an object");
  if (const Json* mobility = find_member(*gi, "mobility")) {
    const std::string m = mobility->is_string() ? mobility->get<std::string>() : std::string();
    if (m == "static") {
      out.mobility = Mobility::Static;
    } else if (m == "dynamic") {
      out.mobility = Mobility::Dynamic;
    } else {
      return ctx.error(where, "'mobility' must be \"static\" or \"dynamic\"");
    }
  }
  if (const Json* region = find_member(*gi, "region")) {
    if (!region->is_string() || region->get<std::string>() != "deforming")
      return ctx.error(where, "'region' must be \"deforming\"");
    out.region = GiRegion::Deforming;
  }
  if (const Json* moves = find_member(*gi, "light_moves")) {
    if (!moves->is_boolean()) return ctx.error(where, "'light_moves' must be true or false");
    out.light_moves = moves->get<bool>();
  }
  if (const Json* area = find_member(*gi, "area_light")) {
    const std::string awhere = where + ".area_light";
    if (!area->is_object()) return ctx.error(awhere, "must be an object");
    const Json* size = find_member(*area, "size_m");
    const Json* radiance = find_member(*area, "radiance");
    if (size == nullptr || radiance == nullptr) return ctx.error(awhere, "needs 'size_m' and 'radiance'");
    auto s = number_array<2>(ctx, *size, awhere, "size_m");
    if (!s) return s.error();
    auto r = number_array<3>(ctx, *radiance, awhere, "radiance");
    if (!r) return r.error();
    if (!(s->x > 0.0f && s->y > 0.0f)) return ctx.error(awhere, "'size_m' must be positive");
    if (r->x < 0.0f || r->y < 0.0f || r->z < 0.0f) return ctx.error(awhere, "'radiance' has a negative component");
    NamedLight light;
    if (const Json* name = find_member(node, "name"); name != nullptr && name->is_string()) {
      light.name = name->get<std::string>();
    }
    light.light.type = LightType::Area;
    light.light.area_size_m = *s;
    const float peak = std::max({r->x, r->y, r->z});
    light.light.intensity = peak;  // W/(m^2 sr), one-sided towards local -Z
    light.light.color = peak > 0.0f ? *r / peak : glm::vec3(1.0f);
    out.area_light = std::move(light);
  }
  return out;
}

Status parse_scene_environment(const Context& ctx, const Json& scene_json, const std::string& location,
                               SceneAsset& scene) {
  const Json* extras = find_member(scene_json, "extras");
  const Json* gi = extras != nullptr && extras->is_object() ? find_member(*extras, "gi") : nullptr;
  if (gi == nullptr) return {};
  const std::string where = location + " extras.gi";
  if (!gi->is_object()) return ctx.error(where, "must be an object");
  if (const Json* sky = find_member(*gi, "sky")) {
    const std::string swhere = where + ".sky";
    if (!sky->is_object()) return ctx.error(swhere, "must be an object");
    // A uniform 'radiance', a gradient ('zenith', 'horizon', 'ground'; engine/sky.h), or both (they add).
    const auto sky_colour = [&](const char* key, glm::vec3& out) -> Status {
      const Json* value = find_member(*sky, key);
      if (value == nullptr) return {};
      auto r = number_array<3>(ctx, *value, swhere, key);
      if (!r) return r.error();
      if (r->x < 0.0f || r->y < 0.0f || r->z < 0.0f)
        return ctx.error(swhere, "'" + std::string(key) + "' has a negative component");
      if (std::max({r->x, r->y, r->z}) > static_cast<float>(kMaxLightIntensity))
        return ctx.error(swhere, "'" + std::string(key) + "' is beyond any real sky (at most 1e15)");
      out = *r;
      return {};
    };
    const int gradient_keys = (find_member(*sky, "zenith") != nullptr) + (find_member(*sky, "horizon") != nullptr) +
                              (find_member(*sky, "ground") != nullptr);
    if (find_member(*sky, "radiance") == nullptr && gradient_keys == 0)
      return ctx.error(swhere, "needs 'radiance' or 'zenith', 'horizon' and 'ground'");
    if (gradient_keys != 0 && gradient_keys != 3)
      return ctx.error(swhere, "a gradient needs all of 'zenith', 'horizon' and 'ground'");
    if (Status s = sky_colour("radiance", scene.environment.sky_radiance); !s) return s;
    if (Status s = sky_colour("zenith", scene.environment.sky_gradient.zenith); !s) return s;
    if (Status s = sky_colour("horizon", scene.environment.sky_gradient.horizon); !s) return s;
    if (Status s = sky_colour("ground", scene.environment.sky_gradient.ground); !s) return s;
  }
  if (const Json* sun = find_member(*gi, "sun")) {
    const std::string swhere = where + ".sun";
    if (!sun->is_object()) return ctx.error(swhere, "must be an object");
    const Json* direction = find_member(*sun, "direction");
    const Json* irradiance = find_member(*sun, "irradiance");
    if (direction == nullptr || irradiance == nullptr) return ctx.error(swhere, "needs 'direction' and 'irradiance'");
    auto d = number_array<3>(ctx, *direction, swhere, "direction");
    if (!d) return d.error();
    auto e = number_array<3>(ctx, *irradiance, swhere, "irradiance");
    if (!e) return e.error();
    if (!(glm::length(*d) > 1e-6f)) return ctx.error(swhere, "'direction' must not be zero");
    if (e->x < 0.0f || e->y < 0.0f || e->z < 0.0f) return ctx.error(swhere, "'irradiance' has a negative component");
    if (std::max({e->x, e->y, e->z}) > static_cast<float>(kMaxLightIntensity))
      return ctx.error(swhere, "'irradiance' is beyond any real sun (at most 1e15)");
    auto radius = number_member(ctx, *sun, "angular_radius_deg", 0.27, swhere);
    if (!radius) return radius.error();
    if (!(*radius >= 0.0 && *radius <= 45.0)) return ctx.error(swhere, "'angular_radius_deg' must lie in [0, 45]");
    // Appended after the file's nodes (scene extras are read last): the sun's node comes last.
    scene.environment.sun_light = -1;
    scene.environment.sun_node = -1;
    set_sun(scene, {.direction = *d,
                    .irradiance = *e,
                    .angular_radius_rad = static_cast<float>(*radius * std::numbers::pi / 180.0)});
  }
  return {};
}

}  // namespace engine::gltf_load
