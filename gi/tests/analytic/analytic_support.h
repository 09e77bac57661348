#pragma once
// Shared pieces of the analytic-truth tests (docs/analytic_truth.md): scenes as plain
// BakeInput data, the texels a bake fills, an independent implementation of glTF 2.0's
// Appendix B BRDF with its own quadrature, and per-texel error statistics.
//   gi::BakeInput in = analytic::closed_box(2.0f, material);
//   analytic::ErrorStats e; e.add(value, truth); e.print("atlas");

#include <gi/bake_input.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace analytic {

inline constexpr double kPi = std::numbers::pi;

/// A quad with corners c, c+u, c+u+v, c+v, front side along cross(u, v), as two triangles.
inline void add_quad(gi::BakePrimitive& p, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const auto base = static_cast<std::uint32_t>(p.positions.size());
  p.positions.insert(p.positions.end(), {c, c + u, c + u + v, c + v});
  p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// Adds a static instance of a one-primitive mesh with its own material.
inline void add_static(gi::BakeInput& in, gi::BakePrimitive p, gi::BakeMaterial m, const char* name) {
  p.material = static_cast<int>(in.materials.size());
  m.name = name;
  in.materials.push_back(m);
  gi::BakeMesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(std::move(p));
  in.instances.push_back(gi::BakeInstance{.name = name,
                                          .mesh = static_cast<std::uint32_t>(in.meshes.size()),
                                          .id = static_cast<std::int64_t>(in.instances.size())});
  in.meshes.push_back(std::move(mesh));
}

/// The closed cube [-s/2, s/2]^3, six faces facing inwards, one material.
inline gi::BakeInput closed_box(float s, const gi::BakeMaterial& m) {
  gi::BakePrimitive p;
  const float h = 0.5f * s;
  add_quad(p, {-h, -h, -h}, {0, 0, s}, {s, 0, 0});  // floor y = -h, faces +y
  add_quad(p, {-h, h, -h}, {s, 0, 0}, {0, 0, s});   // ceiling, -y
  add_quad(p, {-h, -h, -h}, {s, 0, 0}, {0, s, 0});  // z = -h, +z
  add_quad(p, {-h, -h, h}, {0, s, 0}, {s, 0, 0});   // z = +h, -z
  add_quad(p, {-h, -h, -h}, {0, s, 0}, {0, 0, s});  // x = -h, +x
  add_quad(p, {h, -h, -h}, {0, 0, s}, {0, s, 0});   // x = +h, -x
  gi::BakeInput in;
  in.name = "closed box";
  add_static(in, std::move(p), m, "box");
  return in;
}

/// Distance (m) from a point on the surface of the cube [-h, h]^3 to the nearest of its edges.
inline float box_edge_distance(glm::vec3 p, float h) {
  const glm::vec3 d = h - glm::abs(p);  // 0 along the axis of the face the point is on
  const float a = std::min(d.x, std::min(d.y, d.z));
  // The two in-plane distances: drop the smallest (the face's own axis).
  if (a == d.x) return std::min(d.y, d.z);
  if (a == d.y) return std::min(d.x, d.z);
  return std::min(d.x, d.y);
}

/// A point light of `intensity` W/sr at `position` (moves: PRM's kind of light).
inline gi::BakeLight point_light(glm::vec3 position, float intensity, bool moves = false) {
  gi::BakeLight l;
  l.name = "lamp";
  l.light.type = engine::LightType::Point;
  l.light.intensity = intensity;
  l.light.moves = moves;
  l.light_to_world = glm::translate(glm::mat4(1.0f), position);
  return l;
}

inline gi::BakeMaterial lambert(float albedo) {
  // specular 0: glTF's dielectric without its GGX layer, a pure Lambertian of the base colour.
  return gi::BakeMaterial{.base_color = glm::vec3(albedo), .metallic = 0.0f, .roughness = 1.0f, .specular = 0.0f};
}

/// The texels a bake of `input` at `texels_per_metre` fills (the bakers' own layout).
inline gi::AtlasTexels texels_of(const gi::BakeInput& input, const gi::AtlasLayout& layout) {
  return gi::rasterize_atlas(layout, gi::atlas_inputs_from(input));
}

/// Per-sample relative errors |x - t| / t: max, RMS, mean signed (bias); with the worst's index.
struct ErrorStats {
  double max_rel = 0.0, sum_sq = 0.0, sum = 0.0;
  std::size_t n = 0, worst = 0;
  void add(double x, double truth, std::size_t id = 0) {
    const double r = (x - truth) / truth;
    if (std::fabs(r) > max_rel || n == 0) max_rel = std::max(max_rel, std::fabs(r)), worst = id;
    sum_sq += r * r;
    sum += r;
    ++n;
  }
  double rms() const { return n ? std::sqrt(sum_sq / static_cast<double>(n)) : 0.0; }
  double bias() const { return n ? sum / static_cast<double>(n) : 0.0; }
  void print(const char* what) const {
    std::printf("  %-52s n %5zu  max %7.4f  rms %7.4f  bias %+8.4f\n", what, n, max_rel, rms(), bias());
  }
};

// ---- glTF 2.0 Appendix B, written again from the specification (independent of
// engine/gltf_brdf.cpp), for the tests' own quadrature of the directional albedo. ----

struct SpecBrdf {
  double alpha = 1.0;  // roughness^2 (roughness clamped like the engine's, see below)
  bool metal = false;  // base colour 1 (white) in both cases
};

inline SpecBrdf spec_brdf(double roughness, bool metal) {
  const double r = std::clamp(roughness, 0.045, 1.0);  // engine::kGltfMinRoughness
  return {r * r, metal};
}

inline double spec_d(double n_dot_h, double a) {
  const double a2 = a * a, c = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
  return a2 / (kPi * c * c);
}

inline double spec_v(double nv, double nl, double a) {
  const double a2 = a * a;
  const double gv = nl * std::sqrt(nv * nv * (1.0 - a2) + a2);
  const double gl = nv * std::sqrt(nl * nl * (1.0 - a2) + a2);
  return gv + gl > 0.0 ? 0.5 / (gv + gl) : 0.0;
}

/// Directional albedo of a white surface (base colour 1) at cos(theta_v) = nv, by a
/// product midpoint rule: the specular lobe over the half vector with the GGX variable
/// change tan^2(theta_h) = alpha^2 u / (1 - u) (so the peak is resolved at alpha 0.002)
/// and 1 - u = (1 - s)^2 (so its grazing tail converges),
/// the diffuse lobe over l with a cosine-mapped grid. Returns {diffuse, specular}.
inline glm::dvec2 spec_directional_albedo(const SpecBrdf& m, double nv, int nu = 512, int nphi = 256) {
  const glm::dvec3 v(std::sqrt(std::max(0.0, 1.0 - nv * nv)), 0.0, nv);
  const double f0 = m.metal ? 1.0 : 0.04;
  double spec = 0.0, diff = 0.0;
  for (int i = 0; i < nu; ++i) {
    const double u = (i + 0.5) / nu;
    // Specular: D(h) (n.h) dw_h = du dphi / (2 pi) under this mapping; dl = 4 (v.h) dw_h. The
    // integrand then grows as 1 / cos(theta_h) ~ 1 / sqrt(1 - u) at u -> 1; a second change
    // 1 - u = (1 - s)^2 (du = 2 (1 - s) ds) removes that singularity.
    const double su = 1.0 - (1.0 - u) * (1.0 - u), jac = 2.0 * (1.0 - u);
    const double t2 = m.alpha * m.alpha * su / (1.0 - su);
    const double ch = 1.0 / std::sqrt(1.0 + t2), sh = std::sqrt(std::max(0.0, 1.0 - ch * ch));
    for (int j = 0; j < nphi; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / nphi;
      const glm::dvec3 h(sh * std::cos(phi), sh * std::sin(phi), ch);
      const double vh = glm::dot(v, h);
      if (vh <= 0.0) continue;
      const glm::dvec3 l = 2.0 * vh * h - v;
      if (l.z <= 0.0) continue;
      const double fres = f0 + (1.0 - f0) * std::pow(1.0 - vh, 5.0);
      // f cos_l dl = F D V cos_l 4 (v.h) dw_h and D (n.h) dw_h = du dphi / 2pi.
      spec += jac * fres * spec_v(nv, l.z, m.alpha) * l.z * 4.0 * vh / ch / static_cast<double>(nu * nphi);
    }
    if (m.metal) continue;
    // Diffuse: (1 - F(v.h)) / pi x cos_l dl, cosine-mapped: cos_l dl / pi = d(sin^2) dphi / (2 pi).
    const double cl = std::sqrt(1.0 - u), sl = std::sqrt(u);
    for (int j = 0; j < nphi; ++j) {
      const double phi = 2.0 * kPi * (j + 0.5) / nphi;
      const glm::dvec3 l(sl * std::cos(phi), sl * std::sin(phi), cl);
      const glm::dvec3 h = glm::normalize(l + v);
      const double vh = std::max(0.0, glm::dot(v, h));
      diff += (1.0 - (f0 + (1.0 - f0) * std::pow(1.0 - vh, 5.0))) / static_cast<double>(nu * nphi);
    }
  }
  return {diff, spec};
}

/// Hemispherical albedo: 2 x integral of a(mu) mu dmu, midpoint rule in mu^2.
inline glm::dvec2 spec_hemispherical_albedo(const SpecBrdf& m, int n = 48) {
  glm::dvec2 sum(0.0);
  for (int k = 0; k < n; ++k) sum += spec_directional_albedo(m, std::sqrt((k + 0.5) / n), 256, 128);
  return sum / static_cast<double>(n);
}

}  // namespace analytic
