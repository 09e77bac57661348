#include "brf/pca_basis.h"

#include <engine/finite.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <Eigen/Dense>

#include "brf/brdf_separation.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/ray_offset.h"

namespace gi {
namespace {

// N points spread evenly over the unit sphere (a Fibonacci spiral): deterministic and
// without clumps at the poles.
std::vector<glm::vec3> sphere_points(int n) {
  std::vector<glm::vec3> out;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * i;
    out.emplace_back(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                     static_cast<float>(z));
  }
  return out;
}

}  // namespace

std::vector<float> BrfBasis::fit(std::span<const float> values) const {
  const auto n = static_cast<std::size_t>(basis_count);
  std::vector<double> b(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < vertex_count; ++j)
      b[i] += static_cast<double>(psi[i * vertex_count + j]) * static_cast<double>(values[j]);
  std::vector<float> w(n, 0.0f);
  for (std::size_t r = 0; r < n; ++r) {
    double s = 0.0;
    for (std::size_t c = 0; c < n; ++c) s += static_cast<double>(a_inverse[r * n + c]) * b[c];
    w[r] = static_cast<float>(s);
  }
  return w;
}

std::vector<float> BrfBasis::reconstruct(std::span<const float> weights) const {
  std::vector<float> out(vertex_count, 0.0f);
  for (std::size_t i = 0; i < static_cast<std::size_t>(basis_count); ++i)
    for (std::size_t j = 0; j < vertex_count; ++j) out[j] += weights[i] * psi[i * vertex_count + j];
  return out;
}

std::vector<float> point_light_response(const BrfMesh& mesh, const RayCaster& caster, const glm::vec3& light) {
  std::vector<float> out(mesh.positions.size(), 0.0f);
  for (std::size_t j = 0; j < mesh.positions.size(); ++j) {
    const glm::vec3 p = mesh.positions[j], n = mesh.normals[j];
    const glm::vec3 to = light - p;
    const float d2 = glm::dot(to, to);
    if (!(d2 > 0.0f)) continue;
    const float cos_theta = glm::dot(n, to) / std::sqrt(d2);
    if (cos_theta <= 0.0f) continue;
    const glm::vec3 o = offset_ray_origin(p, n);
    if (caster.occluded(Ray{o, 0.0f, light - o, 1.0f})) continue;
    const float rho = mesh.reflectance.empty() ? 1.0f : mesh.reflectance[j];
    out[j] = rho * cos_theta / d2;
  }
  return out;
}

