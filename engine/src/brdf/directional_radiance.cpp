#include <engine/directional_radiance.h>

#include <algorithm>
#include <cmath>

namespace engine {

glm::vec2 directional_lobe_sample_point(int j) {
  // Hammersley: (j + 1/2) / M and the radical inverse of j in base 2.
  std::uint32_t bits = static_cast<std::uint32_t>(j);
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return {(static_cast<float>(j) + 0.5f) / static_cast<float>(kDirectionalLobeSamples),
          static_cast<float>(bits) * 2.3283064365386963e-10f};
}

void directional_tangent_frame(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  t = std::fabs(n.x) > 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  t = glm::normalize(t - n * glm::dot(n, t));
  b = glm::cross(n, t);
}

int directional_bin_of(std::span<const glm::vec3> directions, const glm::vec3& l) {
  int best = -1;
  float best_dot = -2.0f;
  for (std::size_t k = 0; k < directions.size(); ++k) {
    const float d = glm::dot(l, directions[k]);
    if (d > best_dot) best_dot = d, best = static_cast<int>(k);
  }
  return best;
}

glm::vec3 directional_specular(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                               std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
                               const glm::vec3* bin_normal) {
  const float a = m.alpha;
  const float n_dot_v = std::max(glm::dot(n, v), 1e-4f);
  // The frame (t, b, n) and v in it.
  glm::vec3 t, b;
  directional_tangent_frame(n, t, b);
  // Tangent-frame bins: the frame of the bins' own normal (the same function as the bake's).
  glm::vec3 bin_t(1.0f, 0.0f, 0.0f), bin_b(0.0f, 1.0f, 0.0f), bin_n(0.0f, 0.0f, 1.0f);
  if (bin_normal != nullptr) {
    bin_n = *bin_normal;
    directional_tangent_frame(bin_n, bin_t, bin_b);
  }
  const glm::vec3 ve(glm::dot(v, t), glm::dot(v, b), n_dot_v);
  // Heitz 2018, "Sampling the GGX Distribution of Visible Normals".
  const glm::vec3 vh = glm::normalize(glm::vec3(a * ve.x, a * ve.y, ve.z));
  // Below 1e-7 (a view within 3e-4 rad of the normal) the tangent is float noise, and the
  // samples' rotation about n would differ between the C++ and the GPU: fixed instead.
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = lensq > 1e-7f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float g1 = 2.0f * n_dot_v / (n_dot_v + std::sqrt(a * a + (1.0f - a * a) * n_dot_v * n_dot_v));
  const std::size_t count = std::min(directions.size(), radiance.size());
  glm::vec3 sum_w(0.0f), sum(0.0f);
  for (int j = 0; j < kDirectionalLobeSamples; ++j) {
    const glm::vec2 u = directional_lobe_sample_point(j);
    const float r = std::sqrt(u.x), phi = 6.28318530718f * u.y;
    const float p1 = r * std::cos(phi);
    const float s = 0.5f * (1.0f + vh.z);
    const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
    const glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    const glm::vec3 ne = glm::normalize(glm::vec3(a * nh.x, a * nh.y, std::max(0.0f, nh.z)));
    const glm::vec3 h = ne.x * t + ne.y * b + ne.z * n;
    const glm::vec3 l = 2.0f * glm::dot(v, h) * h - v;
    const float n_dot_l = glm::dot(n, l);
    if (!(n_dot_l > 0.0f)) continue;
    const glm::vec3 l_bins =
        bin_normal != nullptr ? glm::vec3(glm::dot(l, bin_t), glm::dot(l, bin_b), glm::dot(l, bin_n)) : l;
    const int k = directional_bin_of(directions.first(count), l_bins);
    if (k < 0) continue;
    // f cos / pdf of the visible-normal sampling: F(v.h) G2(v, l) / G1(v), per channel.
    const float fresnel_w = gltf_schlick_weight(glm::dot(v, h));
    const glm::vec3 fresnel =
        (1.0f - m.metallic) * m.specular_weight * (m.dielectric_f0 + (1.0f - m.dielectric_f0) * fresnel_w) +
        m.metallic * (m.base_color + (1.0f - m.base_color) * fresnel_w);
    const glm::vec3 w = fresnel * (4.0f * n_dot_l * n_dot_v * gltf_smith_visibility(n_dot_v, n_dot_l, a) / g1);
    sum_w += w;
    sum += w * radiance[static_cast<std::size_t>(k)];
  }
  const glm::vec3 albedo = gltf_directional_albedo(m, glm::dot(n, v)).specular;
  glm::vec3 out(0.0f);
  for (int c = 0; c < 3; ++c)
    if (sum_w[c] > 0.0f) out[c] = albedo[c] * sum[c] / sum_w[c];
  return out;
}

}  // namespace engine
