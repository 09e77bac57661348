#include "bundle/geometry_hash.h"

#include <cstdint>

#include "io/content_hash.h"

namespace gi {

namespace {

void add_vec(ContentHash& h, const glm::vec3& v) {
  h.add_value(v.x);
  h.add_value(v.y);
  h.add_value(v.z);
}

void add_material(ContentHash& h, const BakeMaterial& m) {
  add_vec(h, m.base_color);
  h.add_value(m.metallic);
  h.add_value(m.roughness);
  add_vec(h, m.emission);
  h.add_value(m.specular);
  add_vec(h, m.specular_color);
  // Back faces reflect and emit when double-sided: it changes the baked light (v4).
  h.add_value(static_cast<std::uint8_t>(m.double_sided));
}

void add_primitive(ContentHash& h, const BakePrimitive& p) {
  const bool has_normals = p.normals.size() == p.positions.size();
  h.add_value(static_cast<std::uint64_t>(p.indices.size()));
  h.add_value(static_cast<std::uint8_t>(has_normals));
  for (const std::uint32_t i : p.indices) {
    if (i >= p.positions.size()) {
      h.add_value(std::uint8_t{0});
      h.add_value(i);
      continue;
    }
    h.add_value(std::uint8_t{1});
    add_vec(h, p.positions[i]);
    if (has_normals) add_vec(h, p.normals[i]);
  }
}

}  // namespace

std::string scene_geometry_hash(const BakeInput& input) {
  ContentHash h;
  // v4: a material's double_sided; v3: from BakeInput (instance ids, the material an override gives); v2: glTF's BRDF
  // (engine/gltf_brdf.h) replaced Lambert + GGX, so a bundle baked with the old reflectances
  // is stale even where the geometry is the same.
  h.add_string("gi scene geometry v4");
  for (const BakeInstance& inst : input.instances) {
    if (inst.mobility != BakeMobility::Static || inst.mesh >= input.meshes.size()) continue;
    h.add_value(inst.id);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(inst.object_to_world[c][r]);
    const BakeMesh& mesh = input.meshes[inst.mesh];
    h.add_value(static_cast<std::uint64_t>(mesh.primitives.size()));
    for (const BakePrimitive& p : mesh.primitives) {
      add_primitive(h, p);
      add_material(h, bake_material(input, inst, p));
    }
  }
  return h.hex();
}

std::string static_lights_hash(const BakeInput& input) {
  ContentHash h;
  h.add_string("gi static lights v2");
  std::uint64_t n = 0;
  for (const BakeLight& bl : input.lights) {
    const engine::Light& l = bl.light;
    if (!l.enabled || l.moves) continue;
    h.add_value(n++);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(bl.light_to_world[c][r]);
    h.add_value(static_cast<std::uint8_t>(l.type));
    add_vec(h, l.color);
    h.add_value(l.intensity);
    h.add_value(l.range_m);
    h.add_value(l.inner_cone_rad);
    h.add_value(l.outer_cone_rad);
    h.add_value(l.area_size_m.x);
    h.add_value(l.area_size_m.y);
    if (l.angular_radius_rad > 0.0f) h.add_value(l.angular_radius_rad);  // the sun's disc
  }
  // The sky is a static source too; hashed only when there is one, so the hashes of
  // bundles of sky-less scenes stay what they were.
  const BakeEnvironment& env = input.environment;
  if (engine::sky_lit(env.sky_radiance, env.sky_gradient)) {
    h.add_string("sky");
    add_vec(h, env.sky_radiance);
    add_vec(h, env.sky_gradient.zenith);
    add_vec(h, env.sky_gradient.horizon);
    add_vec(h, env.sky_gradient.ground);
  }
  return h.hex();
}

}  // namespace gi
