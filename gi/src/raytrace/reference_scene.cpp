#include "raytrace/reference_scene.h"

#include <engine/finite.h>

#include "core/color.h"
#include "raytrace/material_lookup.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace gi {
namespace {

engine::Error scene_error(std::string location, std::string message) {
  return engine::Error{"<reference scene>", std::move(location), std::move(message)};
}

// True when emissive triangle `t` lies on area light `l`'s rectangle (within 1 mm of its
// plane and of its outline) and faces the same way: it is the light's visible surface.
bool is_proxy_of(const ShadingTriangle& t, const ReferenceLight& l) {
  constexpr float kTolerance = 1e-3f;
  if (glm::dot(t.face_normal, l.direction) < 0.99f) return false;
  const float hx = glm::length(l.half_x);
  const float hy = glm::length(l.half_y);
  if (hx <= 0.0f || hy <= 0.0f) return false;
  const glm::vec3 ax = l.half_x / hx;
  const glm::vec3 ay = l.half_y / hy;
  for (const glm::vec3& p : {t.p0, t.p0 + t.e1, t.p0 + t.e2}) {
    const glm::vec3 d = p - l.position;
    if (std::fabs(glm::dot(d, l.direction)) > kTolerance) return false;
    if (std::fabs(glm::dot(d, ax)) > hx + kTolerance || std::fabs(glm::dot(d, ay)) > hy + kTolerance) return false;
  }
  return true;
}

// The emitter table over the emissive triangles (of the static instances only, if asked),
// sampled in proportion to power; each triangle's `emitter` points into it or is -1.
void index_emitters(const ReferenceScene& scene, ReferenceSceneIndex& index, bool static_only) {
  index.emitters = {};
  std::vector<double> power;
  const auto& instances = scene.geometry.instances;
  for (std::size_t k = 0; k < index.instance_first.size(); ++k) {
    const auto [first, end] = instance_triangles(index, k);
    const bool skip = static_only && k < instances.size() && instances[k].dynamic;
    for (std::uint32_t t = first; t < end; ++t) {
      ShadingTriangle& tri = index.triangles[t];
      tri.emitter = -1;
      const ReferenceMaterial& mat = scene.materials[tri.material];
      // Sampled by power: an emissive texture's mean over the triangle x the factor.
      const float lum = luminance(mat.emissive_texture.present() ? triangle_emission(scene, tri) : mat.emission);
      if (skip || !(lum > 0.0f) || !(tri.area_m2 > 0.0f)) continue;
      tri.emitter = static_cast<std::int32_t>(index.emitters.triangle.size());
      index.emitters.triangle.push_back(t);
      bool proxy = false;
      for (const ReferenceLight& l : scene.lights)
        proxy = proxy || (l.type == ReferenceLight::Type::Area && is_proxy_of(tri, l));
      index.emitters.stands_for_light.push_back(proxy ? 1 : 0);
      power.push_back(static_cast<double>(lum) * static_cast<double>(tri.area_m2) * (mat.double_sided ? 2.0 : 1.0));
    }
  }
  double total = 0.0;
  for (double p : power) total += p;
  double running = 0.0;
  for (double p : power) {
    running += p;
    index.emitters.probability.push_back(static_cast<float>(p / total));
    index.emitters.cdf.push_back(static_cast<float>(running / total));
  }
  if (!index.emitters.cdf.empty()) index.emitters.cdf.back() = 1.0f;
}

// The scene's materials, UV sets, textures and lights checked before indexing.
engine::Status check_scene(const ReferenceScene& scene) {
  const RtSceneData& g = scene.geometry;
  if (scene.normals.size() != g.geometries.size() || scene.triangle_material.size() != g.geometries.size())
    return scene_error("geometries", "normals/materials given for " + std::to_string(scene.normals.size()) + "/" +
                                         std::to_string(scene.triangle_material.size()) + " of " +
                                         std::to_string(g.geometries.size()) + " geometries");
  for (std::size_t m = 0; m < scene.materials.size(); ++m) {
    const ReferenceMaterial& mat = scene.materials[m];
    const engine::GltfBrdf& b = mat.brdf;
    if (!engine::all_finite(b.base_color) || !engine::all_finite(b.dielectric_f0) ||
        !engine::all_finite(mat.emission) || !std::isfinite(b.alpha) || !(b.alpha > 0.0f) ||
        !(b.metallic >= 0.0f && b.metallic <= 1.0f) || !(b.specular_weight >= 0.0f && b.specular_weight <= 1.0f))
      return scene_error("material " + std::to_string(m),
                         "non-finite value, alpha <= 0, or metallic / specular weight outside [0, 1]");
  }
  for (const auto* uvs : {&scene.uv0, &scene.uv1})
    if (!uvs->empty() && uvs->size() != g.geometries.size())
      return scene_error("geometries", "UV sets given for " + std::to_string(uvs->size()) + " of " +
                                           std::to_string(g.geometries.size()) + " geometries");
  for (std::size_t m = 0; m < scene.materials.size(); ++m)
    for (const MaterialTexture* t :
         {&scene.materials[m].base_color_texture, &scene.materials[m].metallic_roughness_texture,
          &scene.materials[m].emissive_texture})
      if (t->present() &&
          (static_cast<std::size_t>(t->mips) >= scene.textures.size() ||
           scene.textures[static_cast<std::size_t>(t->mips)].levels.empty() || t->texcoord < 0 || t->texcoord > 1))
        return scene_error("material " + std::to_string(m), "texture index out of range or UV set not 0 or 1");
  for (std::size_t i = 0; i < scene.lights.size(); ++i) {
    const ReferenceLight& l = scene.lights[i];
    if (!engine::all_finite(l.position) || !engine::all_finite(l.direction) || !engine::all_finite(l.radiant) ||
        !engine::all_finite(l.half_x) || !engine::all_finite(l.half_y))
      return scene_error("light " + std::to_string(i), "non-finite position, direction, size or intensity");
  }
  return {};
}

// What one instance's triangles share: its vertex normals and UV sets (null: none), its
// transform's normal matrix and whether it mirrors.
struct InstanceFrame {
  const std::vector<glm::vec3>& normals;
  const std::vector<glm::vec2>* uv_sets[2];
  glm::mat3 normal_matrix;
  bool mirrored;
};

// The world-space triangle of vertices vi (positions p) with its face and vertex normals,
// material and UVs with their density.
ShadingTriangle shading_triangle(const glm::vec3 (&p)[3], const std::uint32_t (&vi)[3], const InstanceFrame& f,
                                 std::uint32_t material) {
  ShadingTriangle tri;
  tri.p0 = p[0];
  tri.e1 = p[1] - p[0];
  tri.e2 = p[2] - p[0];
  const glm::vec3 c = glm::cross(tri.e1, tri.e2);
  const float len = glm::length(c);
  tri.area_m2 = 0.5f * len;
  tri.face_normal = len > 0.0f ? c / len : glm::vec3(0.0f, 1.0f, 0.0f);
  if (f.mirrored) tri.face_normal = -tri.face_normal;
  glm::vec3 n[3];
  for (int k = 0; k < 3; ++k) {
    n[k] = f.normals.empty() ? tri.face_normal : f.normal_matrix * f.normals[vi[k]];
    const float nl = glm::length(n[k]);
    n[k] = (nl > 0.0f && std::isfinite(nl)) ? n[k] / nl : tri.face_normal;
  }
  tri.n0 = n[0];
  tri.n1 = n[1];
  tri.n2 = n[2];
  tri.material = material;
  for (int set = 0; set < 2; ++set) {
    if (!f.uv_sets[set]) continue;
    glm::vec2* uv = set == 0 ? tri.uv0 : tri.uv1;
    for (int k = 0; k < 3; ++k) uv[k] = (*f.uv_sets[set])[vi[k]];
    const glm::vec2 a = uv[1] - uv[0], b = uv[2] - uv[0];
    const float uv_area = 0.5f * std::fabs(a.x * b.y - a.y * b.x);
    const float per_m = tri.area_m2 > 0.0f ? std::sqrt(uv_area / tri.area_m2) : 0.0f;
    tri.uv_per_m[set] = std::isfinite(per_m) ? per_m : 0.0f;
  }
  return tri;
}

// Appends instance `inst`'s triangles to the index (checked), growing the bounds lo..hi.
engine::Status index_instance(const ReferenceScene& scene, std::size_t inst, ReferenceSceneIndex& index, glm::vec3& lo,
                              glm::vec3& hi) {
  const RtSceneData& g = scene.geometry;
  const RtInstance& in = g.instances[inst];
  const std::string where = "instance " + std::to_string(inst);
  if (in.geometry >= g.geometries.size()) return scene_error(where, "geometry index out of range");
  const RtGeometry& geo = g.geometries[in.geometry];
  const auto& mats = scene.triangle_material[in.geometry];
  const std::size_t tri_count = geo.indices.size() / 3;
  const glm::mat4& m = in.object_to_world;
  InstanceFrame frame{scene.normals[in.geometry],
                      {nullptr, nullptr},
                      glm::transpose(glm::inverse(glm::mat3(m))),
                      glm::determinant(glm::mat3(m)) < 0.0f};  // glTF: front faces turn clockwise
  if (!frame.normals.empty() && frame.normals.size() != geo.positions.size())
    return scene_error(where, "normal count differs from vertex count");
  if (mats.size() != tri_count) return scene_error(where, "material count differs from triangle count");
  for (int set = 0; set < 2; ++set) {
    const auto& uvs = set == 0 ? scene.uv0 : scene.uv1;
    if (uvs.empty() || uvs[in.geometry].empty()) continue;
    if (uvs[in.geometry].size() != geo.positions.size())
      return scene_error(where, "TEXCOORD_" + std::to_string(set) + " count differs from vertex count");
    frame.uv_sets[set] = &uvs[in.geometry];
  }
  index.instance_first.push_back(static_cast<std::uint32_t>(index.triangles.size()));
  for (std::size_t t = 0; t < tri_count; ++t) {
    std::uint32_t vi[3];
    for (int k = 0; k < 3; ++k) {
      vi[k] = geo.indices[3 * t + static_cast<std::size_t>(k)];
      if (vi[k] >= geo.positions.size())
        return scene_error(where, "triangle " + std::to_string(t) + ": index out of range");
    }
    if (mats[t] >= scene.materials.size())
      return scene_error(where, "triangle " + std::to_string(t) + ": material index out of range");
    glm::vec3 p[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = glm::vec3(m * glm::vec4(geo.positions[vi[k]], 1.0f));
      if (!engine::all_finite(p[k]))
        return scene_error(where, "triangle " + std::to_string(t) + ": non-finite position");
      lo = glm::min(lo, p[k]);
      hi = glm::max(hi, p[k]);
    }
    index.triangles.push_back(shading_triangle(p, vi, frame, mats[t]));
  }
  return {};
}

}  // namespace

