#include "raytrace/material_lookup.h"

#include <algorithm>
#include <cmath>

namespace gi {
namespace {

constexpr int kFootprintSamples = 4;  // per axis: a receiving element's mean from 4 x 4 points

glm::vec2 material_uv(const ShadingTriangle& tri, int set, glm::vec2 b) {
  const glm::vec2* t = set == 1 ? tri.uv1 : tri.uv0;
  return (1.0f - b.x - b.y) * t[0] + b.x * t[1] + b.y * t[2];
}

float uv_footprint(const ShadingTriangle& tri, const MaterialTexture& t, float footprint_m) {
  return footprint_m * tri.uv_per_m[t.texcoord == 1 ? 1 : 0];
}

glm::vec4 read(const ReferenceScene& scene, const ShadingTriangle& tri, const MaterialTexture& t, glm::vec2 b,
               float footprint_m) {
  return sample_material_texture(scene.textures, t, material_uv(tri, t.texcoord, b), uv_footprint(tri, t, footprint_m));
}

// Factors x the base colour and metallic-roughness textures' values.
engine::GltfBrdf brdf_of(const ReferenceMaterial& m, const glm::vec3& base, const glm::vec2& metal_rough) {
  return engine::gltf_brdf(m.base_color * base, m.metallic * metal_rough.x, m.roughness * metal_rough.y, m.specular,
                           m.specular_color);
}

glm::vec2 clamp_to_triangle(glm::vec2 b) {
  b = glm::max(b, glm::vec2(0.0f));
  const float s = b.x + b.y;
  return s > 1.0f ? b / s : b;
}

}  // namespace

engine::GltfBrdf material_brdf_at(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 bary,
                                  float footprint_m) {
  const ReferenceMaterial& m = scene.materials[tri.material];
  if (!m.base_color_texture.present() && !m.metallic_roughness_texture.present()) return m.brdf;
  const glm::vec3 base = m.base_color_texture.present()
                             ? glm::vec3(read(scene, tri, m.base_color_texture, bary, footprint_m))
                             : glm::vec3(1.0f);
  glm::vec2 mr(1.0f);
  if (m.metallic_roughness_texture.present()) {
    const glm::vec4 t = read(scene, tri, m.metallic_roughness_texture, bary, footprint_m);
    mr = {t.z, t.y};
  }
  return brdf_of(m, base, mr);
}

glm::vec3 emission_at(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 bary, float footprint_m) {
  const ReferenceMaterial& m = scene.materials[tri.material];
  if (!m.emissive_texture.present()) return m.emission;
  return m.emission * glm::vec3(read(scene, tri, m.emissive_texture, bary, footprint_m));
}

namespace {

// The BRDF of the textures' mean over 4 x 4 points given by point(i, j), each read at the
// level of a footprint share_m metres wide.
template <class Point>
engine::GltfBrdf mean_brdf(const ReferenceScene& scene, const ShadingTriangle& tri, float share_m, Point&& point) {
  const ReferenceMaterial& m = scene.materials[tri.material];
  glm::vec3 base(0.0f);
  glm::vec2 mr(0.0f);
  for (int j = 0; j < kFootprintSamples; ++j)
    for (int i = 0; i < kFootprintSamples; ++i) {
      const glm::vec2 b = point(i, j);
      base += m.base_color_texture.present() ? glm::vec3(read(scene, tri, m.base_color_texture, b, share_m))
                                             : glm::vec3(1.0f);
      if (m.metallic_roughness_texture.present()) {
        const glm::vec4 t = read(scene, tri, m.metallic_roughness_texture, b, share_m);
        mr += glm::vec2(t.z, t.y);
      } else {
        mr += glm::vec2(1.0f);
      }
    }
  constexpr float inv = 1.0f / (kFootprintSamples * kFootprintSamples);
  return brdf_of(m, base * inv, mr * inv);
}

// Point (i, j) of 4 x 4 stratified points uniform on the triangle (the square folded by sqrt).
glm::vec2 triangle_point(int i, int j) {
  const float u1 = (static_cast<float>(i) + 0.5f) / kFootprintSamples;
  const float u2 = (static_cast<float>(j) + 0.5f) / kFootprintSamples;
  const float su = std::sqrt(u1);
  return {su * (1.0f - u2), su * u2};
}

}  // namespace

engine::GltfBrdf footprint_brdf(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 centre,
                                glm::vec2 axis_u, glm::vec2 axis_v) {
  const ReferenceMaterial& m = scene.materials[tri.material];
  if (!m.base_color_texture.present() && !m.metallic_roughness_texture.present()) return m.brdf;
  // Each point reads the level of its share of the footprint: the element's width in
  // metres over the samples per axis.
  const float area_m2 = tri.area_m2 * 2.0f * std::fabs(axis_u.x * axis_v.y - axis_u.y * axis_v.x);
  const float share_m = std::sqrt(std::max(area_m2, 0.0f)) / static_cast<float>(kFootprintSamples);
  return mean_brdf(scene, tri, share_m, [&](int i, int j) {
    const float su = (static_cast<float>(i) + 0.5f) / kFootprintSamples - 0.5f;
    const float sv = (static_cast<float>(j) + 0.5f) / kFootprintSamples - 0.5f;
    return clamp_to_triangle(centre + su * axis_u + sv * axis_v);
  });
}

glm::vec3 footprint_albedo(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 centre, glm::vec2 axis_u,
                           glm::vec2 axis_v) {
  return engine::gltf_hemispherical_albedo(footprint_brdf(scene, tri, centre, axis_u, axis_v)).sum();
}

glm::vec3 triangle_albedo(const ReferenceScene& scene, const ShadingTriangle& tri) {
  const ReferenceMaterial& m = scene.materials[tri.material];
  if (!m.base_color_texture.present() && !m.metallic_roughness_texture.present())
    return engine::gltf_hemispherical_albedo(m.brdf).sum();
  const float share_m = std::sqrt(std::max(tri.area_m2, 0.0f)) / static_cast<float>(kFootprintSamples);
  return engine::gltf_hemispherical_albedo(mean_brdf(scene, tri, share_m, triangle_point)).sum();
}

glm::vec3 triangle_emission(const ReferenceScene& scene, const ShadingTriangle& tri) {
  const ReferenceMaterial& m = scene.materials[tri.material];
  if (!m.emissive_texture.present()) return m.emission;
  const float share_m = std::sqrt(std::max(tri.area_m2, 0.0f)) / static_cast<float>(kFootprintSamples);
  glm::vec3 sum(0.0f);
  for (int j = 0; j < kFootprintSamples; ++j)
    for (int i = 0; i < kFootprintSamples; ++i) {
      sum += emission_at(scene, tri, triangle_point(i, j), share_m);
    }
  return sum / static_cast<float>(kFootprintSamples * kFootprintSamples);
}

glm::vec3 albedo_at(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 bary, float footprint_m) {
  return engine::gltf_hemispherical_albedo(material_brdf_at(scene, tri, bary, footprint_m)).sum();
}

}  // namespace gi
