// area-ltc-fit: fits, for each (roughness, view angle) of a kSide x kSide grid, a linearly
// transformed cosine (Heitz et al. 2016, "Real-time polygonal-light shading with linearly
// transformed cosines") to glTF's GGX specular lobe with Fresnel 1, D V cos(theta_l), divided
// by its integral, and writes the inverse transforms as a C++ table the renderer uploads to
// the buffer the forward pass reads (engine/shaders/lighting_common.glsl, area_ltc_inverse):
//   area-ltc-fit engine/src/render/area_ltc_table.h && tools/check-format.sh --fix engine/src/render/area_ltc_table.h
// The fit is ours: Nelder-Mead on the paper's three parameters (scale along the lobe's
// tangent in the plane of incidence, scale across it, skew) about the lobe's mean direction,
// minimizing the integral of |LTC - GGX|^3 (estimated with stratified samples of both
// distributions, balance-heuristic weights), from the roughest cell to the sharpest, each
// started from its neighbour's fit. Deterministic: the same table on every run.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace {

constexpr int kSide = 32;                // table nodes per axis; must match AREA_LTC_SIDE in the shader
constexpr int kSamples = 32;             // stratified samples per axis, per distribution
constexpr double kMinRoughness = 0.045;  // GLTF_MIN_ROUGHNESS
constexpr double kPi = 3.14159265358979323846;

using glm::dmat3;
using glm::dvec3;

// Node (i, j): view cos theta_v = 1 - t^2 with t = i / (kSide - 1) (the paper's sqrt(1 - cos)
// spacing, dense at grazing views), perceptual roughness linear in j.
double node_cos_view(int i) {
  const double t = static_cast<double>(i) / (kSide - 1);
  return std::max(1.0 - t * t, 1e-3);
}
double node_roughness(int j) { return kMinRoughness + (1.0 - kMinRoughness) * j / (kSide - 1); }

struct Ggx {
  double alpha;
  dvec3 v;  // local frame: normal +Z, view in the XZ plane with x >= 0

  double d(double n_dot_h) const {
    const double a2 = alpha * alpha;
    const double k = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    return a2 / (kPi * k * k);
  }
  // D V cos(theta_l), Fresnel 1 (glTF's lobe, gltf_brdf.glsl).
  double eval(const dvec3& l) const {
    if (l.z <= 0.0) return 0.0;
    const dvec3 h = glm::normalize(l + v);
    const double a2 = alpha * alpha;
    const double nv = v.z;
    const double nl = l.z;
    const double vis = 0.5 / (nl * std::sqrt(nv * nv * (1.0 - a2) + a2) + nv * std::sqrt(nl * nl * (1.0 - a2) + a2));
    return d(std::max(h.z, 0.0)) * vis * nl;
  }
  // Reflected direction of a half vector drawn from D cos(theta_h), and that direction's pdf.
  dvec3 sample(double u1, double u2, double& pdf) const {
    const double a2 = alpha * alpha;
    const double cos_h = std::sqrt((1.0 - u1) / (1.0 + (a2 - 1.0) * u1));
    const double sin_h = std::sqrt(std::max(0.0, 1.0 - cos_h * cos_h));
    const double phi = 2.0 * kPi * u2;
    const dvec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
    const double vh = glm::dot(v, h);
    pdf = vh > 0.0 ? d(cos_h) * cos_h / (4.0 * vh) : 0.0;
    return 2.0 * vh * h - v;
  }
  double pdf(const dvec3& l) const {
    const dvec3 h = glm::normalize(l + v);
    const double vh = glm::dot(v, h);
    return h.z > 0.0 && vh > 0.0 ? d(h.z) * h.z / (4.0 * vh) : 0.0;
  }
};

// A cosine distribution on z > 0 transformed by m: density at unit w.
struct Ltc {
  dmat3 m;
  dmat3 inv;
  double det_inv;

  explicit Ltc(const dmat3& mat) : m(mat), inv(glm::inverse(mat)), det_inv(std::abs(glm::determinant(inv))) {}
  double eval(const dvec3& w) const {
    const dvec3 o = inv * w;
    const double len = glm::length(o);
    const double z = o.z / len;
    return z > 0.0 ? z / kPi * det_inv / (len * len * len) : 0.0;
  }
  dvec3 sample(double u1, double u2) const {
    const double r = std::sqrt(u1);
    const double phi = 2.0 * kPi * u2;
    const dvec3 o(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0, 1.0 - u1)));
    return glm::normalize(m * o);
  }
};

