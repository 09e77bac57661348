#include "reflection_probes/probe_placement.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

namespace gi {

namespace {

constexpr int kBundleSide = 5;  // rays per side of a bundle (odd: one ray through the centre)

struct Reach {
  float distance = 0.0f;  ///< To the nearest hit of the bundle, or to the world's bounds.
  bool inside = false;    ///< The centre ray hit a back face: the point is inside geometry.
};

glm::vec3 axis_direction(int side) {
  glm::vec3 d(0.0f);
  d[side / 2] = side % 2 == 0 ? 1.0f : -1.0f;
  return d;
}

// Distance from p along axis side (0: +x, 1: -x, 2: +y, ...) to the world's bound.
float to_bounds(const glm::vec3& p, int side, const glm::vec3& lo, const glm::vec3& hi) {
  const int a = side / 2;
  return std::max(0.0f, side % 2 == 0 ? hi[a] - p[a] : p[a] - lo[a]);
}

Reach reach(const RayCaster& caster, const glm::vec3& p, int side, const glm::vec3& lo, const glm::vec3& hi,
            float spread) {
  const glm::vec3 d = axis_direction(side);
  const int a = side / 2;
  const int ua = (a + 1) % 3, va = (a + 2) % 3;
  const float bound = to_bounds(p, side, lo, hi);
  Reach r;
  std::vector<float> distances;
  const int half = kBundleSide / 2;
  for (int j = -half; j <= half; ++j)
    for (int i = -half; i <= half; ++i) {
      glm::vec3 o = p;
      o[ua] += static_cast<float>(i) * spread / static_cast<float>(std::max(half, 1));
      o[va] += static_cast<float>(j) * spread / static_cast<float>(std::max(half, 1));
      const Hit h = caster.intersect(Ray{o, 0.0f, d, bound});
      if (i == 0 && j == 0 && h.valid() && glm::dot(h.geometric_normal, d) > 0.0f) r.inside = true;
      distances.push_back(h.valid() ? std::min(h.t, bound) : bound);
    }
  // The median: openings and obstacles that cover less than half the bundle do not count.
  std::nth_element(distances.begin(), distances.begin() + static_cast<std::ptrdiff_t>(distances.size() / 2),
                   distances.end());
  r.distance = distances[distances.size() / 2];
  return r;
}

// The box around free point p, or nullopt when p is inside geometry.
std::optional<ProbeVolume> measure(const RayCaster& caster, const glm::vec3& p, const glm::vec3& lo,
                                   const glm::vec3& hi, float spread) {
  ProbeVolume v;
  v.centre = p;
  v.box_min = p;
  v.box_max = p;
  for (int side = 0; side < 6; ++side) {
    const Reach r = reach(caster, p, side, lo, hi, spread);
    if (r.inside) return std::nullopt;
    if (side % 2 == 0)
      v.box_max[side / 2] = p[side / 2] + r.distance;
    else
      v.box_min[side / 2] = p[side / 2] - r.distance;
  }
  return v;
}

bool free_point(const RayCaster& caster, const glm::vec3& p, const glm::vec3& lo, const glm::vec3& hi) {
  for (int side = 0; side < 6; ++side)
    if (reach(caster, p, side, lo, hi, 0.0f).inside) return false;
  return true;
}

// `v` as it is, or, when it is a corridor (its longer horizontal side more than `aspect`
// times its shorter one), cut across its length into segments about as long as it is wide,
// each a probe at its centre (when free) whose box reaches kProbeFadeM / 2 into the next.
void add_probes(const RayCaster& caster, const ProbeVolume& v, float aspect, const glm::vec3& lo, const glm::vec3& hi,
                std::vector<ProbeVolume>& probes) {
  const glm::vec3 size = v.box_max - v.box_min;
  const int along = size.x >= size.z ? 0 : 2;
  const float length = size[along], width = size[2 - along];
  if (!(aspect > 0.0f) || !(length > aspect * width)) {
    probes.push_back(v);
    return;
  }
  const int count = static_cast<int>(std::lround(length / width));
  const float step = length / static_cast<float>(count);
  for (int k = 0; k < count; ++k) {
    ProbeVolume s = v;
    s.box_min[along] = v.box_min[along] + static_cast<float>(k) * step - (k > 0 ? 0.5f * kProbeFadeM : 0.0f);
    s.box_max[along] =
        v.box_min[along] + static_cast<float>(k + 1) * step + (k + 1 < count ? 0.5f * kProbeFadeM : 0.0f);
    glm::vec3 mid = v.centre;
    mid[along] = v.box_min[along] + (static_cast<float>(k) + 0.5f) * step;
    s.centre = free_point(caster, mid, lo, hi) ? mid : v.centre;
    probes.push_back(s);
  }
}

// The nearest surface along the six axes from p (front faces and back faces alike), at most `limit`.
float clearance(const RayCaster& caster, const glm::vec3& p, float limit) {
  float nearest = limit;
  for (int side = 0; side < 6; ++side) {
    const Hit h = caster.intersect(Ray{p, 0.0f, axis_direction(side), limit});
    if (h.valid()) nearest = std::min(nearest, h.t);
  }
  return nearest;
}

// Each box whose probe does not see more than `min_share` of its receivers gets a second probe with the same box.
void add_second_views(const RayCaster& caster, const glm::vec3& lo, const glm::vec3& hi,
                      const ProbePlacementSettings& settings, std::vector<ProbeVolume>& probes) {
  if (!(settings.second_view_min_share <= 1.0f)) return;
  const std::size_t first = probes.size();
  for (std::size_t i = 0; i < first && static_cast<int>(probes.size()) < settings.max_probes; ++i) {
    HiddenReceivers h = hidden_receivers(caster, probes[i], settings.receiver_step_m);
    if (settings.second_view_min_share < 0.0f) {  // the measurement's "every box": over the box's middle
      h.centroid = 0.5f * (probes[i].box_min + probes[i].box_max);
    } else if (h.hidden == 0 || !(h.share() > settings.second_view_min_share)) {
      continue;
    }
    const auto point = second_view_point(caster, probes[i], h, settings.second_view_height);
    if (!point || !free_point(caster, *point, lo, hi)) continue;
    ProbeVolume second = probes[i];
    second.centre = *point;
    probes.push_back(second);
  }
}

}  // namespace

HiddenReceivers hidden_receivers(const RayCaster& caster, const ProbeVolume& v, float step) {
  HiddenReceivers r;
  if (!(step > 0.0f)) return r;
  const glm::vec3 size = v.box_max - v.box_min;
  const int nx = std::max(1, static_cast<int>(std::lround(size.x / step)));
  const int nz = std::max(1, static_cast<int>(std::lround(size.z / step)));
  const glm::vec3 down(0.0f, -1.0f, 0.0f);
  glm::vec3 sum(0.0f);
  for (int z = 0; z < nz; ++z)
    for (int x = 0; x < nx; ++x) {
      const glm::vec3 o(v.box_min.x + (static_cast<float>(x) + 0.5f) * size.x / static_cast<float>(nx), v.centre.y,
                        v.box_min.z + (static_cast<float>(z) + 0.5f) * size.z / static_cast<float>(nz));
      const Hit below = caster.intersect(Ray{o, 0.0f, down, v.centre.y - v.box_min.y + 0.1f});
      if (!below.valid() || !(below.geometric_normal.y > 0.7f)) continue;  // none, or inside an object
      const glm::vec3 q = o + below.t * down + glm::vec3(0.0f, 0.01f, 0.0f);
      const glm::vec3 d = q - v.centre;
      const float length = glm::length(d);
      ++r.samples;
      if (!(length > 0.02f)) continue;
      const Hit h = caster.intersect(Ray{v.centre, 0.0f, d / length, length});
      if (h.valid() && h.t < length - 0.02f) {
        ++r.hidden;
        sum += q;
      }
    }
  if (r.hidden > 0) r.centroid = sum / static_cast<float>(r.hidden);
  return r;
}

std::optional<glm::vec3> second_view_point(const RayCaster& caster, const ProbeVolume& v, const HiddenReceivers& h,
                                           float height) {
  constexpr float kClearanceM = 0.3f, kStepM = 0.25f;
  constexpr int kRings = 4;  // up to 1 m from the centroid
  glm::vec3 base = h.centroid;
  base.y = v.box_min.y + std::min(height, 0.5f * (v.box_max.y - v.box_min.y));
  // The nearest point to the centroid (ring by ring of a 0.25 m grid around it, in the box) that
  // has kClearanceM to every surface along the axes.
  for (int ring = 0; ring <= kRings; ++ring)
    for (int dz = -ring; dz <= ring; ++dz)
      for (int dx = -ring; dx <= ring; ++dx) {
        if (std::max(std::abs(dx), std::abs(dz)) != ring) continue;
        const glm::vec3 q = base + kStepM * glm::vec3(static_cast<float>(dx), 0.0f, static_cast<float>(dz));
        if (!v.contains(q)) continue;
        if (clearance(caster, q, kClearanceM) >= kClearanceM) return q;
      }
  return std::nullopt;
}

namespace {

// One probe per room-sized box (and the segments of a cut corridor): place_probes without the second views.
std::vector<ProbeVolume> place_room_probes(const RayCaster& caster, const glm::vec3& world_min,
                                           const glm::vec3& world_max, const ProbePlacementSettings& settings) {
  std::vector<ProbeVolume> probes;
  const glm::vec3 extent = glm::max(world_max - world_min, glm::vec3(0.0f));
  // Two passes: cells of cell_m, then of cell_m / 2 for the space the first left without a
  // box. One grid of room-sized cells can step over a room narrower than a cell (the demo
  // level's 2 m corridor lies between two candidates 3.6 m apart and got no probe).
  for (const float cell : {settings.cell_m, 0.5f * settings.cell_m}) {
    glm::ivec3 n;
    for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::ceil(extent[a] / cell)));
    for (int y = 0; y < n.y; ++y)
      for (int z = 0; z < n.z; ++z)
        for (int x = 0; x < n.x; ++x) {
          if (static_cast<int>(probes.size()) >= settings.max_probes) return probes;
          glm::vec3 p = world_min + (glm::vec3(x, y, z) + 0.5f) / glm::vec3(n) * extent;
          const auto covered = [&](const glm::vec3& q) {
            return std::any_of(probes.begin(), probes.end(), [&](const ProbeVolume& v) { return v.contains(q); });
          };
          if (covered(p)) continue;
          if (cell < settings.cell_m) {
            // A finer candidate can sit next to a wall or a floor, where the bundles' spread
            // reaches past them (the corridor's first candidate, 0.9 m above its floor and
            // 0.2 m from its doorway, measured the whole level): it moves first to the middle
            // of what its centre rays see.
            const auto centre_rays = measure(caster, p, world_min, world_max, 0.0f);
            if (!centre_rays) continue;
            p = 0.5f * (centre_rays->box_min + centre_rays->box_max);
            if (covered(p)) continue;
          }
          auto v = measure(caster, p, world_min, world_max, settings.spread_m);
          if (!v) continue;
          const glm::vec3 size = v->box_max - v->box_min;
          if (std::min({size.x, size.y, size.z}) < settings.min_box_m) continue;
          glm::vec3 mid = 0.5f * (v->box_min + v->box_max);
          if (settings.capture_height > 0.0f) mid.y = v->box_min.y + std::min(settings.capture_height, 0.5f * size.y);
          if (free_point(caster, mid, world_min, world_max)) v->centre = mid;
          add_probes(caster, *v, settings.corridor_aspect, world_min, world_max, probes);
          if (static_cast<int>(probes.size()) > settings.max_probes)
            probes.resize(static_cast<std::size_t>(settings.max_probes));
        }
  }
  return probes;
}

}  // namespace

std::vector<ProbeVolume> place_probes(const RayCaster& caster, const glm::vec3& world_min, const glm::vec3& world_max,
                                      const ProbePlacementSettings& settings) {
  std::vector<ProbeVolume> probes = place_room_probes(caster, world_min, world_max, settings);
  add_second_views(caster, world_min, world_max, settings, probes);
  return probes;
}

float probe_blend_weight(const ProbeVolume& v, const glm::vec3& p, float margin) {
  if (glm::any(glm::lessThan(p, v.box_min - margin)) || glm::any(glm::greaterThan(p, v.box_max + margin))) return 0.0f;
  const glm::vec3 depth = glm::min(p - v.box_min, v.box_max - p);
  const glm::vec3 f = glm::clamp(depth / kProbeFadeM, glm::vec3(1e-3f), glm::vec3(1.0f));
  return f.x * f.y * f.z;
}

}  // namespace gi
