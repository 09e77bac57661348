#include "uv/texel_triangle.h"

#include <algorithm>
#include <cmath>

namespace gi {
namespace {

double edge(glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) { return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x); }

// Closest point of segment ab to p: parameter t in [0, 1] along ab.
double segment_param(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  const glm::dvec2 d = b - a;
  const double len2 = glm::dot(d, d);
  return len2 > 0.0 ? std::clamp(glm::dot(p - a, d) / len2, 0.0, 1.0) : 0.0;
}

}  // namespace

bool triangle_contains(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  const glm::dvec2 P(p), A(a), B(b), C(c);
  const double area = edge(A, B, C);
  if (area == 0.0) return false;
  const double s = area > 0.0 ? 1.0 : -1.0;
  return s * edge(A, B, P) >= 0.0 && s * edge(B, C, P) >= 0.0 && s * edge(C, A, P) >= 0.0;
}

glm::vec3 triangle_barycentric(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  const glm::dvec2 P(p), A(a), B(b), C(c);
  const double area = edge(A, B, C);
  const double wa = edge(B, C, P) / area, wb = edge(C, A, P) / area;
  return glm::vec3(glm::dvec3(wa, wb, 1.0 - wa - wb));
}

TrianglePoint closest_point_on_triangle(glm::vec2 p, glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  if (triangle_contains(p, a, b, c)) return {p, triangle_barycentric(p, a, b, c)};
  const glm::dvec2 P(p), V[3] = {glm::dvec2(a), glm::dvec2(b), glm::dvec2(c)};
  TrianglePoint best;
  double best_d2 = INFINITY;
  for (int e = 0; e < 3; ++e) {
    const int i = e, j = (e + 1) % 3;
    const double t = segment_param(P, V[i], V[j]);
    const glm::dvec2 q = V[i] + t * (V[j] - V[i]);
    const double d2 = glm::dot(q - P, q - P);
    if (d2 < best_d2) {
      best_d2 = d2;
      glm::dvec3 w(0.0);
      w[i] = 1.0 - t;
      w[j] = t;
      best = {glm::vec2(q), glm::vec3(w)};
    }
  }
  return best;
}

bool triangle_overlaps_box(glm::vec2 a, glm::vec2 b, glm::vec2 c, glm::vec2 lo, glm::vec2 hi, float eps) {
  const glm::dvec2 L = glm::dvec2(lo) - double(eps), H = glm::dvec2(hi) + double(eps);
  const glm::dvec2 V[3] = {glm::dvec2(a), glm::dvec2(b), glm::dvec2(c)};
  // Box axes.
  for (int k = 0; k < 2; ++k) {
    const double mn = std::min({V[0][k], V[1][k], V[2][k]}), mx = std::max({V[0][k], V[1][k], V[2][k]});
    if (mx < L[k] || mn > H[k]) return false;
  }
  // Edge normals (covers degenerate triangles: a segment's own normal is among them).
  const glm::dvec2 corners[4] = {L, {H.x, L.y}, H, {L.x, H.y}};
  for (int e = 0; e < 3; ++e) {
    const glm::dvec2 d = V[(e + 1) % 3] - V[e];
    const glm::dvec2 n(-d.y, d.x);
    if (n == glm::dvec2(0.0)) continue;
    double tmin = INFINITY, tmax = -INFINITY;
    for (const glm::dvec2& v : V) {
      tmin = std::min(tmin, glm::dot(n, v));
      tmax = std::max(tmax, glm::dot(n, v));
    }
    double bmin = INFINITY, bmax = -INFINITY;
    for (const glm::dvec2& v : corners) {
      bmin = std::min(bmin, glm::dot(n, v));
      bmax = std::max(bmax, glm::dot(n, v));
    }
    if (tmax < bmin || tmin > bmax) return false;
  }
  return true;
}

}  // namespace gi
