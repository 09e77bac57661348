#include "sweep/sweep_scene.h"

#include <engine/gltf.h>

#include <fstream>
#include <iterator>
#include <vector>

#include "io/content_hash.h"

namespace gi {
namespace {

void add_vec(ContentHash& h, const glm::vec2& v) {
  h.add_value(v.x);
  h.add_value(v.y);
}
void add_vec(ContentHash& h, const glm::vec3& v) {
  h.add_value(v.x);
  h.add_value(v.y);
  h.add_value(v.z);
}
void add_vec(ContentHash& h, const glm::vec4& v) {
  add_vec(h, glm::vec3(v));
  h.add_value(v.w);
}
template <class V>
void add_vecs(ContentHash& h, const std::vector<V>& vs) {
  h.add_value(static_cast<std::uint64_t>(vs.size()));
  for (const V& v : vs) add_vec(h, v);
}

// The meshes and materials, in the hash's order.
void add_geometry(ContentHash& h, const engine::SceneAsset& a) {
  h.add_value(static_cast<std::uint64_t>(a.meshes.size()));
  for (const engine::Mesh& m : a.meshes) {
    h.add_string(m.name);
    h.add_value(static_cast<std::uint64_t>(m.primitives.size()));
    for (const engine::Primitive& p : m.primitives) {
      add_vecs(h, p.positions);
      add_vecs(h, p.normals);
      add_vecs(h, p.uv0);
      add_vecs(h, p.uv1);
      h.add_values(std::span<const std::uint32_t>(p.indices));
      h.add_value(p.material);
    }
  }
  h.add_value(static_cast<std::uint64_t>(a.materials.size()));
  for (const engine::Material& m : a.materials) {
    h.add_string(m.name);
    add_vec(h, m.base_color);
    h.add_value(m.metallic);
    h.add_value(m.roughness);
    add_vec(h, m.emissive);
    h.add_value(m.specular_factor);
    add_vec(h, m.specular_color_factor);
    h.add_value(m.base_color_texture.image);
    h.add_value(m.metallic_roughness_texture.image);
    h.add_value(m.normal_texture.image);
    h.add_value(m.emissive_texture.image);
    h.add_value(m.double_sided);
  }
}

// The images and lights, in the hash's order.
void add_images_and_lights(ContentHash& h, const engine::SceneAsset& a) {
  h.add_value(static_cast<std::uint64_t>(a.images.size()));
  for (const engine::Image& im : a.images) {
    h.add_value(im.width);
    h.add_value(im.height);
    h.add_values(std::span<const std::uint8_t>(im.rgba8));
  }
  h.add_value(static_cast<std::uint64_t>(a.lights.size()));
  for (const engine::NamedLight& nl : a.lights) {
    const engine::Light& l = nl.light;
    h.add_string(nl.name);
    h.add_value(l.type);
    add_vec(h, l.color);
    h.add_value(l.intensity);
    h.add_value(l.range_m);
    h.add_value(l.inner_cone_rad);
    h.add_value(l.outer_cone_rad);
    add_vec(h, l.area_size_m);
    h.add_value(l.moves);
    h.add_value(l.cast_shadows);
    h.add_value(l.enabled);
    if (l.angular_radius_rad > 0.0f) h.add_value(l.angular_radius_rad);  // only then: older keys stay valid
  }
}

// The cameras, nodes and sky, in the hash's order.
void add_cameras_nodes_and_sky(ContentHash& h, const engine::SceneAsset& a) {
  h.add_value(static_cast<std::uint64_t>(a.cameras.size()));
  for (const engine::NamedCamera& c : a.cameras) {
    h.add_string(c.name);
    h.add_value(c.camera.yfov_rad);
    h.add_value(c.camera.znear_m);
    h.add_value(c.camera.zfar_m);
    h.add_value(c.camera.aspect);
  }
  h.add_value(static_cast<std::uint64_t>(a.nodes.size()));
  for (const engine::Node& n : a.nodes) {
    h.add_string(n.name);
    h.add_value(n.parent);
    add_vec(h, n.translation);
    h.add_value(n.rotation.w);
    h.add_value(n.rotation.x);
    h.add_value(n.rotation.y);
    h.add_value(n.rotation.z);
    add_vec(h, n.scale);
    h.add_value(n.mesh);
    h.add_value(n.light);
    h.add_value(n.camera);
    h.add_value(n.gi.mobility);
  }
  // The sky (set in code, e.g. by --sky, or from the file), only when there is one: the
  // fingerprints of sky-less scenes are unchanged.
  const engine::Environment& env = a.environment;
  if (env.sky_radiance != glm::vec3(0.0f) || !env.sky_gradient.empty()) {
    h.add_string("sky");
    add_vec(h, env.sky_radiance);
    add_vec(h, env.sky_gradient.zenith);
    add_vec(h, env.sky_gradient.horizon);
    add_vec(h, env.sky_gradient.ground);
  }
}

void add_asset(ContentHash& h, const engine::SceneAsset& a) {
  add_geometry(h, a);
  add_images_and_lights(h, a);
  add_cameras_nodes_and_sky(h, a);
}

}  // namespace

engine::Result<std::string> scene_fingerprint(const std::filesystem::path& path, const engine::SceneAsset& asset) {
  ContentHash h;
  h.add_string("gi-sweep-scene-v2");  // v2: glTF's BRDF (references made before it are not reused)
  if (!path.empty()) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return engine::Error{path.string(), "", "cannot open the scene file to fingerprint it"};
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) return engine::Error{path.string(), "", "read error while fingerprinting the scene file"};
    h.add_value(static_cast<std::uint64_t>(bytes.size()));
    h.add_bytes(bytes.data(), bytes.size());
  }
  add_asset(h, asset);
  return h.hex();
}

engine::Result<SweepScene> load_sweep_scene(const std::filesystem::path& path) {
  engine::Result<engine::SceneAsset> asset = engine::load_gltf(path);
  if (!asset) return asset.error();
  SweepScene scene;
  scene.path = path;
  scene.asset = std::move(asset.value());
  engine::Result<std::string> hash = scene_fingerprint(path, scene.asset);
  if (!hash) return hash.error();
  scene.content_hash = hash.value();
  return scene;
}

}  // namespace gi
