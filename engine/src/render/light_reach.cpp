#include <engine/light_reach.h>
#include <engine/segment_box.h>

#include <algorithm>
#include <cmath>

namespace engine {

namespace {

// Moeller-Trumbore, both faces; t in units of |d| (d not normalized).
bool segment_hits_triangle(const glm::vec3& p, const glm::vec3& d, const ReachTriangle& tri, float t_min, float t_max) {
  const glm::vec3 e1 = tri.b - tri.a;
  const glm::vec3 e2 = tri.c - tri.a;
  const glm::vec3 h = glm::cross(d, e2);
  const float det = glm::dot(e1, h);
  if (std::abs(det) < 1e-12f) return false;
  const float inv = 1.0f / det;
  const glm::vec3 s = p - tri.a;
  const float u = glm::dot(s, h) * inv;
  if (u < 0.0f || u > 1.0f) return false;
  const glm::vec3 q = glm::cross(s, e1);
  const float v = glm::dot(d, q) * inv;
  if (v < 0.0f || u + v > 1.0f) return false;
  const float t = glm::dot(e2, q) * inv;
  return t > t_min && t < t_max;
}

}  // namespace

bool segment_blocked(const std::vector<ReachOccluder>& occluders, const glm::vec3& p, const glm::vec3& q,
                     float end_margin_m) {
  const glm::vec3 d = q - p;
  const float len = glm::length(d);
  if (len <= 2.0f * end_margin_m) return false;
  const float t_min = end_margin_m / len;
  const float t_max = 1.0f - t_min;
  for (const ReachOccluder& o : occluders) {
    if (!segment_meets_box(p, d, 1.0f, o.min, o.max)) continue;
    for (const ReachTriangle& tri : o.triangles)
      if (segment_hits_triangle(p, d, tri, t_min, t_max)) return true;
  }
  return false;
}

std::uint8_t LightReachGrid::at(const glm::vec3& p) const {
  if (masks.empty()) return all;
  const glm::vec3 f = (p - origin) / voxel_m;
  const glm::ivec3 i(static_cast<int>(std::floor(f.x)), static_cast<int>(std::floor(f.y)),
                     static_cast<int>(std::floor(f.z)));
  if (i.x < 0 || i.y < 0 || i.z < 0 || i.x >= dims.x || i.y >= dims.y || i.z >= dims.z) return all;
  return masks[static_cast<std::size_t>((i.z * dims.y + i.y) * dims.x + i.x)];
}

// Long because it is one build in three passes over one grid: the light samples, what
// each lattice point sees of them, then each voxel as its corners' union dilated by one voxel.
LightReachGrid build_light_reach_grid(const std::vector<ReachOccluder>& occluders,
                                      const std::vector<ReachLight>& lights, const glm::vec3& min, const glm::vec3& max,
                                      float voxel_m) {
  LightReachGrid g;
  g.voxel_m = voxel_m;
  const int n_lights = std::min(static_cast<int>(lights.size()), LightReachGrid::kMaxLights);
  g.all = static_cast<std::uint8_t>((1u << n_lights) - 1u);
  if (n_lights == 0 || !(voxel_m > 0.0f) || glm::any(glm::lessThan(max, min))) return g;
  g.origin = min - glm::vec3(voxel_m);
  const glm::vec3 extent = (max + glm::vec3(voxel_m) - g.origin) / voxel_m;
  g.dims = glm::ivec3(static_cast<int>(std::ceil(extent.x)), static_cast<int>(std::ceil(extent.y)),
                      static_cast<int>(std::ceil(extent.z)));
  g.dims = glm::max(g.dims, glm::ivec3(1));

  // Light sample points: a point light's position; an area light's 3 x 3 grid over its
  // rectangle (corners included).
  struct Sample {
    glm::vec3 p;
    int light;
  };
  std::vector<Sample> samples;
  std::vector<glm::vec3> facing(static_cast<std::size_t>(n_lights), glm::vec3(0.0f));
  for (int l = 0; l < n_lights; ++l) {
    const ReachLight& L = lights[static_cast<std::size_t>(l)];
    const bool area = glm::dot(L.half_x, L.half_x) > 0.0f && glm::dot(L.half_y, L.half_y) > 0.0f;
    if (!area) {
      samples.push_back({L.position, l});
      continue;
    }
    facing[static_cast<std::size_t>(l)] = L.direction;
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i)
        samples.push_back({L.position + static_cast<float>(i) * L.half_x + static_cast<float>(j) * L.half_y, l});
  }

  // Lattice points (the voxels' corners).
  const glm::ivec3 pts = g.dims + 1;
  const auto point_index = [&](int x, int y, int z) { return static_cast<std::size_t>((z * pts.y + y) * pts.x + x); };
  std::vector<std::uint8_t> seen(
      static_cast<std::size_t>(pts.x) * static_cast<std::size_t>(pts.y) * static_cast<std::size_t>(pts.z), 0);
  constexpr float kEndMargin = 5e-3f;  // the area light's emissive quad sits 0.1 mm in front of it
  for (int z = 0; z < pts.z; ++z)
    for (int y = 0; y < pts.y; ++y)
      for (int x = 0; x < pts.x; ++x) {
        const glm::vec3 p = g.origin + glm::vec3(x, y, z) * voxel_m;
        std::uint8_t m = 0;
        for (const Sample& s : samples) {
          const std::uint8_t bit = static_cast<std::uint8_t>(1u << s.light);
          if (m & bit) continue;
          const glm::vec3& f = facing[static_cast<std::size_t>(s.light)];
          if (glm::dot(f, f) > 0.0f && glm::dot(p - lights[static_cast<std::size_t>(s.light)].position, f) <= 0.0f)
            continue;  // behind a one-sided area light
          if (!segment_blocked(occluders, p, s.p, kEndMargin)) m = static_cast<std::uint8_t>(m | bit);
        }
        seen[point_index(x, y, z)] = m;
      }

  // Voxel = union of its corners, then dilated by one voxel.
  const std::size_t n =
      static_cast<std::size_t>(g.dims.x) * static_cast<std::size_t>(g.dims.y) * static_cast<std::size_t>(g.dims.z);
  std::vector<std::uint8_t> corners(n, 0);
  const auto voxel_index = [&](int x, int y, int z) {
    return static_cast<std::size_t>((z * g.dims.y + y) * g.dims.x + x);
  };
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        std::uint8_t m = 0;
        for (int c = 0; c < 8; ++c)
          m = static_cast<std::uint8_t>(m | seen[point_index(x + (c & 1), y + ((c >> 1) & 1), z + (c >> 2))]);
        corners[voxel_index(x, y, z)] = m;
      }
  g.masks.assign(n, 0);
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        std::uint8_t m = 0;
        for (int dz = -1; dz <= 1; ++dz)
          for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
              const int xx = x + dx, yy = y + dy, zz = z + dz;
              if (xx < 0 || yy < 0 || zz < 0 || xx >= g.dims.x || yy >= g.dims.y || zz >= g.dims.z) continue;
              m = static_cast<std::uint8_t>(m | corners[voxel_index(xx, yy, zz)]);
            }
        g.masks[voxel_index(x, y, z)] = m;
      }
  return g;
}

}  // namespace engine
