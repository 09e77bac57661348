#pragma once
// Scenes built in code for the renderer tests, a CPU reference of the BRDF and camera
// helpers (pixel <-> world for a known pinhole camera).

#include <cmath>
#include <cstdlib>
#include <memory>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <engine/components.h>
#include <engine/gpu/context.h>
#include <engine/registry.h>
#include <engine/renderer.h>
#include <engine/scene_asset.h>

namespace renderer_test {

constexpr float kPi = 3.14159265358979f;

/// A context or a test failure (never a silent skip).
inline engine::GpuContext headless_context() {
  auto ctx = engine::GpuContext::create_headless();
  if (!ctx) {
    ADD_FAILURE() << "headless GL context creation failed: " << ctx.error().to_string();
    std::abort();
  }
  return std::move(ctx.value());
}

/// A quad (two triangles) centred at c with normal u x v, half extents |u|, |v|.
inline void add_quad(engine::Primitive& p, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const glm::vec3 n = glm::normalize(glm::cross(u, v));
  const auto base = static_cast<std::uint32_t>(p.positions.size());
  const glm::vec3 corners[4] = {c - u - v, c + u - v, c + u + v, c - u + v};
  const glm::vec2 uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  for (int i = 0; i < 4; ++i) {
    p.positions.push_back(corners[i]);
    p.normals.push_back(n);
    p.uv0.push_back(uvs[i]);
    p.uv1.push_back(uvs[i]);
  }
  for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) p.indices.push_back(base + i);
}

/// Horizontal plane y = 0 facing +Y, half size `half_m`.
inline engine::Mesh plane_mesh(float half_m, int material) {
  engine::Mesh m;
  m.name = "plane";
  m.primitives.emplace_back();
  m.primitives[0].material = material;
  add_quad(m.primitives[0], glm::vec3(0.0f), glm::vec3(0, 0, half_m), glm::vec3(half_m, 0, 0));
  return m;
}

/// Axis-aligned box centred at the origin with outward faces.
inline engine::Mesh box_mesh(glm::vec3 half, int material) {
  engine::Mesh m;
  m.name = "box";
  m.primitives.emplace_back();
  engine::Primitive& p = m.primitives[0];
  p.material = material;
  const glm::vec3 x(half.x, 0, 0), y(0, half.y, 0), z(0, 0, half.z);
  add_quad(p, y, z, x);   // +Y
  add_quad(p, -y, x, z);  // -Y
  add_quad(p, x, y, z);   // +X
  add_quad(p, -x, z, y);  // -X
  add_quad(p, z, x, y);   // +Z
  add_quad(p, -z, y, x);  // -Z
  return m;
}

inline engine::Material diffuse_material(float albedo, float roughness = 1.0f, float metallic = 0.0f) {
  engine::Material m;
  m.base_color = glm::vec4(albedo, albedo, albedo, 1.0f);
  m.roughness = roughness;
  m.metallic = metallic;
  return m;
}

/// World matrix of an object at `eye` whose local -Z points at `target`.
inline glm::mat4 looking_at(glm::vec3 eye, glm::vec3 target) {
  const glm::vec3 f = glm::normalize(target - eye);
  const glm::vec3 up = std::abs(f.y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0);
  return glm::inverse(glm::lookAt(eye, target, up));
}

inline engine::Entity add_entity(engine::Registry& reg, const glm::mat4& world) {
  engine::Entity e = reg.create();
  reg.emplace<engine::WorldTransform>(e, engine::WorldTransform{world});
  return e;
}

inline engine::Entity add_mesh(engine::Registry& reg, std::uint32_t mesh, const glm::mat4& world,
                               bool is_static = true) {
  engine::Entity e = add_entity(reg, world);
  reg.emplace<engine::MeshRenderer>(e, engine::MeshRenderer{mesh, -1, true});
  if (is_static)
    reg.emplace<engine::StaticTag>(e);
  else
    reg.emplace<engine::DynamicTag>(e);
  return e;
}

inline engine::Entity add_light(engine::Registry& reg, const engine::Light& light, glm::vec3 position,
                                glm::vec3 target) {
  engine::Entity e = add_entity(reg, looking_at(position, target));
  reg.emplace<engine::Light>(e, light);
  return e;
}

/// A pinhole camera at `eye` looking at `target` (square image, fov `yfov`).
struct TestCamera {
  glm::vec3 eye;
  glm::vec3 target;
  float yfov = 0.8f;
  int size = 65;

