#include <engine/gltf_brdf.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <map>
#include <mutex>
#include <numbers>

namespace engine {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

float max_component(const glm::vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

// The (a, b) integrals of the specular lobe at one view angle by quadrature over the GGX
// distribution of half vectors: h = (theta_h, phi) with tan(theta_h) = alpha sqrt(u/(1-u))
// has density D(h) n.h, so l = reflect(v, h) has D n.h / (4 v.h) and the estimator of
// integral(g dl) is g / that. For g = D V n.l the D cancels: 4 V n.l v.h / n.h. Midpoint
// rule over (s, phi in [0, pi]) (the integrand is even in phi), `nu` x `nphi` points, with
// u = 1 - (1 - s)^2: the integrand changes fastest near u = 1 (h near the horizon, where l
// crosses it), and a plain grid in u converged only like 1/nu there (0.04 off at grazing v
// with 64 points; 0.003 with this substitution).
glm::dvec2 specular_integrals(float n_dot_v, float alpha, int nu, int nphi) {
  const float mu = std::clamp(n_dot_v, GltfAlbedoTable::kMinCos, 1.0f);
  const glm::vec3 v(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  double a = 0.0, b = 0.0;
  for (int i = 0; i < nu; ++i) {
    const double s = (i + 0.5) / nu;
    const double u = 1.0 - (1.0 - s) * (1.0 - s);
    const double du_ds = 2.0 * (1.0 - s);
    const double tan_h = static_cast<double>(alpha) * std::sqrt(u / (1.0 - u));
    const auto cos_h = static_cast<float>(1.0 / std::sqrt(1.0 + tan_h * tan_h));
    const float sin_h = std::sqrt(std::max(0.0f, 1.0f - cos_h * cos_h));
    for (int k = 0; k < nphi; ++k) {
      const float phi = kPi * (static_cast<float>(k) + 0.5f) / static_cast<float>(nphi);
      const glm::vec3 h(sin_h * std::cos(phi), sin_h * std::sin(phi), cos_h);
      const float v_dot_h = glm::dot(v, h);
      if (v_dot_h <= 0.0f) continue;
      const glm::vec3 l = 2.0f * v_dot_h * h - v;
      if (l.z <= 0.0f) continue;
      const double g = 4.0 * static_cast<double>(gltf_smith_visibility(mu, l.z, alpha) * l.z * v_dot_h / cos_h) * du_ds;
      a += g;
      b += g * static_cast<double>(gltf_schlick_weight(v_dot_h));
    }
  }
  return glm::dvec2(a, b) / static_cast<double>(nu * nphi);
}

// p: the mean of (1 - v.h)^5 over cosine-distributed l (roughness does not enter).
double diffuse_fresnel_integral(float n_dot_v, int nr, int nphi) {
  const float mu = std::clamp(n_dot_v, GltfAlbedoTable::kMinCos, 1.0f);
  const glm::vec3 v(std::sqrt(std::max(0.0f, 1.0f - mu * mu)), 0.0f, mu);
  double p = 0.0;
  for (int i = 0; i < nr; ++i) {
    const float u = (static_cast<float>(i) + 0.5f) / static_cast<float>(nr);
    const float r = std::sqrt(u);
    const float z = std::sqrt(1.0f - u);
    for (int k = 0; k < nphi; ++k) {
      const float phi = kPi * (static_cast<float>(k) + 0.5f) / static_cast<float>(nphi);
      const glm::vec3 l(r * std::cos(phi), r * std::sin(phi), z);
      const glm::vec3 h = glm::normalize(l + v);
      p += static_cast<double>(gltf_schlick_weight(glm::dot(v, h)));
    }
  }
  return p / static_cast<double>(nr * nphi);
}

constexpr int kTableU = 128;   // quadrature points over the half-vector angle
constexpr int kTablePhi = 32;  // ... and over the azimuth in [0, pi]

float roughness_of_node(int j) {
  return kGltfMinRoughness + (1.0f - kGltfMinRoughness) * static_cast<float>(j) / (GltfAlbedoTable::kSize - 1);
}

float cos_of_node(int i) {
  const float x = static_cast<float>(i) / (GltfAlbedoTable::kSize - 1);
  return std::max(x * x, GltfAlbedoTable::kMinCos);
}

GltfBrdfValue albedo_from_integrals(const GltfBrdf& m, const glm::vec3& abp) {
  const float a = abp.x, b = abp.y, p = abp.z;
  const float f0m = max_component(m.dielectric_f0);
  GltfBrdfValue out;
  out.diffuse = (1.0f - m.metallic) * m.base_color * (1.0f - m.specular_weight * (f0m + (1.0f - f0m) * p));
  out.specular = (1.0f - m.metallic) * m.specular_weight * (m.dielectric_f0 * a + (1.0f - m.dielectric_f0) * b) +
                 m.metallic * (m.base_color * a + (1.0f - m.base_color) * b);
  return out;
}

}  // namespace

GltfBrdf gltf_brdf(const glm::vec3& base_color, float metallic, float roughness, float specular_weight,
                   const glm::vec3& specular_color) {
  GltfBrdf m;
  m.base_color = glm::max(base_color, glm::vec3(0.0f));
  m.metallic = std::clamp(metallic, 0.0f, 1.0f);
  const float r = std::clamp(roughness, kGltfMinRoughness, 1.0f);
  m.alpha = r * r;
  m.specular_weight = std::clamp(specular_weight, 0.0f, 1.0f);
  m.dielectric_f0 = glm::min(kGltfDielectricF0 * glm::max(specular_color, glm::vec3(0.0f)), glm::vec3(1.0f));
  return m;
}

GltfBrdf gltf_lambertian(const glm::vec3& albedo) {
  GltfBrdf m = gltf_brdf(albedo, 0.0f, 1.0f);
  m.specular_weight = 0.0f;
  return m;
}

float gltf_ggx_distribution(float n_dot_h, float alpha) {
  const float a2 = alpha * alpha;
  const float d = n_dot_h * n_dot_h * (a2 - 1.0f) + 1.0f;
  return a2 / (kPi * d * d);
}

float gltf_smith_visibility(float n_dot_v, float n_dot_l, float alpha) {
  const float a2 = alpha * alpha;
  const float gv = n_dot_l * std::sqrt(n_dot_v * n_dot_v * (1.0f - a2) + a2);
  const float gl = n_dot_v * std::sqrt(n_dot_l * n_dot_l * (1.0f - a2) + a2);
  return 0.5f / std::max(gv + gl, 1e-7f);
}

float gltf_schlick_weight(float v_dot_h) {
  const float m = 1.0f - std::clamp(v_dot_h, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

float gltf_diffuse_weight(const GltfBrdf& m, float v_dot_h) {
  const float f0m = max_component(m.dielectric_f0);
  return 1.0f - m.specular_weight * (f0m + (1.0f - f0m) * gltf_schlick_weight(v_dot_h));
}

GltfBrdfValue gltf_eval_cos(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v, const glm::vec3& l) {
  GltfBrdfValue out;
  const float n_dot_l = glm::dot(n, l);
  if (!(n_dot_l > 0.0f)) return out;
  const float n_dot_v = std::max(glm::dot(n, v), 1e-4f);
  const glm::vec3 sum = l + v;
  const float len2 = glm::dot(sum, sum);
  const glm::vec3 h = len2 > 1e-12f ? sum / std::sqrt(len2) : n;
  const float n_dot_h = std::clamp(glm::dot(n, h), 0.0f, 1.0f);
  const float v_dot_h = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
  const float w = gltf_schlick_weight(v_dot_h);
  const glm::vec3 f_dielectric = m.dielectric_f0 + (1.0f - m.dielectric_f0) * w;
  const glm::vec3 f_metal = m.base_color + (1.0f - m.base_color) * w;
  const float lobe = gltf_ggx_distribution(n_dot_h, m.alpha) * gltf_smith_visibility(n_dot_v, n_dot_l, m.alpha);
  out.diffuse = (1.0f - m.metallic) * gltf_diffuse_weight(m, v_dot_h) * m.base_color * (n_dot_l / kPi);
  out.specular = ((1.0f - m.metallic) * m.specular_weight * f_dielectric + m.metallic * f_metal) * (lobe * n_dot_l);
  return out;
}

glm::vec4 gltf_albedo_integrals(float n_dot_v, float alpha) {
  const glm::dvec2 ab = specular_integrals(n_dot_v, alpha, kTableU, kTablePhi);
  const double p = diffuse_fresnel_integral(n_dot_v, kTableU, kTablePhi);
  return glm::vec4(static_cast<float>(ab.x), static_cast<float>(ab.y), static_cast<float>(p), 0.0f);
}

const GltfAlbedoTable& gltf_albedo_table() {
  static const GltfAlbedoTable table = [] {
    GltfAlbedoTable t{};
    constexpr int n = GltfAlbedoTable::kSize;
    float p[n];
    for (int i = 0; i < n; ++i) p[i] = static_cast<float>(diffuse_fresnel_integral(cos_of_node(i), kTableU, kTablePhi));
    for (int j = 0; j < n; ++j) {
      const float r = roughness_of_node(j);
      for (int i = 0; i < n; ++i) {
        const glm::dvec2 ab = specular_integrals(cos_of_node(i), r * r, kTableU, kTablePhi);
        t.node[j][i] = glm::vec4(static_cast<float>(ab.x), static_cast<float>(ab.y), p[i], 0.0f);
      }
    }
    return t;
  }();
  return table;
}

glm::vec4 GltfAlbedoTable::sample(float n_dot_v, float roughness) const {
  constexpr float last = kSize - 1;
  const float x = std::sqrt(std::clamp(n_dot_v, 0.0f, 1.0f)) * last;
  const float y = std::clamp((roughness - kGltfMinRoughness) / (1.0f - kGltfMinRoughness), 0.0f, 1.0f) * last;
  const int i0 = std::min(static_cast<int>(x), kSize - 2);
  const int j0 = std::min(static_cast<int>(y), kSize - 2);
  const float fx = x - static_cast<float>(i0);
  const float fy = y - static_cast<float>(j0);
  const glm::vec4 lo = glm::mix(node[j0][i0], node[j0][i0 + 1], fx);
  const glm::vec4 hi = glm::mix(node[j0 + 1][i0], node[j0 + 1][i0 + 1], fx);
  return glm::mix(lo, hi, fy);
}

GltfBrdfValue gltf_directional_albedo(const GltfBrdf& m, float n_dot_v) {
  const glm::vec4 abp = gltf_albedo_table().sample(n_dot_v, std::sqrt(m.alpha));
  return albedo_from_integrals(m, glm::vec3(abp));
}

GltfBrdfValue gltf_hemispherical_albedo(const GltfBrdf& m) {
  // Midpoint rule in cos(theta_v) with the weight 2 cos(theta_v); the integrals at the
  // material's own alpha (not the table's interpolation). They depend on alpha alone and
  // cost ~400k BRDF evaluations, so each alpha is integrated once per process (the bakers
  // ask per material, from several threads, on every bake).
  static std::mutex mutex;
  static std::map<std::uint32_t, glm::vec3> integrals_of_alpha;
  const std::uint32_t key = std::bit_cast<std::uint32_t>(m.alpha);
  {
    const std::lock_guard lock(mutex);
    if (auto it = integrals_of_alpha.find(key); it != integrals_of_alpha.end())
      return albedo_from_integrals(m, it->second);
  }
  constexpr int kCos = 48;
  glm::dvec3 sum(0.0);
  for (int i = 0; i < kCos; ++i) {
    const float mu = (static_cast<float>(i) + 0.5f) / kCos;
    sum += 2.0 * static_cast<double>(mu) * glm::dvec3(gltf_albedo_integrals(mu, m.alpha));
  }
  const glm::vec3 abp(sum / static_cast<double>(kCos));
  {
    const std::lock_guard lock(mutex);
    integrals_of_alpha.emplace(key, abp);
  }
  return albedo_from_integrals(m, abp);
}

}  // namespace engine