struct Lobe {
  double norm = 0.0;    // integral of D V cos over the sphere
  dvec3 mean{0, 0, 1};  // normalized mean direction
};

Lobe measure(const Ggx& g) {
  Lobe out;
  dvec3 sum(0.0);
  const int n = 256;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      double pdf = 0.0;
      const dvec3 l = g.sample((i + 0.5) / n, (j + 0.5) / n, pdf);
      if (pdf <= 0.0) continue;
      const double w = g.eval(l) / pdf;
      out.norm += w;
      sum += w * l;
    }
  out.norm /= n * n;
  if (glm::length(sum) > 0.0) out.mean = glm::normalize(sum);
  return out;
}

// The transform of parameters p = (m11, m22, m13) about the frame (x, y, mean).
dmat3 transform(const dvec3& mean, const std::array<double, 3>& p) {
  const dvec3 z = mean;
  const dvec3 x(z.z, 0.0, -z.x);
  const dvec3 y(0.0, 1.0, 0.0);
  const dmat3 frame(x, y, z);  // columns
  // Columns of the parameter matrix [[m11, 0, m13], [0, m22, 0], [0, 0, 1]].
  const dmat3 a(dvec3(p[0], 0, 0), dvec3(0, p[1], 0), dvec3(p[2], 0, 1));
  return frame * a;
}

// Integral of |LTC - GGX / norm|^3 over the sphere.
double fit_error(const Ggx& g, const Lobe& lobe, const std::array<double, 3>& p) {
  if (p[0] <= 1e-6 || p[1] <= 1e-6) return 1e30;
  const Ltc ltc(transform(lobe.mean, p));
  double err = 0.0;
  for (int j = 0; j < kSamples; ++j)
    for (int i = 0; i < kSamples; ++i) {
      const double u1 = (i + 0.5) / kSamples;
      const double u2 = (j + 0.5) / kSamples;
      for (int from = 0; from < 2; ++from) {
        double pdf_g = 0.0;
        dvec3 l;
        if (from == 0) {
          l = g.sample(u1, u2, pdf_g);
        } else {
          l = ltc.sample(u1, u2);
          pdf_g = g.pdf(l);
        }
        const double pdf_l = ltc.eval(l);
        const double sum = pdf_g + pdf_l;
        if (sum <= 0.0) continue;
        const double e = std::abs(pdf_l - g.eval(l) / lobe.norm);
        err += e * e * e / sum;
      }
    }
  return err / (kSamples * kSamples);
}

// Nelder-Mead on three parameters, steps relative to the start.
// Long because its reflect, expand, contract and shrink steps share the simplex and its
// values: split, each step would take and return all of them.
std::array<double, 3> minimize(const std::function<double(const std::array<double, 3>&)>& f,
                               std::array<double, 3> start, int iterations) {
  using P = std::array<double, 3>;
  std::array<P, 4> s;
  std::array<double, 4> v{};
  s[0] = start;
  for (int k = 0; k < 3; ++k) {
    s[k + 1] = start;
    const double scale = k == 2 ? std::max(0.05 * start[0], 1e-3) : 0.1 * start[k];
    s[k + 1][k] += scale;
  }
  for (int k = 0; k < 4; ++k) v[k] = f(s[k]);
  for (int it = 0; it < iterations; ++it) {
    std::array<int, 4> order{0, 1, 2, 3};
    std::sort(order.begin(), order.end(), [&](int a, int b) { return v[a] < v[b]; });
    std::array<P, 4> ss;
    std::array<double, 4> vv{};
    for (int k = 0; k < 4; ++k) {
      ss[k] = s[order[k]];
      vv[k] = v[order[k]];
    }
    s = ss;
    v = vv;
    P c{0, 0, 0};
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) c[d] += s[k][d] / 3.0;
    const auto along = [&](double t) {
      P q;
      for (int d = 0; d < 3; ++d) q[d] = c[d] + t * (s[3][d] - c[d]);
      return q;
    };
    const P r = along(-1.0);
    const double fr = f(r);
    if (fr < v[0]) {
      const P e = along(-2.0);
      const double fe = f(e);
      if (fe < fr) {
        s[3] = e;
        v[3] = fe;
      } else {
        s[3] = r;
        v[3] = fr;
      }
    } else if (fr < v[2]) {
      s[3] = r;
      v[3] = fr;
    } else {
      const P k = along(fr < v[3] ? -0.5 : 0.5);
      const double fk = f(k);
      if (fk < std::min(fr, v[3])) {
        s[3] = k;
        v[3] = fk;
      } else {
        for (int i = 1; i < 4; ++i) {
          for (int d = 0; d < 3; ++d) s[i][d] = s[0][d] + 0.5 * (s[i][d] - s[0][d]);
          v[i] = f(s[i]);
        }
      }
    }
  }
  int best = 0;
  for (int k = 1; k < 4; ++k)
    if (v[k] < v[best]) best = k;
  return s[best];
}

}  // namespace