namespace {

/// compute_pca_basis' checks of its inputs.
engine::Status check_inputs(const BrfMesh& mesh, const PcaBasisSettings& settings) {
  const std::size_t nv = mesh.positions.size();
  if (mesh.indices.empty() || mesh.indices.size() % 3 != 0)
    return engine::Error{.message = "basis radiance fields: the mesh has no triangles"};
  if (mesh.normals.size() != nv || (!mesh.reflectance.empty() && mesh.reflectance.size() != nv))
    return engine::Error{.message = "basis radiance fields: normals/reflectance do not match the vertices"};
  for (std::uint32_t i : mesh.indices)
    if (i >= nv) return engine::Error{.message = "basis radiance fields: index " + std::to_string(i) + " out of range"};
  for (std::size_t j = 0; j < nv; ++j)
    if (!engine::all_finite(mesh.positions[j]) || !engine::all_finite(mesh.normals[j]))
      return engine::Error{.message = "basis radiance fields: vertex " + std::to_string(j) + " is not finite"};
  if (settings.lights < 2 || settings.lights > 65536 || settings.basis < 1 || settings.basis > 1024 ||
      !(settings.light_radius_scale >= 1.0f) || !(settings.rank_tolerance > 0.0f && settings.rank_tolerance < 1.0f) ||
      !(settings.max_condition >= 1.0))
    return engine::Error{.message = "basis radiance fields: settings out of range"};
  return {};
}

/// Training distributions B_eta, one column per light (§4.2) around the bounding sphere
/// (`basis`' centre and radius); a glossy object adds one column per light and glossy term,
/// L_k = g_k(w_light) E (eq. 8), each term's block scaled to the diffuse block's norm.
Eigen::MatrixXd training_distributions(const BrfMesh& mesh, const RayCaster& caster, const PcaBasisSettings& settings,
                                       const BrdfSeparation* glossy, const BrfBasis& basis) {
  const std::size_t nv = mesh.positions.size();
  const int terms = basis.terms;
  const auto lights = static_cast<Eigen::Index>(settings.lights);
  Eigen::MatrixXd c(static_cast<Eigen::Index>(nv), lights * terms);
  const std::vector<glm::vec3> dirs = sphere_points(settings.lights);
  BrfMesh bare = mesh;
  bare.reflectance.clear();
  std::vector<glm::mat3> frames;
  if (glossy != nullptr)
    for (const glm::vec3& n : mesh.normals) frames.push_back(glm::transpose(brf_tangent_frame(n)));  // world -> local
  for (Eigen::Index k = 0; k < lights; ++k) {
    const glm::vec3 light =
        basis.centre + dirs[static_cast<std::size_t>(k)] * (basis.radius * settings.light_radius_scale);
    const std::vector<float> e = point_light_response(bare, caster, light);  // irradiance
    for (std::size_t j = 0; j < nv; ++j)
      c(static_cast<Eigen::Index>(j), k) =
          static_cast<double>((mesh.reflectance.empty() ? 1.0f : mesh.reflectance[j]) * e[j]);
    for (int t = 1; t < terms; ++t)
      for (std::size_t j = 0; j < nv; ++j) {
        const glm::vec3 w = frames[j] * glm::normalize(light - mesh.positions[j]);
        c(static_cast<Eigen::Index>(j), t * lights + k) =
            e[j] > 0.0f ? static_cast<double>(glossy->g_at(t - 1, w) * e[j]) : 0.0;
      }
  }
  // Each glossy term's block scaled to the diffuse block's norm (a black diffuse part: 1).
  if (terms > 1) {
    const double diffuse_norm = c.leftCols(lights).norm();
    for (int t = 1; t < terms; ++t) {
      const double norm = c.middleCols(t * lights, lights).norm();
      if (norm > 0.0 && diffuse_norm > 0.0) c.middleCols(t * lights, lights) *= diffuse_norm / norm;
    }
  }
  return c;
}

/// The mean and the first `components` columns of `u`, orthonormalized: modified
/// Gram-Schmidt in double precision. It fits the same distributions, and A becomes the
/// identity up to rounding: the scale of the light (1 / d^2, 1 cm or 100 m objects) and a mean
/// lying in the span of the components (flat objects) cannot make A ill-conditioned. A vector
/// with nothing left after the projections is dropped.
std::vector<Eigen::VectorXd> orthonormal_basis(const Eigen::VectorXd& mean, const Eigen::MatrixXd& u, int components) {
  std::vector<Eigen::VectorXd> kept;
  const auto add = [&](Eigen::VectorXd v) {
    const double norm0 = v.norm();
    if (!(norm0 > 0.0)) return;
    for (const Eigen::VectorXd& q : kept) v -= q.dot(v) * q;
    if (v.norm() > 1e-6 * norm0) kept.push_back(v / v.norm());
  };
  add(mean);
  for (int i = 0; i < components; ++i) add(u.col(i));
  return kept;
}

/// A = Psi^T Psi and its pseudo-inverse (eq. 14) into out.a_inverse and out.condition, as the
/// paper precomputes it (here close to the identity); eigenvalues below the tolerances are
/// treated as zero.
void set_a_inverse(const Eigen::MatrixXd& psi, const PcaBasisSettings& settings, BrfBasis& out) {
  const auto n = static_cast<std::size_t>(out.basis_count);
  const Eigen::MatrixXd a = psi.transpose() * psi;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
  const Eigen::VectorXd& lambda = eig.eigenvalues();
  const double lambda_max = lambda.maxCoeff();
  const double cutoff =
      std::max(static_cast<double>(settings.rank_tolerance) * static_cast<double>(settings.rank_tolerance),
               1.0 / settings.max_condition) *
      lambda_max;
  Eigen::VectorXd inv = Eigen::VectorXd::Zero(lambda.size());
  double lambda_min_kept = lambda_max;
  for (Eigen::Index i = 0; i < lambda.size(); ++i)
    if (lambda(i) > cutoff) inv(i) = 1.0 / lambda(i), lambda_min_kept = std::min(lambda_min_kept, lambda(i));
  const Eigen::MatrixXd a_inv = eig.eigenvectors() * inv.asDiagonal() * eig.eigenvectors().transpose();
  out.condition = lambda_max > 0.0 ? lambda_max / lambda_min_kept : 1.0;
  out.a_inverse.resize(n * n);
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t col = 0; col < n; ++col)
      out.a_inverse[r * n + col] =
          static_cast<float>(a_inv(static_cast<Eigen::Index>(r), static_cast<Eigen::Index>(col)));
}

}  // namespace

