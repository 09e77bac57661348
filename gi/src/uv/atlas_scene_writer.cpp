#include "uv/atlas_scene_writer.h"

#include <string>
#include <vector>

namespace gi {
namespace {

engine::Error mismatch(const engine::SceneAsset& scene, std::size_t mesh_index, const std::string& what) {
  return engine::Error{scene.source, "atlas layout mesh " + std::to_string(mesh_index),
                       "does not match the scene: " + what + " (was the layout built from atlas_inputs_from(scene)?)"};
}

template <class T>
void copy_attribute(const std::vector<T>& from, std::vector<T>& to, const std::vector<std::uint32_t>& source) {
  to.clear();
  if (from.empty()) return;
  to.reserve(source.size());
  for (std::uint32_t v : source) to.push_back(from[v]);
}

// The mesh of one static instance rebuilt with the layout's split vertices and uv1.
// Long because it is one rebuild: check the layout against the mesh, map the output vertices
// to primitives, then rebuild each primitive with that map; the checks and the map feed the last loop.
engine::Result<engine::Mesh> mesh_with_uv1(const engine::SceneAsset& scene, const engine::Mesh& mesh,
                                           const AtlasMeshUv& uv, std::size_t mesh_index) {
  std::size_t vertices = 0, indices = 0;
  for (const engine::Primitive& p : mesh.primitives) {
    vertices += p.positions.size();
    indices += p.indices.size();
  }
  if (indices != uv.indices.size())
    return mismatch(
        scene, mesh_index,
        std::to_string(uv.indices.size()) + " indices against " + std::to_string(indices) + " in the scene");
  if (uv.source_vertex.size() < vertices || uv.uv1.size() != uv.source_vertex.size())
    return mismatch(scene, mesh_index, "fewer output vertices than the mesh has");
  for (std::size_t v = 0; v < vertices; ++v)
    if (uv.source_vertex[v] != v) return mismatch(scene, mesh_index, "vertex " + std::to_string(v) + " is remapped");

  // Output vertex -> (primitive, local index in the rebuilt primitive).
  std::vector<std::size_t> prim_begin;  // first concatenated vertex of each primitive
  std::size_t begin = 0;
  for (const engine::Primitive& p : mesh.primitives) {
    prim_begin.push_back(begin);
    begin += p.positions.size();
  }
  auto primitive_of = [&](std::uint32_t concatenated) {
    std::size_t p = 0;
    while (p + 1 < prim_begin.size() && prim_begin[p + 1] <= concatenated) ++p;
    return p;
  };
  std::vector<std::vector<std::uint32_t>> sources(mesh.primitives.size());  // local vertex -> primitive vertex
  std::vector<std::vector<glm::vec2>> uv1(mesh.primitives.size());
  std::vector<std::uint32_t> local(uv.source_vertex.size());
  for (std::size_t o = 0; o < uv.source_vertex.size(); ++o) {
    const std::uint32_t s = uv.source_vertex[o];
    if (s >= vertices) return mismatch(scene, mesh_index, "a vertex maps outside the mesh");
    const std::size_t p = primitive_of(s);
    local[o] = static_cast<std::uint32_t>(sources[p].size());
    sources[p].push_back(static_cast<std::uint32_t>(s - prim_begin[p]));
    uv1[p].push_back(uv.uv1[o]);
  }

  engine::Mesh out = mesh;
  std::size_t k = 0;
  for (std::size_t p = 0; p < out.primitives.size(); ++p) {
    engine::Primitive& prim = out.primitives[p];
    const engine::Primitive& src = mesh.primitives[p];
    copy_attribute(src.positions, prim.positions, sources[p]);
    copy_attribute(src.normals, prim.normals, sources[p]);
    copy_attribute(src.uv0, prim.uv0, sources[p]);
    copy_attribute(src.tangents, prim.tangents, sources[p]);
    // The atlas takes TEXCOORD_1: a material that reads its textures there would read the
    // atlas's parameterization instead of the artist's (docs/scene-format.md).
    if (src.material >= 0 && static_cast<std::size_t>(src.material) < scene.materials.size()) {
      const engine::Material& m = scene.materials[static_cast<std::size_t>(src.material)];
      for (const engine::TextureRef* t :
           {&m.base_color_texture, &m.metallic_roughness_texture, &m.normal_texture, &m.emissive_texture})
        if (t->present() && t->texcoord == 1)
          return engine::Error{scene.source, "mesh '" + mesh.name + "' primitive " + std::to_string(p),
                               "material '" + m.name +
                                   "' reads a texture from TEXCOORD_1, which the light atlas replaces on static "
                                   "meshes; move the texture to TEXCOORD_0 or make the node dynamic"};
    }
    prim.uv1 = std::move(uv1[p]);
    for (std::uint32_t& i : prim.indices) {
      const std::uint32_t o = uv.indices[k++];
      if (o >= local.size() || primitive_of(uv.source_vertex[o]) != p)
        return mismatch(scene, mesh_index,
                        "a triangle of primitive " + std::to_string(p) + " uses another primitive's vertex");
      i = local[o];
    }
  }
  return out;
}

}  // namespace

engine::Result<engine::SceneAsset> with_atlas_uv1(const engine::SceneAsset& scene, const AtlasLayout& layout) {
  engine::SceneAsset out = scene;
  std::vector<int> static_users(scene.meshes.size(), 0);
  std::vector<bool> dynamic_user(scene.meshes.size(), false);
  for (const engine::Node& n : scene.nodes) {
    if (n.mesh < 0 || static_cast<std::size_t>(n.mesh) >= scene.meshes.size()) continue;
    if (n.gi.mobility == engine::Mobility::Dynamic)
      dynamic_user[static_cast<std::size_t>(n.mesh)] = true;
    else
      ++static_users[static_cast<std::size_t>(n.mesh)];
  }
  std::vector<bool> taken(scene.meshes.size(), false);
  for (std::size_t i = 0; i < layout.meshes.size(); ++i) {
    const AtlasMeshUv& uv = layout.meshes[i];
    if (uv.id < 0 || static_cast<std::size_t>(uv.id) >= scene.nodes.size())
      return mismatch(scene, i, "id " + std::to_string(uv.id) + " is not a node index");
    engine::Node& node = out.nodes[static_cast<std::size_t>(uv.id)];
    if (node.mesh < 0 || static_cast<std::size_t>(node.mesh) >= scene.meshes.size() ||
        node.gi.mobility == engine::Mobility::Dynamic)
      return mismatch(scene, i, "node " + std::to_string(uv.id) + " has no static mesh");
    const auto m = static_cast<std::size_t>(node.mesh);
    engine::Result<engine::Mesh> mesh = mesh_with_uv1(scene, scene.meshes[m], uv, i);
    if (!mesh) return mesh.error();
    if (!taken[m] && !dynamic_user[m]) {
      taken[m] = true;
      out.meshes[m] = std::move(mesh.value());
    } else {
      mesh->name = scene.meshes[m].name + "@" + node.name;
      node.mesh = static_cast<int>(out.meshes.size());
      out.meshes.push_back(std::move(mesh.value()));
    }
  }
  return out;
}

engine::Result<std::vector<engine::AtlasMesh>> atlas_meshes_of(const engine::Scene& scene, const AtlasLayout& layout) {
  const engine::SceneAsset& assets = scene.assets;
  std::vector<engine::AtlasMesh> out;
  out.reserve(layout.meshes.size());
  for (std::size_t i = 0; i < layout.meshes.size(); ++i) {
    const AtlasMeshUv& uv = layout.meshes[i];
    if (uv.id < 0 || static_cast<std::size_t>(uv.id) >= assets.nodes.size())
      return mismatch(assets, i, "id " + std::to_string(uv.id) + " is not a node index");
    const engine::Node& node = assets.nodes[static_cast<std::size_t>(uv.id)];
    if (node.mesh < 0 || static_cast<std::size_t>(node.mesh) >= assets.meshes.size() ||
        node.gi.mobility == engine::Mobility::Dynamic)
      return mismatch(assets, i, "node " + std::to_string(uv.id) + " has no static mesh");
    const auto m = static_cast<std::size_t>(node.mesh);
    engine::Result<engine::Mesh> mesh = mesh_with_uv1(assets, assets.meshes[m], uv, i);
    if (!mesh) return mesh.error();
    // A node without a live entity draws nothing to give the atlas to.
    const auto node_index = static_cast<std::size_t>(uv.id);
    if (node_index >= scene.node_entities.size() || !scene.registry.valid(scene.node_entities[node_index])) continue;
    out.push_back({.entity = scene.node_entities[node_index],
                   .source_mesh = static_cast<std::uint32_t>(m),
                   .mesh = std::move(mesh).value()});
  }
  return out;
}

}  // namespace gi
