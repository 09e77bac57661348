#include "raytrace/reference_brdf.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/color.h"

namespace gi {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;

// Smith masking G1 of the view direction (the normalization of the visible-normal density).
float smith_g1(float n_dot_v, float alpha) {
  const float a2 = alpha * alpha;
  return 2.0f * n_dot_v / (n_dot_v + std::sqrt(a2 + (1.0f - a2) * n_dot_v * n_dot_v));
}

// Heitz 2018, listing 1: a visible normal in the local frame (z = normal) for view ve.
glm::vec3 sample_ggx_vndf(const glm::vec3& ve, float alpha, float u1, float u2) {
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * ve.x, alpha * ve.y, ve.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = lensq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * p2;
  const glm::vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(0.0f, nh.z)));
}

}  // namespace

void orthonormal_basis(const glm::vec3& n, glm::vec3& t, glm::vec3& b) {
  const float sign = std::copysign(1.0f, n.z);
  const float a = -1.0f / (sign + n.z);
  const float bb = n.x * n.y * a;
  t = glm::vec3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
  b = glm::vec3(bb, sign + n.y * n.y * a, -n.y);
}

glm::vec3 sample_cosine_hemisphere(const glm::vec3& n, float u1, float u2) {
  glm::vec3 t, b;
  orthonormal_basis(n, t, b);
  const float r = std::sqrt(u1);
  const float phi = 2.0f * kPi * u2;
  const float z = std::sqrt(std::max(0.0f, 1.0f - u1));
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + z * n);
}

glm::vec3 sample_cone(const glm::vec3& axis, float cos_max, float u1, float u2) {
  glm::vec3 t, b;
  orthonormal_basis(axis, t, b);
  const float z = 1.0f - u1 * (1.0f - cos_max);  // cos theta uniform on [cos_max, 1]: uniform in solid angle
  const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  const float phi = 2.0f * kPi * u2;
  return glm::normalize(r * std::cos(phi) * t + r * std::sin(phi) * b + z * axis);
}

float ReferenceBrdf::specular_probability(const glm::vec3& wo) const {
  const engine::GltfBrdfValue albedo =
      engine::gltf_directional_albedo(material, std::clamp(glm::dot(normal, wo), 0.0f, 1.0f));
  const float spec = luminance(albedo.specular);
  const float diff = luminance(albedo.diffuse);
  if (!(spec > 0.0f)) return 0.0f;
  if (!(diff > 0.0f)) return 1.0f;
  return std::clamp(spec / (spec + diff), 0.1f, 0.9f);
}

glm::vec3 ReferenceBrdf::eval_cos(const glm::vec3& wo, const glm::vec3& wi) const {
  return engine::gltf_eval_cos(material, normal, wo, wi).sum();
}

float ReferenceBrdf::pdf(const glm::vec3& wo, const glm::vec3& wi) const {
  const float n_dot_l = glm::dot(normal, wi);
  const float n_dot_v = glm::dot(normal, wo);
  if (n_dot_l <= 0.0f || n_dot_v <= 0.0f) return 0.0f;
  const float ps = specular_probability(wo);
  float pdf = (1.0f - ps) * n_dot_l / kPi;
  if (ps > 0.0f) {
    const glm::vec3 h = glm::normalize(wi + wo);
    const float n_dot_h = std::max(glm::dot(normal, h), 0.0f);
    // Visible-normal density mapped to wi: G1(wo) D(h) / (4 n.wo) (Heitz 2018, eq. 17 / 4 wo.h).
    pdf += ps * smith_g1(n_dot_v, material.alpha) * engine::gltf_ggx_distribution(n_dot_h, material.alpha) /
           (4.0f * n_dot_v);
  }
  return pdf;
}

bool ReferenceBrdf::sample(const glm::vec3& wo, float u_lobe, float u1, float u2, BrdfSample& out) const {
  const float n_dot_v = glm::dot(normal, wo);
  if (n_dot_v <= 0.0f) return false;
  const float ps = specular_probability(wo);
  glm::vec3 wi;
  if (u_lobe < ps) {
    glm::vec3 t, b;
    orthonormal_basis(normal, t, b);
    const glm::vec3 ve(glm::dot(wo, t), glm::dot(wo, b), n_dot_v);
    const glm::vec3 m = sample_ggx_vndf(ve, material.alpha, u1, u2);
    const glm::vec3 h = m.x * t + m.y * b + m.z * normal;
    wi = 2.0f * glm::dot(wo, h) * h - wo;
  } else {
    wi = sample_cosine_hemisphere(normal, u1, u2);
  }
  out.pdf = pdf(wo, wi);
  if (!(out.pdf > 0.0f) || !std::isfinite(out.pdf)) return false;
  out.wi = wi;
  out.weight = eval_cos(wo, wi) / out.pdf;
  return out.weight != glm::vec3(0.0f);
}

}  // namespace gi