engine::Result<ReferenceSceneIndex> index_reference_scene(const ReferenceScene& scene) {
  if (engine::Status ok = check_scene(scene); !ok) return ok.error();
  ReferenceSceneIndex index;
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (std::size_t inst = 0; inst < scene.geometry.instances.size(); ++inst)
    if (engine::Status ok = index_instance(scene, inst, index, lo, hi); !ok) return ok.error();
  index.scene_radius_m = index.triangles.empty() ? 1.0f : 0.5f * glm::length(hi - lo);

  index.light_has_proxy.assign(scene.lights.size(), false);
  for (const ShadingTriangle& tri : index.triangles) {
    if (!(luminance(scene.materials[tri.material].emission) > 0.0f) || !(tri.area_m2 > 0.0f)) continue;
    for (std::size_t l = 0; l < scene.lights.size(); ++l)
      if (scene.lights[l].type == ReferenceLight::Type::Area && is_proxy_of(tri, scene.lights[l]))
        index.light_has_proxy[l] = true;
  }
  index_emitters(scene, index, /*static_only=*/false);
  return index;
}

void keep_static_emitters(const ReferenceScene& scene, ReferenceSceneIndex& index) {
  index_emitters(scene, index, /*static_only=*/true);
}

ReferenceBrdf shading_brdf(const ReferenceScene& scene, const ShadingTriangle& tri, glm::vec2 uv, bool front,
                           float footprint_m) {
  ReferenceBrdf f;
  f.material = material_brdf_at(scene, tri, uv, footprint_m);
  glm::vec3 n = (1.0f - uv.x - uv.y) * tri.n0 + uv.x * tri.n1 + uv.y * tri.n2;
  const float len = glm::length(n);
  n = len > 1e-8f ? n / len : tri.face_normal;
  const glm::vec3 facing = front ? tri.face_normal : -tri.face_normal;
  if (!front) n = -n;
  // A shading normal on the other side of the surface than the viewer would reflect light
  // through the surface: use the geometric normal there.
  if (glm::dot(n, facing) <= 0.0f) n = facing;
  f.normal = n;
  return f;
}

}  // namespace gi