engine::Result<BrfBasis> compute_pca_basis(const BrfMesh& mesh, const PcaBasisSettings& settings,
                                           const BrdfSeparation* glossy) {
  if (engine::Status s = check_inputs(mesh, settings); !s) return s.error();
  const std::size_t nv = mesh.positions.size();
  BrfBasis out;
  out.vertex_count = nv;
  glm::vec3 lo = mesh.positions[0], hi = lo;
  for (const glm::vec3& p : mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  out.centre = 0.5f * (lo + hi);
  for (const glm::vec3& p : mesh.positions) out.radius = std::max(out.radius, glm::length(p - out.centre));
  if (!(out.radius > 0.0f)) return engine::Error{.message = "basis radiance fields: the mesh has no extent"};

  RtSceneData data;
  data.geometries.push_back({mesh.positions, mesh.indices});
  data.instances.push_back({0, glm::mat4(1.0f), false, 0});
  auto caster = make_embree_ray_caster(data);
  if (!caster) return caster.error();

  out.terms = 1 + (glossy != nullptr ? glossy->terms : 0);
  Eigen::MatrixXd c = training_distributions(mesh, **caster, settings, glossy, out);
  const Eigen::VectorXd mean = c.rowwise().mean();
  c.colwise() -= mean;
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(c, Eigen::ComputeThinU);
  const Eigen::VectorXd& sigma = svd.singularValues();
  for (Eigen::Index i = 0; i < sigma.size(); ++i) out.singular_values.push_back(static_cast<float>(sigma(i)));

  // The mean plus the components above the rank tolerance, at most N - 1 of them.
  int components = 0;
  const double top = sigma.size() > 0 ? sigma(0) : 0.0;
  // (and no more functions than vertices: they could not be independent)
  while (components + 1 < settings.basis && components < sigma.size() &&
         static_cast<std::size_t>(components + 1) < nv &&
         sigma(components) > static_cast<double>(settings.rank_tolerance) * top)
    ++components;
  // The basis spans the mean and the kept components.
  const std::vector<Eigen::VectorXd> kept = orthonormal_basis(mean, svd.matrixU(), components);
  if (kept.empty()) return engine::Error{.message = "basis radiance fields: no light reaches the object"};
  out.basis_count = static_cast<int>(kept.size());
  const auto n = static_cast<std::size_t>(out.basis_count);
  Eigen::MatrixXd psi(static_cast<Eigen::Index>(nv), static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) psi.col(static_cast<Eigen::Index>(i)) = kept[i];
  out.psi.resize(n * nv);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < nv; ++j)
      out.psi[i * nv + j] = static_cast<float>(psi(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)));
  set_a_inverse(psi, settings, out);
  return out;
}

}  // namespace gi
