#include <engine/directional_radiance.h>

#include <algorithm>
#include <cmath>

namespace engine {

namespace {

// Hammersley point j of m: (j + 1/2) / m and the radical inverse of j in base 2.
glm::vec2 lobe_sample_point(int j, int m) {
  std::uint32_t bits = static_cast<std::uint32_t>(j);
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return {(static_cast<float>(j) + 0.5f) / static_cast<float>(m), static_cast<float>(bits) * 2.3283064365386963e-10f};
}

// Slack of the search's stopping bound against float rounding (the bound is exact in reals;
// the directions and l are unit to ~1e-7): a larger one only scans more directions.
constexpr float kSearchSlack = 1e-4f;

// Scans directions k = start + step, start + 2 step, ... while they can still beat `best_dot`:
// it stops at the first one beyond l's z (on the scan's side) whose bound l.z psi.z +
// |l.xy| |psi.xy| is below the best found; those farther are further off in z, so lower.
void scan_side(std::span<const glm::vec3> directions, const glm::vec3& l, float l_xy, float l_len, int start, int step,
               int& best, float& best_dot) {
  const int n = static_cast<int>(directions.size());
  for (int k = start + step; k >= 0 && k < n; k += step) {
    const glm::vec3& p = directions[static_cast<std::size_t>(k)];
    const bool beyond = step > 0 ? p.z * l_len < l.z : p.z * l_len > l.z;
    if (beyond && l.z * p.z + l_xy * std::sqrt(p.x * p.x + p.y * p.y) < best_dot - kSearchSlack) break;
    const float d = glm::dot(l, p);
    if (d > best_dot || (d == best_dot && k < best)) best_dot = d, best = k;
  }
}

// f cos / pdf of the visible-normal sampling: F(v.h) G2(v, l) / G1(v), per channel.
glm::vec3 lobe_sample_weight(const GltfBrdf& m, const glm::vec3& v, const glm::vec3& h, float n_dot_v, float n_dot_l,
                             float g1) {
  const float fresnel_w = gltf_schlick_weight(glm::dot(v, h));
  const glm::vec3 fresnel =
      (1.0f - m.metallic) * m.specular_weight * (m.dielectric_f0 + (1.0f - m.dielectric_f0) * fresnel_w) +
      m.metallic * (m.base_color + (1.0f - m.base_color) * fresnel_w);
  return fresnel * (4.0f * n_dot_l * n_dot_v * gltf_smith_visibility(n_dot_v, n_dot_l, m.alpha) / g1);
}

// The bins within `radius` of l blended with weights l.psi - cos(radius); bin `nearest` alone where none is.
glm::vec3 kernel_radiance(std::span<const glm::vec3> dirs, std::span<const glm::vec3> radiance, const glm::vec3& l,
                          float radius, int nearest) {
  const float cos_r = std::cos(radius);
  const float len = std::sqrt(glm::dot(l, l));
  glm::vec3 sum(0.0f);
  float total = 0.0f;
  for (std::size_t k = 0; k < dirs.size(); ++k) {
    const float w = glm::dot(l, dirs[k]) / len - cos_r;
    if (w > 0.0f) sum += w * radiance[k], total += w;
  }
  return total > 0.0f ? sum / total : radiance[static_cast<std::size_t>(nearest)];
}

}  // namespace

glm::vec2 directional_lobe_sample_point(int j) { return lobe_sample_point(j, kDirectionalLobeSamples); }

void directional_tangent_frame(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  t = std::fabs(n.x) > 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  t = glm::normalize(t - n * glm::dot(n, t));
  b = glm::cross(n, t);
}

int directional_bin_of_linear(std::span<const glm::vec3> directions, const glm::vec3& l) {
  int best = -1;
  float best_dot = -2.0f;
  for (std::size_t k = 0; k < directions.size(); ++k) {
    const float d = glm::dot(l, directions[k]);
    if (d > best_dot) best_dot = d, best = static_cast<int>(k);
  }
  return best;
}

int directional_bin_of(std::span<const glm::vec3> directions, const glm::vec3& l) {
  const int n = static_cast<int>(directions.size());
  if (n == 0) return -1;
  const float l_len = std::sqrt(glm::dot(l, l));
  const float z_first = directions.front().z, z_last = directions.back().z;
  // Where l.z would lie among uniform z (a NaN goes to 0 and the scans then test every direction).
  const float at = z_first > z_last ? (z_first - l.z / l_len) / (z_first - z_last) * static_cast<float>(n - 1) : 0.0f;
  const int start = at >= 0.0f ? (at < static_cast<float>(n - 1) ? static_cast<int>(at + 0.5f) : n - 1) : 0;
  int best = -1;
  float best_dot = -2.0f;
  if (const float d = glm::dot(l, directions[static_cast<std::size_t>(start)]); d > best_dot)
    best_dot = d, best = start;
  const float l_xy = std::sqrt(l.x * l.x + l.y * l.y);
  scan_side(directions, l, l_xy, l_len, start, 1, best, best_dot);
  scan_side(directions, l, l_xy, l_len, start, -1, best, best_dot);
  return best;
}

glm::vec3 directional_specular(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                               std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
                               const glm::vec3* bin_normal) {
  return directional_specular_sampled(m, n, v, directions, radiance, bin_normal, kDirectionalLobeSamples);
}

glm::vec3 directional_specular_sampled(const GltfBrdf& m, const glm::vec3& n, const glm::vec3& v,
                                       std::span<const glm::vec3> directions, std::span<const glm::vec3> radiance,
                                       const glm::vec3* bin_normal, int samples, float kernel_radius) {
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
  const std::span<const glm::vec3> dirs = directions.first(count);
  // The search needs the directions sorted by z (gi's sets, and what the GPU reads); others
  // (e.g. a tangent-frame set turned to a normal) are searched linearly.
  const bool sorted =
      std::is_sorted(dirs.begin(), dirs.end(), [](const glm::vec3& p, const glm::vec3& q) { return p.z > q.z; });
  glm::vec3 sum_w(0.0f), sum(0.0f);
  for (int j = 0; j < samples; ++j) {
    const glm::vec2 u = lobe_sample_point(j, samples);
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
    const int k = sorted ? directional_bin_of(dirs, l_bins) : directional_bin_of_linear(dirs, l_bins);
    if (k < 0) continue;
    const glm::vec3 w = lobe_sample_weight(m, v, h, n_dot_v, n_dot_l, g1);
    sum_w += w;
    sum += w * (kernel_radius > 0.0f ? kernel_radiance(dirs, radiance, l_bins, kernel_radius, k)
                                     : radiance[static_cast<std::size_t>(k)]);
  }
  const glm::vec3 albedo = gltf_directional_albedo(m, glm::dot(n, v)).specular;
  glm::vec3 out(0.0f);
  for (int c = 0; c < 3; ++c)
    if (sum_w[c] > 0.0f) out[c] = albedo[c] * sum[c] / sum_w[c];
  return out;
}

}  // namespace engine