  engine::Entity add_to(engine::Registry& reg) const {
    engine::Entity e = add_entity(reg, looking_at(eye, target));
    reg.emplace<engine::Camera>(e, engine::Camera{yfov, 0.05f, 100.0f, 0.0f});
    return e;
  }
  /// The point of the plane y = 0 seen through the centre of pixel (px, py) (rows top down).
  glm::vec3 plane_point(int px, int py) const {
    const glm::mat4 w = looking_at(eye, target);
    const glm::vec3 right(w[0]), up(w[1]), back(w[2]);
    const float t = std::tan(0.5f * yfov);
    const float x = (2.0f * (static_cast<float>(px) + 0.5f) / static_cast<float>(size) - 1.0f) * t;
    const float y = (1.0f - 2.0f * (static_cast<float>(py) + 0.5f) / static_cast<float>(size)) * t;
    const glm::vec3 d = -back + x * right + y * up;
    return eye + d * (-eye.y / d.y);
  }
  /// The pixel whose centre is nearest to world point p.
  glm::ivec2 pixel_of(glm::vec3 p) const {
    const glm::mat4 view = glm::lookAt(
        eye, target, std::abs(glm::normalize(target - eye).y) > 0.99f ? glm::vec3(0, 0, -1) : glm::vec3(0, 1, 0));
    const glm::vec4 clip = glm::perspective(yfov, 1.0f, 0.05f, 100.0f) * view * glm::vec4(p, 1.0f);
    const glm::vec2 ndc = glm::vec2(clip) / clip.w;
    const float s = static_cast<float>(size);
    return {static_cast<int>(std::floor((ndc.x * 0.5f + 0.5f) * s)),
            static_cast<int>(std::floor((0.5f - 0.5f * ndc.y) * s))};
  }
};

/// Red channel of pixel (x, y) of an image with rows top to bottom.
inline float red(const engine::ImageRgbaF& img, int x, int y) {
  return img
      .pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x)) * 4];
}
inline float red(const engine::ImageRgbaF& img, glm::ivec2 p) { return red(img, p.x, p.y); }

/// CPU reference of the renderer's BRDF times cos for a dielectric/metal of grey base
/// colour, written from glTF 2.0's Appendix B independently of engine/gltf_brdf.h:
/// mix(dielectric = (1 - F_d) Lambert + F_d GGX, metal = F_m GGX, metallic), GGX with Smith
/// height-correlated visibility, Schlick Fresnel on v.h.
inline float reference_brdf_cos(float base, float metallic, float roughness, glm::vec3 n, glm::vec3 v, glm::vec3 l) {
  const float nl = glm::dot(n, l);
  if (nl <= 0.0f) return 0.0f;
  const float nv = std::max(glm::dot(n, v), 1e-4f);
  const glm::vec3 h = glm::normalize(l + v);
  const float nh = std::max(glm::dot(n, h), 0.0f);
  const float vh = std::max(glm::dot(v, h), 0.0f);
  const float a = roughness * roughness;
  const float a2 = a * a;
  const float dd = nh * nh * (a2 - 1.0f) + 1.0f;
  const float d = a2 / (kPi * dd * dd);
  const float vis = 0.5f / (nl * std::sqrt(nv * nv * (1 - a2) + a2) + nv * std::sqrt(nl * nl * (1 - a2) + a2));
  const float w = std::pow(1.0f - vh, 5.0f);
  const float f_dielectric = 0.04f + 0.96f * w;
  const float f_metal = base + (1.0f - base) * w;
  const float dielectric = (1.0f - f_dielectric) * base / kPi + f_dielectric * d * vis;
  const float metal = f_metal * d * vis;
  return ((1.0f - metallic) * dielectric + metallic * metal) * nl;
}

/// Radiance at plane point p (normal +Y) seen from `eye`, lit by a point light.
inline float reference_point_light(float base, float roughness, glm::vec3 p, glm::vec3 eye, glm::vec3 light_pos,
                                   float intensity) {
  const glm::vec3 d = light_pos - p;
  const float d2 = glm::dot(d, d);
  return intensity / d2 *
         reference_brdf_cos(base, 0.0f, roughness, glm::vec3(0, 1, 0), glm::normalize(eye - p), glm::normalize(d));
}

inline std::unique_ptr<engine::Renderer> make_renderer(const engine::SceneAsset& assets, int size, float ambient) {
  engine::RenderSettings s;
  s.width = size;
  s.height = size;
  s.shadow_map_size = 512;
  s.stand_in_ambient = ambient;
  auto r = engine::Renderer::create(assets, s);
  if (!r) {
    ADD_FAILURE() << "Renderer::create failed: " << r.error().to_string();
    return nullptr;
  }
  return std::move(r.value());
}

}  // namespace renderer_test