// Writes the fitted table as the C++ header the forward pass includes; false when it cannot.
bool write_table(const char* path, const std::vector<std::array<double, 4>>& table) {
  std::FILE* out = std::fopen(path, "w");
  if (!out) {
    std::fprintf(stderr, "cannot write %s\n", path);
    return false;
  }
  std::fprintf(out,
               "#pragma once\n"
               "// Generated by tools/area-ltc-fit (do not edit): the inverse linearly transformed cosines\n"
               "// fitted to glTF's GGX lobe, %d x %d nodes, uploaded to the forward pass's AreaLtc buffer\n"
               "// (lighting_common.glsl). Node (i, j) at view cos = 1 - (i / %d)^2 and roughness\n"
               "// %.3f + %.3f j / %d holds (a, b, c, d) at [4 (j %d + i)]: the inverse transform\n"
               "// [[a, 0, b], [0, 1, 0], [c, 0, d]] in the frame (tangent towards the view, bitangent, normal).\n\n"
               "namespace engine::render {\n\n"
               "inline constexpr int kAreaLtcSide = %d;\n"
               "inline constexpr float kAreaLtcTable[%d] = {\n",
               kSide, kSide, kSide - 1, kMinRoughness, 1.0 - kMinRoughness, kSide - 1, kSide, kSide, 4 * kSide * kSide);
  // A float literal of x: 7 significant digits, with a decimal point or an exponent.
  const auto literal = [](double x) {
    char text[40];
    std::snprintf(text, sizeof(text), "%.7g", x);
    std::string s(text);
    if (s.find_first_of(".en") == std::string::npos) s += ".0";
    return s + "f";
  };
  for (const auto& t : table)
    std::fprintf(out, "    %s, %s, %s, %s,\n", literal(t[0]).c_str(), literal(t[1]).c_str(), literal(t[2]).c_str(),
                 literal(t[3]).c_str());
  std::fprintf(out, "};\n\n}  // namespace engine::render\n");
  std::fclose(out);
  return true;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: area-ltc-fit <out.h>\n");
    return 2;
  }
  // table[j][i] = (a, b, c, d): the inverse transform [[a, 0, b], [0, 1, 0], [c, 0, d]] in the
  // local frame (normal +Z, view in the XZ plane), scaled so that its middle entry is 1 (the
  // transformed polygon's cosine integral does not change with the scale).
  std::vector<std::array<double, 4>> table(static_cast<std::size_t>(kSide * kSide));
  std::array<double, 3> row_start{1.0, 1.0, 0.0};
  double worst_error = 0.0;
  for (int j = kSide - 1; j >= 0; --j) {
    const double roughness = node_roughness(j);
    std::array<double, 3> p = row_start;
    for (int i = 0; i < kSide; ++i) {
      const double cos_v = node_cos_view(i);
      const Ggx g{roughness * roughness, dvec3(std::sqrt(1.0 - cos_v * cos_v), 0.0, cos_v)};
      const Lobe lobe = measure(g);
      if (i == 0) p[2] = 0.0;  // isotropic at normal view
      const auto f = [&](const std::array<double, 3>& q) { return fit_error(g, lobe, q); };
      p = minimize(f, p, 150);
      p = minimize(f, p, 100);  // restart: a fresh simplex escapes a collapsed one
      if (i == 0) row_start = p;
      worst_error = std::max(worst_error, f(p));
      const dmat3 inv = glm::inverse(transform(lobe.mean, p));
      // glm is column-major: inv[col][row].
      const double k = inv[1][1];
      table[static_cast<std::size_t>(j * kSide + i)] = {inv[0][0] / k, inv[2][0] / k, inv[0][2] / k, inv[2][2] / k};
    }
    std::fprintf(stderr, "roughness %.3f done (m11 %.4g m22 %.4g m13 %.4g at grazing)\n", roughness, p[0], p[1], p[2]);
  }
  if (!write_table(argv[1], table)) return 1;
  std::fprintf(stderr, "worst fit error %.4g\n", worst_error);
  return 0;
}
