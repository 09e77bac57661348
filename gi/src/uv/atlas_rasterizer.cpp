#include "uv/atlas_rasterizer.h"

#include <engine/check.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "uv/texel_triangle.h"

namespace gi {
namespace {

constexpr float kTouchEpsilonTexels = 1e-4f;
// `s` moved towards the triangle's centroid until it lies `inset` texels inside every edge
// (or at the centroid of a triangle thinner than that). A sample on a chart's border is
// on the line where the next surface begins (a floor's edge under a wall): rays from it
// start on that wall's plane and slip behind it. Inside a chart the move stays on the
// same surface.
TrianglePoint inset_sample(const TrianglePoint& s, const glm::vec2 (&v)[3], double inset) {
  const glm::dvec2 a(v[0]), b(v[1]), c(v[2]);
  const double area2 = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  if (!(std::fabs(area2) > 1e-12)) return s;
  const double orient = area2 > 0.0 ? 1.0 : -1.0;
  const glm::dvec2 g = (a + b + c) / 3.0, p(s.point);
  const glm::dvec2 pts[3] = {a, b, c};
  double t = 0.0;
  for (int k = 0; k < 3; ++k) {
    const glm::dvec2 o = pts[k], e = pts[(k + 1) % 3] - o;
    const double len = glm::length(e);
    if (!(len > 0.0)) continue;
    const auto dist = [&](glm::dvec2 q) { return orient * (e.x * (q.y - o.y) - e.y * (q.x - o.x)) / len; };
    const double dp = dist(p), dg = dist(g);
    if (dp < inset && dg > dp) t = std::max(t, (inset - dp) / (dg - dp));
  }
  if (!(t > 0.0)) return s;
  const glm::vec2 moved(p + std::min(t, 1.0) * (g - p));
  return {moved, triangle_barycentric(moved, v[0], v[1], v[2])};
}

glm::vec3 shading_normal(const AtlasInputMesh& in, const std::uint32_t v[3], glm::vec3 w, glm::vec3 chart_normal) {
  if (!in.normals.empty()) {
    const glm::vec3 n = w.x * in.normals[v[0]] + w.y * in.normals[v[1]] + w.z * in.normals[v[2]];
    const float len = glm::length(n);
    if (len > 1e-6f && std::isfinite(len)) return n / len;
  }
  const glm::vec3 f = glm::cross(in.positions[v[1]] - in.positions[v[0]], in.positions[v[2]] - in.positions[v[0]]);
  const float len = glm::length(f);
  if (len > 0.0f && std::isfinite(len)) return f / len;
  return chart_normal;
}

}  // namespace

// Long because it is one scan conversion: per triangle, per texel of its box, the inside or
// conservative sample and its write to every texel array; the ownership rule between triangles is this loop.
AtlasTexels rasterize_atlas(const AtlasLayout& layout, std::span<const AtlasInputMesh> inputs, float inset_texels) {
  GI_EXPECTS(inputs.size() == layout.meshes.size(), "inputs are the meshes the layout was built from");
  AtlasTexels out;
  out.width = layout.width;
  out.height = layout.height;
  const std::size_t n = static_cast<std::size_t>(layout.width) * static_cast<std::size_t>(layout.height);
  out.position.resize(n);  // value-initialized: zero (memset rather than an element loop)
  out.normal.resize(n);
  out.valid.assign(n, 0);
  out.coverage.assign(n, TexelCoverage::Empty);
  out.mesh.assign(n, -1);
  out.triangle.assign(n, -1);
  out.chart.assign(n, -1);
  std::vector<float> distance(n, std::numeric_limits<float>::infinity());  // of conservative samples
  const glm::vec2 size(static_cast<float>(layout.width), static_cast<float>(layout.height));

  for (std::size_t mi = 0; mi < inputs.size(); ++mi) {
    const AtlasInputMesh& in = inputs[mi];
    const AtlasMeshUv& uv = layout.meshes[mi];
    GI_EXPECTS(uv.indices.size() == in.indices.size(), "layout mesh matches its input's triangles");
    for (std::size_t t = 0; t < uv.indices.size() / 3; ++t) {
      glm::vec2 p[3];
      std::uint32_t v[3];
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t o = uv.indices[3 * t + k];
        p[k] = uv.uv1[o] * size;
        v[k] = uv.source_vertex[o];
        GI_EXPECTS(v[k] < in.positions.size(), "layout vertex maps to an input vertex");
      }
      const std::uint32_t ci = uv.triangle_chart[t];
      const glm::vec3 chart_normal = layout.charts[ci].normal;
      const glm::vec2 lo = glm::min(p[0], glm::min(p[1], p[2])), hi = glm::max(p[0], glm::max(p[1], p[2]));
      const int x0 = std::max(0, static_cast<int>(std::floor(lo.x - kTouchEpsilonTexels)));
      const int y0 = std::max(0, static_cast<int>(std::floor(lo.y - kTouchEpsilonTexels)));
      const int x1 = std::min(layout.width - 1, static_cast<int>(std::floor(hi.x + kTouchEpsilonTexels)));
      const int y1 = std::min(layout.height - 1, static_cast<int>(std::floor(hi.y + kTouchEpsilonTexels)));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
          const std::size_t i = out.index(x, y);
          if (out.coverage[i] == TexelCoverage::Inside) continue;  // an earlier triangle owns the centre
          const glm::vec2 centre(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f);
          TrianglePoint s;
          TexelCoverage kind;
          float d = 0.0f;
          if (triangle_contains(centre, p[0], p[1], p[2])) {
            s = {centre, triangle_barycentric(centre, p[0], p[1], p[2])};
            kind = TexelCoverage::Inside;
          } else {
            const glm::vec2 cell(static_cast<float>(x), static_cast<float>(y));
            if (!triangle_overlaps_box(p[0], p[1], p[2], cell, cell + 1.0f, kTouchEpsilonTexels)) continue;
            s = closest_point_on_triangle(centre, p[0], p[1], p[2]);
            d = glm::length(s.point - centre);
            if (!(d < distance[i])) continue;  // an earlier or closer triangle keeps it
            kind = TexelCoverage::Conservative;
          }
          if (inset_texels > 0.0f) s = inset_sample(s, p, double{inset_texels});
          const glm::vec3 w = s.barycentric;
          distance[i] = d;
          out.coverage[i] = kind;
          out.valid[i] = 1;
          out.position[i] = w.x * in.positions[v[0]] + w.y * in.positions[v[1]] + w.z * in.positions[v[2]];
          out.normal[i] = shading_normal(in, v, w, chart_normal);
          out.mesh[i] = static_cast<std::int32_t>(mi);
          out.triangle[i] = static_cast<std::int32_t>(t);
          out.chart[i] = static_cast<std::int32_t>(ci);
        }
    }
  }
  return out;
}

}  // namespace gi
