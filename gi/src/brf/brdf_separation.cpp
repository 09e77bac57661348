#include "brf/brdf_separation.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "raytrace/reference_brdf.h"

namespace gi {

glm::vec2 hemisphere_to_square(const glm::vec3& w) {
  const float z = std::max(w.z, 0.0f);
  const float sum = std::abs(w.x) + std::abs(w.y) + z;
  if (!(sum > 0.0f)) return {0.0f, 0.0f};
  const float px = w.x / sum, py = w.y / sum;
  return {px + py, px - py};
}

glm::vec3 square_to_hemisphere(const glm::vec2& s) {
  const float px = 0.5f * (s.x + s.y), py = 0.5f * (s.x - s.y);
  const float z = std::max(0.0f, 1.0f - std::abs(px) - std::abs(py));
  return glm::normalize(glm::vec3(px, py, z));
}

glm::mat3 brf_tangent_frame(const glm::vec3& n) {
  glm::vec3 t, b;
  orthonormal_basis(n, t, b);
  return glm::mat3(t, b, n);
}

float glossy_lobe_brdf(const GlossyLobe& lobe, const glm::vec3& w_in, const glm::vec3& w_out) {
  if (w_in.z <= 0.0f || w_out.z <= 0.0f) return 0.0f;
  // The lobe is glTF's conductor: a metal whose base colour is f0.
  engine::GltfBrdf metal;
  metal.base_color = glm::vec3(lobe.f0);
  metal.metallic = 1.0f;
  metal.alpha = lobe.alpha;
  return engine::gltf_eval_cos(metal, glm::vec3(0.0f, 0.0f, 1.0f), w_out, w_in).specular.x / w_in.z;
}

namespace {

// Bilinear lookup over cell centres, clamped to the table's edge.
float lookup(const std::vector<float>& table, int k, int res, const glm::vec3& local) {
  const glm::vec2 s = hemisphere_to_square(local);
  const float n = static_cast<float>(res);
  const float fu = std::clamp((s.x + 1.0f) * 0.5f * n - 0.5f, 0.0f, n - 1.0f);
  const float fv = std::clamp((s.y + 1.0f) * 0.5f * n - 0.5f, 0.0f, n - 1.0f);
  const int u0 = static_cast<int>(fu), v0 = static_cast<int>(fv);
  const int u1 = std::min(u0 + 1, res - 1), v1 = std::min(v0 + 1, res - 1);
  const float tu = fu - static_cast<float>(u0), tv = fv - static_cast<float>(v0);
  const float* t = table.data() + static_cast<std::size_t>(k) * static_cast<std::size_t>(res * res);
  const auto at = [&](int u, int v) { return t[v * res + u]; };
  return (1.0f - tv) * ((1.0f - tu) * at(u0, v0) + tu * at(u1, v0)) + tv * ((1.0f - tu) * at(u0, v1) + tu * at(u1, v1));
}

glm::vec2 cell_centre(int u, int v, int res) {
  return {(static_cast<float>(u) + 0.5f) / static_cast<float>(res) * 2.0f - 1.0f,
          (static_cast<float>(v) + 0.5f) / static_cast<float>(res) * 2.0f - 1.0f};
}

// Solid angle of a cell: the map's Jacobian integrated over 4 x 4 sub-cells.
double cell_solid_angle(int u, int v, int res) {
  const double size = 2.0 / res;
  double sum = 0.0;
  constexpr int kSub = 4;
  for (int a = 0; a < kSub; ++a)
    for (int b = 0; b < kSub; ++b) {
      const double su = -1.0 + size * (u + (a + 0.5) / kSub), sv = -1.0 + size * (v + (b + 0.5) / kSub);
      const auto dir = [](double x, double y) {
        const double px = 0.5 * (x + y), py = 0.5 * (x - y);
        const double z = std::max(0.0, 1.0 - std::abs(px) - std::abs(py));
        const Eigen::Vector3d d(px, py, z);
        return Eigen::Vector3d(d / d.norm());
      };
      const double e = size / kSub * 0.25;
      const Eigen::Vector3d du = (dir(su + e, sv) - dir(su - e, sv)) / (2.0 * e);
      const Eigen::Vector3d dv = (dir(su, sv + e) - dir(su, sv - e)) / (2.0 * e);
      sum += du.cross(dv).norm() * (size / kSub) * (size / kSub);
    }
  return sum;
}

}  // namespace

float BrdfSeparation::g_at(int k, const glm::vec3& local) const { return lookup(g, k, resolution, local); }
float BrdfSeparation::h_at(int k, const glm::vec3& local) const { return lookup(h, k, resolution, local); }

std::vector<float> BrdfSeparation::albedo_corrected_h() const {
  std::vector<float> out = h;
  if (terms <= 0 || resolution <= 0) return out;
  // G_k = int g_k(w) cos dw and each cell's exact albedo, by a 64 x 64 midpoint rule in
  // (cos theta, phi) (uniform in solid angle).
  constexpr int kN = 64;
  std::vector<glm::vec3> dirs;
  dirs.reserve(kN * kN);
  for (int a = 0; a < kN; ++a)
    for (int b = 0; b < kN; ++b) {
      const float z = (static_cast<float>(a) + 0.5f) / kN;
      const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
      const float phi = 2.0f * std::numbers::pi_v<float> * (static_cast<float>(b) + 0.5f) / kN;
      dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
  const double dw = 2.0 * std::numbers::pi / (kN * kN);
  std::vector<double> g_integral(static_cast<std::size_t>(terms), 0.0);
  for (int k = 0; k < terms; ++k)
    for (const glm::vec3& w : dirs) g_integral[static_cast<std::size_t>(k)] += dw * double{g_at(k, w)} * double{w.z};
  const std::size_t cells = static_cast<std::size_t>(resolution) * static_cast<std::size_t>(resolution);
  for (int v = 0; v < resolution; ++v)
    for (int u = 0; u < resolution; ++u) {
      const std::size_t c = static_cast<std::size_t>(v * resolution + u);
      const glm::vec3 wo = square_to_hemisphere(cell_centre(u, v, resolution));
      double exact = 0.0, separated = 0.0;
      for (const glm::vec3& w : dirs) exact += dw * double{glossy_lobe_brdf(lobe, w, wo)} * double{w.z};
      for (int k = 0; k < terms; ++k)
        separated += double{h[static_cast<std::size_t>(k) * cells + c]} * g_integral[static_cast<std::size_t>(k)];
      if (!(separated > 0.0)) continue;
      const double scale = std::clamp(exact / separated, 0.25, 4.0);
      for (int k = 0; k < terms; ++k) out[static_cast<std::size_t>(k) * cells + c] *= static_cast<float>(scale);
    }
  return out;
}

float BrdfSeparation::eval(const glm::vec3& w_in, const glm::vec3& w_out) const {
  float s = 0.0f;
  for (int k = 0; k < terms; ++k) s += g_at(k, w_in) * h_at(k, w_out);
  return s;
}

// Long because it is one separation: tabulate the lobe, take its SVD, choose the terms,
// scale g and h, then project g on SH; each step reads the previous step's matrices and tables.
engine::Result<BrdfSeparation> separate_glossy_brdf(const GlossyLobe& lobe, const BrdfSeparationSettings& settings) {
  if (!(lobe.alpha > 0.0f && lobe.alpha <= 1.0f) || !(lobe.f0 > 0.0f && lobe.f0 <= 1.0f))
    return engine::Error{.message = "glossy BRDF separation: alpha and f0 must lie in (0, 1]"};
  if (settings.terms < 1 || settings.terms > kMaxGlossyTerms || settings.resolution < 4 || settings.resolution > 64)
    return engine::Error{.message = "glossy BRDF separation: terms must be >= 1 and the resolution in [4, 64]"};
  const int res = settings.resolution;
  const int cells = res * res;
  std::vector<glm::vec3> dirs(static_cast<std::size_t>(cells));
  Eigen::VectorXd root_omega(cells);
  for (int v = 0; v < res; ++v)
    for (int u = 0; u < res; ++u) {
      dirs[static_cast<std::size_t>(v * res + u)] = square_to_hemisphere(cell_centre(u, v, res));
      root_omega(v * res + u) = std::sqrt(cell_solid_angle(u, v, res));
    }
  Eigen::MatrixXd m(cells, cells);  // rows: w_out, columns: w_in
  for (int o = 0; o < cells; ++o)
    for (int i = 0; i < cells; ++i)
      m(o, i) = static_cast<double>(
                    glossy_lobe_brdf(lobe, dirs[static_cast<std::size_t>(i)], dirs[static_cast<std::size_t>(o)])) *
                root_omega(o) * root_omega(i) *
                static_cast<double>(dirs[static_cast<std::size_t>(i)].z * dirs[static_cast<std::size_t>(o)].z);
  const Eigen::BDCSVD<Eigen::MatrixXd> svd(m, Eigen::ComputeThinU | Eigen::ComputeThinV);
  const Eigen::VectorXd& sigma = svd.singularValues();

  BrdfSeparation out;
  out.lobe = lobe;
  out.resolution = res;
  for (Eigen::Index i = 0; i < sigma.size(); ++i) out.singular_values.push_back(static_cast<float>(sigma(i)));
  int terms = std::min(settings.terms, static_cast<int>(sigma.size()));
  while (terms < sigma.size() && terms < kMaxGlossyTerms && sigma(terms) > 0.0 &&
         sigma(terms) >= 0.995 * sigma(terms - 1))
    ++terms;
  out.terms = terms;
  double tail = 0.0, all = 0.0;
  for (Eigen::Index i = 0; i < sigma.size(); ++i) {
    all += sigma(i) * sigma(i);
    if (i >= terms) tail += sigma(i) * sigma(i);
  }
  out.relative_error = all > 0.0 ? static_cast<float>(std::sqrt(tail / all)) : 0.0f;

  out.g.resize(static_cast<std::size_t>(terms * cells));
  out.h.resize(static_cast<std::size_t>(terms * cells));
  for (int k = 0; k < terms; ++k) {
    const double s = std::sqrt(sigma(k));
    // The sign of a singular pair is arbitrary; make g_k's mean positive so runs agree.
    const double sign = svd.matrixV().col(k).sum() < 0.0 ? -1.0 : 1.0;
    for (int c = 0; c < cells; ++c) {
      const double cosine = static_cast<double>(dirs[static_cast<std::size_t>(c)].z);
      out.g[static_cast<std::size_t>(k * cells + c)] =
          static_cast<float>(sign * s * svd.matrixV()(c, k) / (root_omega(c) * cosine));
      out.h[static_cast<std::size_t>(k * cells + c)] =
          static_cast<float>(sign * s * svd.matrixU()(c, k) / (root_omega(c) * cosine));
    }
  }

  // SH of g_k(w) max(0, cos) in the local frame, integrated over 4 x 4 sub-cells per cell
  // with the bilinear table (what g_at returns).
  std::vector<double> acc(static_cast<std::size_t>(terms * kMaxShCoefficients), 0.0);
  constexpr int kSub = 4;
  const int fine = res * kSub;
  for (int v = 0; v < fine; ++v)
    for (int u = 0; u < fine; ++u) {
      const glm::vec2 sq = cell_centre(u, v, fine);
      const glm::vec3 w = square_to_hemisphere(sq);
      const double omega = cell_solid_angle(u, v, fine);
      const auto y = sh_basis(w);
      for (int k = 0; k < terms; ++k) {
        const double gw = static_cast<double>(out.g_at(k, w)) * static_cast<double>(w.z) * omega;
        for (int c = 0; c < kMaxShCoefficients; ++c)
          acc[static_cast<std::size_t>(k * kMaxShCoefficients + c)] +=
              gw * static_cast<double>(y[static_cast<std::size_t>(c)]);
      }
    }
  out.lobe_sh.assign(acc.begin(), acc.end());
  return out;
}

}  // namespace gi
