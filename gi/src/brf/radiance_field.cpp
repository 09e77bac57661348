#include "brf/radiance_field.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "brf/brdf_separation.h"
#include "brf/spherical_harmonics.h"
#include "core/thread_pool.h"
#include "raytrace/embree_ray_caster.h"

namespace gi {
namespace {

// Cube face f's point (u, v) in [-1, 1]^2 as a direction (not normalized).
glm::vec3 cube_direction(int f, float u, float v) {
  switch (f) {
    case 0:
      return {1.0f, v, -u};
    case 1:
      return {-1.0f, v, u};
    case 2:
      return {u, 1.0f, -v};
    case 3:
      return {u, -1.0f, v};
    case 4:
      return {u, v, 1.0f};
    default:
      return {-u, v, -1.0f};
  }
}

// The face and (u, v) of a direction (inverse of cube_direction).
void cube_face(const glm::vec3& d, int& f, float& u, float& v) {
  const glm::vec3 a = glm::abs(d);
  if (a.x >= a.y && a.x >= a.z) {
    f = d.x > 0.0f ? 0 : 1;
    u = d.x > 0.0f ? -d.z / a.x : d.z / a.x;
    v = d.y / a.x;
  } else if (a.y >= a.z) {
    f = d.y > 0.0f ? 2 : 3;
    u = d.x / a.y;
    v = d.y > 0.0f ? -d.z / a.y : d.z / a.y;
  } else {
    f = d.z > 0.0f ? 4 : 5;
    u = d.z > 0.0f ? d.x / a.z : -d.x / a.z;
    v = d.y / a.z;
  }
}

// Cell (iu, iv) of face f, where iu or iv may lie one cell beyond the face (-1 or res): such a
// cell is the one on the neighbouring face that holds the direction of its centre (the cube
// map's seam), so bilinear lookups blend across faces instead of clamping to the edge cell.
void seam_cell(int res, int& f, int& iu, int& iv) {
  if (iu >= 0 && iu < res && iv >= 0 && iv < res) return;
  const float n = static_cast<float>(res);
  const float cu = (static_cast<float>(iu) + 0.5f) / n * 2.0f - 1.0f;
  const float cv = (static_cast<float>(iv) + 0.5f) / n * 2.0f - 1.0f;
  float u = 0.0f, v = 0.0f;
  cube_face(cube_direction(f, cu, cv), f, u, v);
  iu = std::clamp(static_cast<int>(std::floor((u + 1.0f) * 0.5f * n)), 0, res - 1);
  iv = std::clamp(static_cast<int>(std::floor((v + 1.0f) * 0.5f * n)), 0, res - 1);
}

}  // namespace

float BasisRadianceField::sphere_radius(int s) const {
  if (spheres <= 1) return inner_radius;
  return inner_radius * std::pow(outer_radius / inner_radius, static_cast<float>(s) / static_cast<float>(spheres - 1));
}

// Long because it is one trilinear lookup: the radial coordinate, the cube face
// cell across seams, then the eight corners summed with their weights and 1/r^2 scale.
void BasisRadianceField::sample(const glm::vec3& p, std::span<float> out) const {
  const auto per_point = static_cast<std::size_t>(channel_count() * coefficient_count());
  std::fill(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(per_point), 0.0f);
  const glm::vec3 d = p - centre;
  const float r = glm::length(d);
  if (!(r > 0.0f) || !std::isfinite(r)) return;
  // Radius: linear in log r between spheres; clamped inside; 1/r^2 beyond the outermost.
  float falloff = 1.0f;
  float sr = 0.0f;
  if (r <= inner_radius || spheres == 1) {
    sr = 0.0f;
  } else if (r >= outer_radius) {
    sr = static_cast<float>(spheres - 1);
    falloff = (outer_radius / r) * (outer_radius / r);
  } else {
    sr = std::log(r / inner_radius) / std::log(outer_radius / inner_radius) * static_cast<float>(spheres - 1);
  }
  // NaN-safe (degenerate radii): the index stays within the spheres whatever sr is.
  if (!(sr >= 0.0f)) sr = 0.0f;
  sr = std::min(sr, static_cast<float>(spheres - 1));
  const int s0 = static_cast<int>(sr), s1 = std::min(s0 + 1, spheres - 1);
  const float ts = sr - static_cast<float>(s0);
  int f = 0;
  float u = 0.0f, v = 0.0f;
  cube_face(d, f, u, v);
  // Cell centres sit at ((k + 0.5) / res) * 2 - 1. Within half a cell of a face's edge the
  // outer neighbours lie on the next face (seam_cell): the lookup blends across the seam.
  // (Clamping to the edge cell jumped by up to 27% where two faces meet, docs/brf.md.)
  const float n = static_cast<float>(face_resolution);
  const float fu = std::clamp((u + 1.0f) * 0.5f * n - 0.5f, -0.5f, n - 0.5f);
  const float fv = std::clamp((v + 1.0f) * 0.5f * n - 0.5f, -0.5f, n - 0.5f);
  const int u0 = static_cast<int>(std::floor(fu)), v0 = static_cast<int>(std::floor(fv));
  const int u1 = u0 + 1, v1 = v0 + 1;
  const float tu = fu - static_cast<float>(u0), tv = fv - static_cast<float>(v0);
  const auto point = [&](int s, int uu, int vv) {
    int ff = f;
    seam_cell(face_resolution, ff, uu, vv);
    const std::size_t idx =
        ((static_cast<std::size_t>(s) * 6 + static_cast<std::size_t>(ff)) * static_cast<std::size_t>(face_resolution) +
         static_cast<std::size_t>(vv)) *
            static_cast<std::size_t>(face_resolution) +
        static_cast<std::size_t>(uu);
    return coefficients.data() + idx * per_point;
  };
  const struct {
    int s, u, v;
    float w;
  } corners[8] = {{s0, u0, v0, (1 - ts) * (1 - tu) * (1 - tv)},
                  {s0, u1, v0, (1 - ts) * tu * (1 - tv)},
                  {s0, u0, v1, (1 - ts) * (1 - tu) * tv},
                  {s0, u1, v1, (1 - ts) * tu * tv},
                  {s1, u0, v0, ts * (1 - tu) * (1 - tv)},
                  {s1, u1, v0, ts * tu * (1 - tv)},
                  {s1, u0, v1, ts * (1 - tu) * tv},
                  {s1, u1, v1, ts * tu * tv}};
  // The object's radiance coefficients fall off about as 1 / r^2 between spheres:
  // interpolate r^2 x coefficients (linear interpolation of 1 / r^2 itself overestimates by
  // up to a few percent between spheres).
  const bool between = r > inner_radius && r < outer_radius && spheres > 1;
  for (const auto& c : corners) {
    if (c.w == 0.0f) continue;
    const float* src = point(c.s, c.u, c.v);
    const float rs = sphere_radius(c.s);
    const float scale = c.w * falloff * (between ? (rs / r) * (rs / r) : 1.0f);
    for (std::size_t k = 0; k < per_point; ++k) out[k] += scale * src[k];
  }
}

// Long because it is the checks, the field's shape, then one parallel loop whose
// body (a sample point's rays and their SH projection) reads most of the locals set up before it.
engine::Result<BasisRadianceField> compute_basis_radiance_field(const BrfMesh& mesh, const BrfBasis& basis,
                                                                const RadianceFieldSettings& settings,
                                                                const BrdfSeparation* glossy) {
  if (basis.vertex_count != mesh.positions.size() || basis.basis_count < 1)
    return engine::Error{.message = "basis radiance field: the basis does not belong to this mesh"};
  const int terms = 1 + (glossy != nullptr ? glossy->terms : 0);
  if (basis.terms != terms)
    return engine::Error{.message = "basis radiance field: the basis was trained for " + std::to_string(basis.terms) +
                                    " BRDF terms, the material has " + std::to_string(terms)};
  if (settings.spheres < 1 || settings.spheres > 256 || settings.face_resolution < 1 ||
      settings.face_resolution > 256 || (settings.sh_bands != 3 && settings.sh_bands != 4) ||
      settings.directions < 16 || settings.directions > 65536 || !(settings.inner_radius_scale > 0.0f) ||
      !(settings.outer_radius_scale >= settings.inner_radius_scale))
    return engine::Error{.message = "basis radiance field: settings out of range"};

  BasisRadianceField field;
  field.spheres = settings.spheres;
  field.face_resolution = settings.face_resolution;
  field.sh_bands = settings.sh_bands;
  field.basis_count = basis.basis_count;
  field.terms = terms;
  field.centre = basis.centre;
  field.inner_radius = basis.radius * settings.inner_radius_scale;
  field.outer_radius = basis.radius * settings.outer_radius_scale;
  const auto coefs = static_cast<std::size_t>(field.coefficient_count());
  const auto per_point = static_cast<std::size_t>(field.channel_count()) * coefs;
  const std::size_t nb = static_cast<std::size_t>(field.basis_count);
  const std::size_t res = static_cast<std::size_t>(settings.face_resolution);
  const std::size_t points = static_cast<std::size_t>(settings.spheres) * 6 * res * res;
  field.coefficients.assign(points * per_point, 0.0f);

  RtSceneData data;
  data.geometries.push_back({mesh.positions, mesh.indices});
  data.instances.push_back({0, glm::mat4(1.0f), false, 0});
  auto caster = make_embree_ray_caster(data);
  if (!caster) return caster.error();

  // Directions: only the cone the bounding sphere subtends can see the object, so the rays
  // are spread over that cap (a Fibonacci spiral in cos theta and phi), each standing for
  // cap / directions steradians. Far spheres then get as many hits as near ones; uniform
  // directions over the whole sphere would leave an object 8 radii away about one hit in
  // 256.
  const auto n_dirs = static_cast<std::size_t>(settings.directions);
  const float inv_pi = 1.0f / std::numbers::pi_v<float>;
  const float golden = std::numbers::pi_v<float> * (3.0f - std::sqrt(5.0f));
  const std::size_t nv = basis.vertex_count;

  ThreadPool pool(settings.threads);
  const bool completed = pool.parallel_for_with_progress(
      points, settings.progress,
      [&](std::size_t pt) {
        const std::size_t s = pt / (6 * res * res), rem = pt % (6 * res * res);
        const int f = static_cast<int>(rem / (res * res));
        const std::size_t vv = (rem / res) % res, uu = rem % res;
        const float u = (static_cast<float>(uu) + 0.5f) / static_cast<float>(res) * 2.0f - 1.0f;
        const float v = (static_cast<float>(vv) + 0.5f) / static_cast<float>(res) * 2.0f - 1.0f;
        const glm::vec3 outward = glm::normalize(cube_direction(f, u, v));
        const float d = field.sphere_radius(static_cast<int>(s));
        const glm::vec3 p = field.centre + outward * d;
        const glm::vec3 axis = -outward;
        const float sin_max = d > basis.radius ? basis.radius / d : 1.0f;
        const float cos_max = std::sqrt(std::max(0.0f, 1.0f - sin_max * sin_max));
        const float cap = 2.0f * std::numbers::pi_v<float> * (1.0f - cos_max);
        const float solid_angle = cap / static_cast<float>(n_dirs);
        const glm::vec3 t = glm::normalize(std::abs(axis.x) < 0.9f ? glm::cross(axis, glm::vec3(1, 0, 0))
                                                                   : glm::cross(axis, glm::vec3(0, 1, 0)));
        const glm::vec3 b = glm::cross(axis, t);
        float* out = field.coefficients.data() + pt * per_point;
        for (std::size_t k = 0; k < n_dirs; ++k) {
          const float ct = 1.0f - (1.0f - cos_max) * (static_cast<float>(k) + 0.5f) / static_cast<float>(n_dirs);
          const float st = std::sqrt(std::max(0.0f, 1.0f - ct * ct));
          const float phi = golden * static_cast<float>(k);
          const glm::vec3 dir = ct * axis + st * (std::cos(phi) * t + std::sin(phi) * b);
          const Hit h = (*caster)->intersect(Ray{p, 0.0f, dir});
          if (!h.valid() || glm::dot(h.geometric_normal, dir) >= 0.0f) continue;  // missed, or a back face
          const auto y = sh_basis(dir);
          const std::uint32_t* tri = mesh.indices.data() + 3 * static_cast<std::size_t>(h.primitive);
          const float b1 = h.barycentric.x, b2 = h.barycentric.y, b0 = 1.0f - b1 - b2;
          // h_k toward the sample point, in the hit's tangent frame (interpolated normal).
          float h_out[1 + kMaxGlossyTerms];
          h_out[0] = inv_pi;  // the diffuse term: radiance of radiosity Psi_i is Psi_i / pi
          if (terms > 1) {
            const glm::vec3 n =
                glm::normalize(b0 * mesh.normals[tri[0]] + b1 * mesh.normals[tri[1]] + b2 * mesh.normals[tri[2]]);
            const glm::vec3 w = glm::transpose(brf_tangent_frame(n)) * -dir;
            for (int term = 1; term < terms; ++term) h_out[term] = glossy->h_at(term - 1, w);
          }
          for (std::size_t term = 0; term < static_cast<std::size_t>(terms); ++term)
            for (std::size_t i = 0; i < nb; ++i) {
              const float* psi = basis.psi.data() + i * nv;
              const float radiance =
                  (b0 * psi[tri[0]] + b1 * psi[tri[1]] + b2 * psi[tri[2]]) * h_out[term] * solid_angle;
              for (std::size_t c = 0; c < coefs; ++c) out[(term * nb + i) * coefs + c] += radiance * y[c];
            }
        }
      },
      4);
  if (!completed) return engine::cancelled_error("basis radiance field");
  return field;
}

}  // namespace gi
