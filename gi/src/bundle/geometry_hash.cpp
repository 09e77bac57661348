#include "bundle/geometry_hash.h"

#include <cstdint>
#include <span>
#include <vector>

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

// A texture the bakers read: its image's content (by the per-image hash), UV set, sampler
// and transform. Added only for a present texture.
void add_texture(ContentHash& h, const BakeTexture& t, const std::vector<std::uint64_t>& image_hash) {
  h.add_value(static_cast<std::int32_t>(t.image));
  h.add_value(t.image >= 0 && static_cast<std::size_t>(t.image) < image_hash.size()
                  ? image_hash[static_cast<std::size_t>(t.image)]
                  : std::uint64_t{0});
  h.add_value(static_cast<std::int32_t>(t.texcoord));
  h.add_value(t.sampler.wrap_s);
  h.add_value(t.sampler.wrap_t);
  h.add_value(static_cast<std::uint8_t>(t.sampler.mipmaps));
  h.add_value(t.transform.offset.x);
  h.add_value(t.transform.offset.y);
  h.add_value(t.transform.rotation_rad);
  h.add_value(t.transform.scale.x);
  h.add_value(t.transform.scale.y);
}

// What a textured or cut-out material adds (nothing for an untextured opaque one, so the
// hashes of bundles baked before the bakers read textures stay what they were): the
// textures the bakers read, alpha mode, cutoff and alpha factor, and the primitive's UV
// sets per corner (the texture is read through them).
void add_material_textures(ContentHash& h, const BakeMaterial& m, const BakePrimitive& p,
                           const std::vector<std::uint64_t>& image_hash) {
  if (!m.textured() && !m.cuts_out()) return;
  h.add_string("textures");
  for (const BakeTexture* t : {&m.base_color_texture, &m.metallic_roughness_texture, &m.emissive_texture}) {
    h.add_value(static_cast<std::uint8_t>(t->present()));
    if (t->present()) add_texture(h, *t, image_hash);
  }
  h.add_value(m.alpha_mode);
  h.add_value(m.alpha_cutoff);
  h.add_value(m.base_alpha);
  for (const std::vector<glm::vec2>* uv : {&p.uv0, &p.uv1}) {
    const bool has = uv->size() == p.positions.size();
    h.add_value(static_cast<std::uint8_t>(has));
    if (!has) continue;
    for (const std::uint32_t i : p.indices) {
      const glm::vec2 t = i < uv->size() ? (*uv)[i] : glm::vec2(0.0f);
      h.add_value(t.x);
      h.add_value(t.y);
    }
  }
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
  std::vector<std::uint64_t> image_hash;  // XXH3 of each image's size and texels
  for (const BakeImage& img : input.images) {
    ContentHash ih;
    ih.add_value(static_cast<std::int32_t>(img.width));
    ih.add_value(static_cast<std::int32_t>(img.height));
    ih.add_values(std::span<const std::uint8_t>(img.rgba8));
    image_hash.push_back(ih.value());
  }
  for (const BakeInstance& inst : input.instances) {
    if (inst.mobility != BakeMobility::Static || inst.mesh >= input.meshes.size()) continue;
    h.add_value(inst.id);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) h.add_value(inst.object_to_world[c][r]);
    const BakeMesh& mesh = input.meshes[inst.mesh];
    h.add_value(static_cast<std::uint64_t>(mesh.primitives.size()));
    for (const BakePrimitive& p : mesh.primitives) {
      add_primitive(h, p);
      const BakeMaterial m = bake_material(input, inst, p);
      add_material(h, m);
      add_material_textures(h, m, p, image_hash);
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
