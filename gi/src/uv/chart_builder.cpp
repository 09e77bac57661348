#include "uv/chart_builder.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numeric>
#include <unordered_map>
#include <utility>

namespace gi {
namespace {

constexpr std::uint32_t kUnassigned = std::numeric_limits<std::uint32_t>::max();

// Canonical vertex per vertex: the lowest-index vertex within `eps` found in the 27 grid
// cells around it (a hash grid of cell size eps). Deterministic: cells keep insertion order.
std::vector<std::uint32_t> weld_vertices(const std::vector<glm::vec3>& positions, float eps) {
  std::vector<std::uint32_t> canon(positions.size());
  if (!(eps > 0.0f)) {
    std::iota(canon.begin(), canon.end(), 0u);
    return canon;
  }
  struct CellHash {
    std::size_t operator()(const glm::i64vec3& c) const {
      const auto h = static_cast<std::uint64_t>(c.x) * 0x9E3779B97F4A7C15ull ^
                     static_cast<std::uint64_t>(c.y) * 0xC2B2AE3D27D4EB4Full ^
                     static_cast<std::uint64_t>(c.z) * 0x165667B19E3779F9ull;
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  std::unordered_map<glm::i64vec3, std::vector<std::uint32_t>, CellHash> cells;
  cells.reserve(positions.size());
  const double limit = 4.0e18;  // keeps cell coordinates inside int64 for huge coordinates
  auto cell_of = [&](glm::vec3 p) {
    glm::i64vec3 c;
    for (int k = 0; k < 3; ++k)
      c[k] = static_cast<std::int64_t>(
          std::clamp(std::floor(static_cast<double>(p[k]) / static_cast<double>(eps)), -limit, limit));
    return c;
  };
  const float eps2 = eps * eps;
  for (std::uint32_t v = 0; v < positions.size(); ++v) {
    const glm::i64vec3 c = cell_of(positions[v]);
    std::uint32_t found = kUnassigned;
    for (std::int64_t dz = -1; dz <= 1; ++dz)
      for (std::int64_t dy = -1; dy <= 1; ++dy)
        for (std::int64_t dx = -1; dx <= 1; ++dx) {
          const auto it = cells.find(c + glm::i64vec3(dx, dy, dz));
          if (it == cells.end()) continue;
          for (std::uint32_t r : it->second) {
            const glm::vec3 d = positions[r] - positions[v];
            if (glm::dot(d, d) <= eps2 && r < found) found = r;
          }
        }
    if (found == kUnassigned) {
      canon[v] = v;
      cells[c].push_back(v);
    } else {
      canon[v] = canon[found];
    }
  }
  return canon;
}

// Compressed adjacency lists: neighbours of item i are list[offset[i] .. offset[i+1]).
struct Adjacency {
  std::vector<std::uint32_t> offset;
  std::vector<std::uint32_t> list;
};

// Builds adjacency from (key, item) pairs: items sharing a key are neighbours of each other.
Adjacency adjacency_from_keys(std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed, std::size_t items) {
  std::sort(keyed.begin(), keyed.end());
  std::vector<std::vector<std::uint32_t>> lists(items);
  for (std::size_t b = 0; b < keyed.size();) {
    std::size_t e = b;
    while (e < keyed.size() && keyed[e].first == keyed[b].first) ++e;
    for (std::size_t i = b; i < e; ++i)
      for (std::size_t j = b; j < e; ++j)
        if (keyed[i].second != keyed[j].second) lists[keyed[i].second].push_back(keyed[j].second);
    b = e;
  }
  Adjacency adj;
  adj.offset.push_back(0);
  for (auto& l : lists) {
    std::sort(l.begin(), l.end());
    l.erase(std::unique(l.begin(), l.end()), l.end());
    adj.list.insert(adj.list.end(), l.begin(), l.end());
    adj.offset.push_back(static_cast<std::uint32_t>(adj.list.size()));
  }
  return adj;
}

// Orthonormal basis around a unit normal: Duff et al. 2017, "Building an Orthonormal Basis,
// Revisited" (JCGT 6(1)), listing 3.
void orthonormal_basis(glm::vec3 n, glm::vec3& b1, glm::vec3& b2) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float b = n.x * n.y * a;
  b1 = glm::vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x);
  b2 = glm::vec3(b, sign + n.y * n.y * a, -n.y);
}

float cross2(glm::vec2 o, glm::vec2 a, glm::vec2 b) { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); }

// Convex hull, Andrew's monotone chain (counter-clockwise, no collinear points).
std::vector<glm::vec2> convex_hull(std::vector<glm::vec2> pts) {
  std::sort(pts.begin(), pts.end(), [](glm::vec2 a, glm::vec2 b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  pts.erase(std::unique(pts.begin(), pts.end()), pts.end());
  if (pts.size() < 3) return pts;
  std::vector<glm::vec2> h(2 * pts.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    while (k >= 2 && cross2(h[k - 2], h[k - 1], pts[i]) <= 0.0f) --k;
    h[k++] = pts[i];
  }
  for (std::size_t i = pts.size() - 1, t = k + 1; i > 0; --i) {
    while (k >= t && cross2(h[k - 2], h[k - 1], pts[i - 1]) <= 0.0f) --k;
    h[k++] = pts[i - 1];
  }
  h.resize(k - 1);
  return h;
}

// Fills the chart's projection: normal, in-plane axes (rotated so the bounding rectangle has
// minimal area: it has a side collinear with a hull edge, Freeman & Shapira 1975), rectangle.
// Long because it is one projection: normal and axes, the points in the plane, the
// minimal-area rotation, then the wider-than-tall turn; axes and points change together at each step.
void project_chart(Chart& chart, const AtlasInputMesh& mesh, const std::vector<glm::vec3>& face_cross, bool rotate) {
  glm::dvec3 sum(0.0);
  double area = 0.0;
  for (std::uint32_t t : chart.triangles) {
    sum += glm::dvec3(face_cross[t]);
    area += 0.5 * glm::length(glm::dvec3(face_cross[t]));
  }
  chart.area_m2 = area;
  const double len = glm::length(sum);
  chart.normal = len > 0.0 && std::isfinite(len) ? glm::vec3(sum / len) : glm::vec3(0.0f, 0.0f, 1.0f);
  orthonormal_basis(chart.normal, chart.axis_u, chart.axis_v);
  chart.origin = mesh.positions[mesh.indices[3 * chart.triangles.front()]];
  chart.min_m = glm::vec2(0.0f);

  std::vector<glm::vec2> pts;
  pts.reserve(chart.triangles.size() * 3);
  for (std::uint32_t t : chart.triangles)
    for (int k = 0; k < 3; ++k) pts.push_back(chart.project_m(mesh.positions[mesh.indices[3 * t + k]]));

  if (rotate) {
    const std::vector<glm::vec2> hull = convex_hull(pts);
    float best_area = std::numeric_limits<float>::infinity();
    glm::vec2 best_dir(1.0f, 0.0f);
    for (std::size_t i = 0; i < hull.size() && hull.size() >= 3; ++i) {
      glm::vec2 d = hull[(i + 1) % hull.size()] - hull[i];
      const float l = glm::length(d);
      if (!(l > 0.0f)) continue;
      d /= l;
      glm::vec2 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
      for (glm::vec2 p : hull) {
        const glm::vec2 q(glm::dot(p, d), -d.y * p.x + d.x * p.y);
        lo = glm::min(lo, q);
        hi = glm::max(hi, q);
      }
      const float a = (hi.x - lo.x) * (hi.y - lo.y);
      if (a < best_area * (1.0f - 1e-5f)) {
        best_area = a;
        best_dir = d;
      }
    }
    const glm::vec3 u = best_dir.x * chart.axis_u + best_dir.y * chart.axis_v;
    const glm::vec3 v = -best_dir.y * chart.axis_u + best_dir.x * chart.axis_v;
    chart.axis_u = u;
    chart.axis_v = v;
    for (glm::vec2& p : pts) p = glm::vec2(p.x * best_dir.x + p.y * best_dir.y, -best_dir.y * p.x + best_dir.x * p.y);
  }
  glm::vec2 lo(std::numeric_limits<float>::infinity()), hi(-std::numeric_limits<float>::infinity());
  for (glm::vec2 p : pts) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  if (rotate && hi.y - lo.y > hi.x - lo.x) {
    // Wider than tall packs better on shelves: (u, v) -> (v, -u) keeps u x v = normal.
    const glm::vec3 u = chart.axis_v, v = -chart.axis_u;
    chart.axis_u = u;
    chart.axis_v = v;
    lo = glm::vec2(std::numeric_limits<float>::infinity());
    hi = glm::vec2(-std::numeric_limits<float>::infinity());
    for (glm::vec2 p : pts) {
      const glm::vec2 q(p.y, -p.x);
      lo = glm::min(lo, q);
      hi = glm::max(hi, q);
    }
  }
  chart.min_m = lo;
  chart.size_m = hi - lo;
}

}  // namespace

// Long because it is one charting pipeline: face normals, welded-edge adjacency, flood fill by
// angle, degenerate triangles' placement, then projection; each stage reads the previous one's arrays.
std::vector<Chart> build_charts(const AtlasInputMesh& mesh, std::uint32_t mesh_index,
                                const ChartingSettings& settings) {
  const std::size_t tri_count = mesh.indices.size() / 3;
  const std::vector<std::uint32_t> canon = weld_vertices(mesh.positions, settings.weld_distance_m);

  std::vector<glm::vec3> face_cross(tri_count);
  std::vector<glm::vec3> face_normal(tri_count);
  std::vector<bool> degenerate(tri_count);
  for (std::size_t t = 0; t < tri_count; ++t) {
    const glm::vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
                    c = mesh.positions[mesh.indices[3 * t + 2]];
    const glm::vec3 w = glm::cross(b - a, c - a);
    const float longest2 = std::max({glm::dot(b - a, b - a), glm::dot(c - b, c - b), glm::dot(a - c, a - c)});
    const float len = glm::length(w);
    degenerate[t] = !std::isfinite(len) || !(len > kDegenerateRelativeArea * longest2);
    face_cross[t] = std::isfinite(len) ? w : glm::vec3(0.0f);
    face_normal[t] = degenerate[t] ? glm::vec3(0.0f) : w / len;
  }

  // Triangles sharing a welded edge are neighbours.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> edge_keys;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> vertex_keys;
  edge_keys.reserve(3 * tri_count);
  vertex_keys.reserve(3 * tri_count);
  for (std::uint32_t t = 0; t < tri_count; ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint64_t a = canon[mesh.indices[3 * t + k]], b = canon[mesh.indices[3 * t + (k + 1) % 3]];
      vertex_keys.emplace_back(a, t);
      if (a != b) edge_keys.emplace_back((std::min(a, b) << 32) | std::max(a, b), t);
    }
  const Adjacency edges = adjacency_from_keys(std::move(edge_keys), tri_count);

  std::vector<std::uint32_t> chart_of(tri_count, kUnassigned);
  std::vector<Chart> charts;
  const float cos_max = std::cos(glm::radians(settings.max_angle_degrees));
  std::deque<std::uint32_t> queue;
  for (std::uint32_t seed = 0; seed < tri_count; ++seed) {
    if (degenerate[seed] || chart_of[seed] != kUnassigned) continue;
    const auto id = static_cast<std::uint32_t>(charts.size());
    charts.emplace_back();
    chart_of[seed] = id;
    queue.push_back(seed);
    while (!queue.empty()) {
      const std::uint32_t t = queue.front();
      queue.pop_front();
      for (std::uint32_t i = edges.offset[t]; i < edges.offset[t + 1]; ++i) {
        const std::uint32_t u = edges.list[i];
        if (degenerate[u] || chart_of[u] != kUnassigned) continue;
        if (glm::dot(face_normal[u], face_normal[seed]) < cos_max) continue;
        chart_of[u] = id;
        queue.push_back(u);
      }
    }
  }

  // Degenerate triangles join a chart through a shared welded vertex (repeat for chains of
  // degenerate triangles); the rest get charts of their own.
  const Adjacency by_vertex = adjacency_from_keys(std::move(vertex_keys), tri_count);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::uint32_t t = 0; t < tri_count; ++t) {
      if (chart_of[t] != kUnassigned) continue;
      for (std::uint32_t i = by_vertex.offset[t]; i < by_vertex.offset[t + 1]; ++i)
        if (chart_of[by_vertex.list[i]] != kUnassigned) {
          chart_of[t] = chart_of[by_vertex.list[i]];
          changed = true;
          break;
        }
    }
  }
  for (std::uint32_t t = 0; t < tri_count; ++t)
    if (chart_of[t] == kUnassigned) {
      chart_of[t] = static_cast<std::uint32_t>(charts.size());
      charts.emplace_back();
    }

  for (std::uint32_t t = 0; t < tri_count; ++t) charts[chart_of[t]].triangles.push_back(t);
  for (Chart& c : charts) {
    c.mesh = mesh_index;
    project_chart(c, mesh, face_cross, settings.rotate_to_min_area);
  }
  return charts;
}

}  // namespace gi
