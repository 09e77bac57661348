#include "antiradiance/near_door_visibility.h"

#include <algorithm>
#include <chrono>

namespace gi {
namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

NearDoorVisibilitySettings near_door_settings(const AntiradianceSettings& s) {
  NearDoorVisibilitySettings n;
  n.radius_m = s.near_visibility_radius_m;
  n.budget_bytes = static_cast<std::size_t>(s.near_visibility_budget_bytes);
  n.point_pairs = s.near_visibility_point_pairs;
  return n;
}

std::vector<char> near_door_receivers(const BakeInput& input, const ElementHierarchy& h, std::uint32_t door,
                                      const NearDoorVisibilitySettings& settings) {
  std::vector<char> mask(h.leaf_count(), 0);
  if (door >= input.instances.size() || input.instances[door].mesh >= input.meshes.size()) return mask;
  const glm::vec3 origin(input.instances[door].object_to_world[3]);
  float reach = 0.0f;
  for (const BakePrimitive& p : input.meshes[input.instances[door].mesh].primitives)
    for (const glm::vec3& v : p.positions) reach = std::max(reach, glm::length(v));
  // Each leaf's gap to the reached sphere (its bounding sphere's nearest point; <= 0 inside).
  std::vector<std::pair<float, std::size_t>> others;
  std::size_t receivers = 0;
  for (std::size_t l = 0; l < h.leaf_count(); ++l) {
    const auto node = static_cast<std::size_t>(h.leaves[l]);
    const ElementNode& e = h.nodes[node];
    const float gap = glm::length(e.center - origin) - reach - e.radius_m;
    mask[l] = h.node_instance[node] == static_cast<std::int32_t>(door) || gap <= settings.radius_m;
    if (mask[l])
      ++receivers;
    else
      others.emplace_back(gap, l);
  }
  const std::size_t row = h.leaf_count() * ExactLeafTransport::row_bytes_per_leaf(settings.point_pairs);
  if (settings.budget_bytes == 0 || row == 0) return mask;
  const std::size_t fit = settings.budget_bytes / row;
  if (fit <= receivers) return mask;
  const std::size_t more = std::min(fit - receivers, others.size());
  std::partial_sort(others.begin(), others.begin() + static_cast<std::ptrdiff_t>(more), others.end());
  for (std::size_t k = 0; k < more; ++k) mask[others[k].second] = 1;
  return mask;
}

engine::Result<NearDoorVisibility> NearDoorVisibility::create(const BakeInput& input, const AntiradianceRegion& region,
                                                              std::uint32_t door,
                                                              const NearDoorVisibilitySettings& settings) {
  if (door >= input.instances.size() || !input.instances[door].deforming)
    return engine::Error{.message = "near-door visibility: the door is not a deforming instance"};
  const ElementHierarchy& h = region.hierarchy();
  std::vector<char> mask = near_door_receivers(input, h, door, settings);
  const auto receivers = static_cast<std::size_t>(std::count(mask.begin(), mask.end(), char{1}));
  ExactTransportSettings es;
  es.point_pairs = settings.point_pairs;
  es.tolerance = settings.tolerance;
  es.seed = settings.seed;
  es.reuse_visibility = settings.reuse_visibility;
  es.streams = settings.streams;
  es.door_only_rays = settings.door_only_rays;
  auto t = ExactLeafTransport::create(input, es);
  if (!t) return t.error();
  NearDoorVisibility out(std::move(t).value());
  out.receivers_ = receivers;
  out.transport_.set_receivers(std::move(mask));
  out.transport_.update(h);
  const ExactSolveResult base = out.transport_.solve_receivers(h, region.direct(), region.baseline());
  out.baseline_ = base.irradiance;
  out.last_ = base.irradiance;
  out.iterations_ = base.iterations;
  out.warm_start_ = settings.warm_start;
  return out;
}

std::vector<glm::vec3> NearDoorVisibility::move(const AntiradianceRegion& region, std::uint32_t door,
                                                const glm::mat4& object_to_world) {
  const auto t0 = std::chrono::steady_clock::now();
  transport_.set_instance_transform(door, object_to_world);
  transport_.update(region.hierarchy());
  update_ms_ = ms_since(t0);
  const auto t1 = std::chrono::steady_clock::now();
  const std::vector<glm::vec3> others = region.irradiance();
  ExactSolveResult e =
      transport_.solve_receivers(region.hierarchy(), region.direct(), others,
                                 warm_start_ ? std::span<const glm::vec3>(last_) : std::span<const glm::vec3>());
  solve_ms_ = ms_since(t1);
  iterations_ = e.iterations;
  last_ = e.irradiance;
  return std::move(e.irradiance);
}

}  // namespace gi
