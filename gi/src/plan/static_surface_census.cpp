#include "plan/static_surface_census.h"

#include "core/color.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>
#include <glm/glm.hpp>

namespace gi {

namespace {

// Triangles of one instance are grouped by plane: normal directions within ~10 degrees
// (components rounded to 1/6) and offsets within 1 cm, like the charting's 20 degree
// near-coplanarity; pieces of a group that share no vertex are separate charts.
constexpr double kNormalCells = 6.0;
constexpr double kOffsetCell_m = 0.01;
constexpr double kWeldCell_m = 1e-4;

struct DisjointSets {
  std::vector<std::uint32_t> parent;
  explicit DisjointSets(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  std::uint32_t find(std::uint32_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  }
  void unite(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

std::uint64_t mix(std::uint64_t h, std::int64_t v) {
  h ^= static_cast<std::uint64_t>(v) + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
  return h;
}

std::int64_t cell(double v, double size) { return static_cast<std::int64_t>(std::llround(v / size)); }

struct Triangle {
  glm::dvec3 p[3];
  glm::dvec3 normal;
  double area = 0.0;
  std::uint64_t plane = 0;
};

void add_instance_charts(const std::vector<Triangle>& tris, std::vector<ChartExtent>& out) {
  DisjointSets sets(tris.size());
  std::unordered_map<std::uint64_t, std::uint32_t> first_at;  // (plane, welded position) -> triangle
  for (std::uint32_t t = 0; t < tris.size(); ++t)
    for (const glm::dvec3& p : tris[t].p) {
      std::uint64_t key = tris[t].plane;
      for (int c = 0; c < 3; ++c) key = mix(key, cell(p[c], kWeldCell_m));
      auto [it, inserted] = first_at.emplace(key, t);
      if (!inserted) sets.unite(t, it->second);
    }
  std::unordered_map<std::uint32_t, std::vector<std::uint32_t>> pieces;
  for (std::uint32_t t = 0; t < tris.size(); ++t) pieces[sets.find(t)].push_back(t);
  std::vector<std::uint32_t> roots;
  for (const auto& [root, members] : pieces) roots.push_back(root);
  std::sort(roots.begin(), roots.end());  // deterministic order
  for (std::uint32_t root : roots) {
    const std::vector<std::uint32_t>& members = pieces[root];
    ChartExtent chart;
    double longest = 0.0;
    glm::dvec3 n(0.0);
    for (std::uint32_t t : members) {
      chart.area_m2 += tris[t].area;
      n += tris[t].normal * tris[t].area;
      for (int e = 0; e < 3; ++e) {
        const glm::dvec3 edge = tris[t].p[(e + 1) % 3] - tris[t].p[e];
        longest = std::max(longest, glm::dot(edge, edge));
      }
    }
    if (longest <= 0.0 || glm::dot(n, n) <= 0.0) continue;
    n = glm::normalize(n);
    // The charting rotates a chart to its minimal-area rectangle; try the directions of the
    // piece's edges (a quad's diagonal is its longest edge but not a side).
    double best = 1e300;
    for (std::size_t k = 0; k < members.size() && k < 32; ++k) {
      const Triangle& tri = tris[members[k]];
      for (int e = 0; e < 3; ++e) {
        glm::dvec3 dir = tri.p[(e + 1) % 3] - tri.p[e];
        dir -= n * glm::dot(dir, n);
        if (glm::dot(dir, dir) <= 1e-18) continue;
        const glm::dvec3 a = glm::normalize(dir);
        const glm::dvec3 b = glm::cross(n, a);
        double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
        for (std::uint32_t t : members)
          for (const glm::dvec3& p : tris[t].p) {
            a0 = std::min(a0, glm::dot(p, a)), a1 = std::max(a1, glm::dot(p, a));
            b0 = std::min(b0, glm::dot(p, b)), b1 = std::max(b1, glm::dot(p, b));
          }
        if ((a1 - a0) * (b1 - b0) < best) {
          best = (a1 - a0) * (b1 - b0);
          chart.width_m = std::max(a1 - a0, b1 - b0);
          chart.height_m = std::min(a1 - a0, b1 - b0);
        }
      }
    }
    out.push_back(chart);
  }
}

}  // namespace

StaticSurfaceCensus census_static_surfaces(const BakeInput& input) {
  StaticSurfaceCensus census;
  double albedo_area = 0.0;
  for (const BakeInstance& inst : input.instances) {
    if (inst.mobility != BakeMobility::Static || inst.mesh >= input.meshes.size()) continue;
    const glm::dmat4 m(inst.object_to_world);
    std::vector<Triangle> tris;
    for (const BakePrimitive& prim : input.meshes[inst.mesh].primitives) {
      const glm::vec3 base = bake_material(input, inst, prim).base_color;
      const auto corner = [&](std::size_t k) {
        const std::size_t i = prim.indices.empty() ? k : prim.indices[k];
        return i < prim.positions.size() ? glm::dvec3(m * glm::dvec4(glm::dvec3(prim.positions[i]), 1.0))
                                         : glm::dvec3(0.0);
      };
      const std::size_t corners = prim.indices.empty() ? prim.positions.size() : prim.indices.size();
      for (std::size_t k = 0; k + 2 < corners; k += 3) {
        Triangle t{{corner(k), corner(k + 1), corner(k + 2)}, glm::dvec3(0.0), 0.0, 0};
        const glm::dvec3 c = glm::cross(t.p[1] - t.p[0], t.p[2] - t.p[0]);
        const double len = glm::length(c);
        if (!(len > 0.0) || !std::isfinite(len)) continue;
        t.area = 0.5 * len;
        t.normal = c / len;
        std::uint64_t key = 0x51ed270b27d3c8f1ull;
        for (int a = 0; a < 3; ++a) key = mix(key, cell(t.normal[a], 1.0 / kNormalCells));
        t.plane = mix(key, cell(glm::dot(t.normal, t.p[0]), kOffsetCell_m));
        census.area_m2 += t.area;
        ++census.triangles;
        albedo_area += luminance(double{base.x}, double{base.y}, double{base.z}) * t.area;
        tris.push_back(t);
      }
    }
    add_instance_charts(tris, census.charts);
  }
  census.albedo = census.area_m2 > 0.0 ? albedo_area / census.area_m2 : 0.0;
  return census;
}

}  // namespace gi
