#include "system/prm_probe_light.h"

#include <engine/finite.h>
#include <engine/gltf_brdf.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <unordered_map>

#include "prm/prm.h"
#include "raytrace/material_lookup.h"
#include "raytrace/ray.h"
#include "raytrace/ray_caster.h"
#include "system/prm_lighting.h"
#include "transport/static_scene.h"

namespace gi {

std::vector<glm::vec3> prm_entry_albedo(const StaticBakeScene& statics, std::span<const PrmEntryPoint> entries,
                                        std::size_t* missed) {
  std::vector<glm::vec3> out(entries.size(), glm::vec3(0.0f));
  std::unordered_map<std::uint32_t, glm::vec3> of_material;
  std::size_t misses = 0;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const PrmEntryPoint& e = entries[i];
    // The entry point lies on a triangle: a ray from 1 cm above it down its normal finds it
    // (then one from 10 cm, for entries a rounding away from their surface).
    Hit hit;
    for (const float lift : {0.01f, 0.1f}) {
      hit = statics.caster->intersect(
          Ray{.origin = e.position + lift * e.normal, .t_min = 0.0f, .direction = -e.normal, .t_max = 2.0f * lift});
      if (hit.valid()) break;
    }
    if (!hit.valid()) {
      ++misses;
      continue;
    }
    const ShadingTriangle& tri = statics.index.triangles[statics.triangle_of(hit)];
    const std::uint32_t material = tri.material;
    if (statics.scene.materials[material].textured()) {  // the texture around the entry point
      out[i] = albedo_at(statics.scene, tri, hit.barycentric, std::sqrt(std::max(e.area_m2, 0.0f)));
      continue;
    }
    auto it = of_material.find(material);
    if (it == of_material.end())
      it =
          of_material.emplace(material, engine::gltf_hemispherical_albedo(statics.scene.materials[material].brdf).sum())
              .first;
    out[i] = it->second;
  }
  if (missed != nullptr) *missed = misses;
  return out;
}

engine::Result<PrmProbeLight> PrmProbeLight::create(const RayCaster& static_world, const WorldProbeGrid& grid,
                                                    std::span<const PrmEntryPoint> entries,
                                                    std::vector<glm::vec3> albedo, unsigned threads) {
  if (albedo.size() != entries.size())
    return engine::Error{
        .location = "PRM world probes",
        .message = std::to_string(albedo.size()) + " albedos for " + std::to_string(entries.size()) + " entry points"};
  std::vector<glm::vec3> position, normal;
  std::vector<float> area;
  position.reserve(entries.size());
  normal.reserve(entries.size());
  area.reserve(entries.size());
  for (const PrmEntryPoint& e : entries) {
    position.push_back(e.position);
    normal.push_back(e.normal);
    area.push_back(e.area_m2);
  }
  auto transfer = bake_world_probe_transfer(static_world, grid, position, normal, area, threads);
  if (!transfer) return transfer.error();
  PrmProbeLight out;
  out.transfer_ = std::move(transfer).value();
  out.albedo_area_.resize(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    if (!engine::all_finite(albedo[i]))
      return engine::Error{.location = "PRM world probes",
                           .message = "entry point " + std::to_string(i) + " has a non-finite albedo"};
    out.albedo_area_[i] = albedo[i] * entries[i].area_m2;
  }
  out.sh_.assign(grid.probe_count(), {});
  out.stats_.transfer_bytes = out.transfer_.bytes();
  out.stats_.transfer_entries = out.transfer_.emitter.size();
  return out;
}

bool PrmProbeLight::reproject(std::span<const glm::vec3> entry_irradiance) {
  if (entry_irradiance.size() != albedo_area_.size()) return false;
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<glm::vec3> power(albedo_area_.size());
  for (std::size_t i = 0; i < power.size(); ++i) power[i] = albedo_area_[i] * entry_irradiance[i];
  auto sh = reproject_world_probes(transfer_, power);
  if (!sh) return false;
  sh_ = std::move(sh).value();
  ++stats_.reprojections;
  stats_.last_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

bool PrmProbeLight::update(const PrmLighting& prm) {
  const std::uint64_t version = prm.entry_version();
  if (seen_any_ && version == seen_version_) return false;
  if (!seen_any_ && version == 0) return false;  // the PRM has not computed its light yet
  seen_any_ = true;
  seen_version_ = version;
  return reproject(prm.moving_entry_irradiance());
}

}  // namespace gi
