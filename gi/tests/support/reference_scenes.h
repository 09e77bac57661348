#pragma once
// Hand-built scenes with known answers for the reference path tracer's tests.
//   gi::ReferenceScene s = reftest::plane_scene(0.5f);
//   s.lights.push_back(reftest::point_light({0, 2, 0}, 10.0f));

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "raytrace/reference_scene.h"

namespace reftest {

/// A quad with corners c, c + u, c + u + v, c + v; front side along cross(u, v).
inline void add_quad(gi::RtGeometry& g, glm::vec3 c, glm::vec3 u, glm::vec3 v) {
  const auto base = static_cast<std::uint32_t>(g.positions.size());
  g.positions.insert(g.positions.end(), {c, c + u, c + u + v, c + v});
  g.indices.insert(g.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

/// Adds `g` as one geometry with one material and an identity instance.
inline void add_geometry(gi::ReferenceScene& s, gi::RtGeometry g, const gi::ReferenceMaterial& m) {
  const auto material = static_cast<std::uint32_t>(s.materials.size());
  s.materials.push_back(m);
  const std::size_t triangles = g.indices.size() / 3;
  const auto id = static_cast<std::uint32_t>(s.geometry.geometries.size());
  s.geometry.geometries.push_back(std::move(g));
  s.normals.emplace_back();
  s.triangle_material.emplace_back(triangles, material);
  s.geometry.instances.push_back(gi::RtInstance{id, glm::mat4(1.0f), false, id});
}

inline gi::ReferenceMaterial lambert(float albedo, glm::vec3 emission = glm::vec3(0.0f)) {
  gi::ReferenceMaterial m;
  m.brdf = engine::gltf_lambertian(glm::vec3(albedo));
  m.emission = emission;
  return m;
}

/// A square floor of side `size` at y = 0 centred on the origin, facing +y.
inline gi::ReferenceScene plane_scene(float albedo, float size = 20.0f) {
  gi::ReferenceScene s;
  gi::RtGeometry g;
  add_quad(g, {-0.5f * size, 0, -0.5f * size}, {0, 0, size}, {size, 0, 0});
  add_geometry(s, std::move(g), lambert(albedo));
  return s;
}

/// A closed cube [-1, 1]^3 whose six faces face inwards, all of one material.
inline gi::ReferenceScene furnace_scene(const gi::ReferenceMaterial& m) {
  gi::ReferenceScene s;
  gi::RtGeometry g;
  for (int axis = 0; axis < 3; ++axis) {
    for (float side : {-1.0f, 1.0f}) {
      glm::vec3 c(-1.0f), u(0.0f), v(0.0f);
      c[axis] = side;
      u[(axis + 1) % 3] = 2.0f;
      v[(axis + 2) % 3] = 2.0f;
      // The face at side -1 must face +axis (inwards): cross(u, v) = +axis, so swap for +1.
      if (side > 0) std::swap(u, v);
      add_quad(g, c, u, v);
    }
  }
  add_geometry(s, std::move(g), m);
  return s;
}

inline gi::ReferenceLight point_light(glm::vec3 position, float intensity_w_sr) {
  gi::ReferenceLight l;
  l.type = gi::ReferenceLight::Type::Point;
  l.position = position;
  l.radiant = glm::vec3(intensity_w_sr);
  return l;
}

}  // namespace reftest
