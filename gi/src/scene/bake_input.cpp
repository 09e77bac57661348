#include <engine/finite.h>
#include <gi/bake_input.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <unordered_map>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

namespace gi {

namespace {

BakeMaterial material_from(const engine::Material& m) {
  BakeMaterial b;
  b.name = m.name;
  b.base_color = glm::vec3(m.base_color);
  b.metallic = m.metallic;
  b.roughness = m.roughness;
  b.specular = m.specular_factor;
  b.specular_color = m.specular_color_factor;
  b.emission = m.emissive;
  b.double_sided = m.double_sided;
  b.base_alpha = m.base_color.w;
  b.base_color_texture = m.base_color_texture;
  b.metallic_roughness_texture = m.metallic_roughness_texture;
  b.emissive_texture = m.emissive_texture;
  b.normal_texture = m.normal_texture;
  b.normal_scale = m.normal_scale;
  b.alpha_mode = m.alpha_mode;
  b.alpha_cutoff = m.alpha_cutoff;
  return b;
}

BakeImage image_from(const engine::Image& i) {
  return {.name = i.name, .uri = i.uri, .width = i.width, .height = i.height, .rgba8 = i.rgba8};
}

BakeMesh mesh_from(const engine::Mesh& m) {
  BakeMesh b;
  b.name = m.name;
  for (const engine::Primitive& p : m.primitives)
    b.primitives.push_back({.positions = p.positions,
                            .normals = p.normals,
                            .indices = p.indices,
                            .uv0 = p.uv0,
                            .uv1 = p.uv1,
                            .material = p.material});
  return b;
}

glm::mat4 local_matrix(const engine::Node& n) {
  return glm::translate(glm::mat4(1.0f), n.translation) * glm::mat4_cast(n.rotation) *
         glm::scale(glm::mat4(1.0f), n.scale);
}

// Per node, what its parent chain gives it, for all nodes at once in O(nodes) (walking each
// node's chain was O(nodes x depth): a 2^20-node chain took 2^40 steps): its world matrix,
// whether it or an ancestor is flagged deforming, its nearest dynamic ancestor (itself
// included; -1: none). A chain that loops (the loader refuses those) ends where it loops.
struct NodeChains {
  std::vector<glm::mat4> world;
  std::vector<std::uint8_t> deforming;
  std::vector<int> dynamic_ancestor;
};

NodeChains node_chains(const engine::SceneAsset& asset) {
  const std::size_t n = asset.nodes.size();
  NodeChains c{std::vector<glm::mat4>(n, glm::mat4(1.0f)), std::vector<std::uint8_t>(n, 0), std::vector<int>(n, -1)};
  enum : std::uint8_t { kTodo, kOnChain, kDone };
  std::vector<std::uint8_t> state(n, kTodo);
  std::vector<int> chain;
  const auto in_range = [&](int i) { return i >= 0 && static_cast<std::size_t>(i) < n; };
  for (std::size_t start = 0; start < n; ++start) {
    chain.clear();
    int i = static_cast<int>(start);
    while (in_range(i) && state[static_cast<std::size_t>(i)] == kTodo) {
      state[static_cast<std::size_t>(i)] = kOnChain;
      chain.push_back(i);
      i = asset.nodes[static_cast<std::size_t>(i)].parent;
    }
    int parent = in_range(i) && state[static_cast<std::size_t>(i)] == kDone ? i : -1;
    for (auto it = chain.rbegin(); it != chain.rend(); ++it) {
      const auto k = static_cast<std::size_t>(*it);
      const engine::Node& node = asset.nodes[k];
      const bool own_deforming = node.gi.region == engine::GiRegion::Deforming;
      const bool own_dynamic = node.gi.mobility == engine::Mobility::Dynamic;
      if (parent >= 0) {
        const auto p = static_cast<std::size_t>(parent);
        c.world[k] = c.world[p] * local_matrix(node);
        c.deforming[k] = static_cast<std::uint8_t>(own_deforming || c.deforming[p] != 0);
        c.dynamic_ancestor[k] = own_dynamic ? static_cast<int>(k) : c.dynamic_ancestor[p];
      } else {
        c.world[k] = local_matrix(node);
        c.deforming[k] = static_cast<std::uint8_t>(own_deforming);
        c.dynamic_ancestor[k] = own_dynamic ? static_cast<int>(k) : -1;
      }
      state[k] = kDone;
      parent = static_cast<int>(k);
    }
  }
  return c;
}

std::vector<engine::Entity> sorted(std::vector<engine::Entity> entities) {
  std::sort(entities.begin(), entities.end(), [](engine::Entity a, engine::Entity b) { return a.index < b.index; });
  return entities;
}

// The name of the nearest entity up `e`'s parent chain (itself included) that is dynamic
// (DynamicTag or a node of Dynamic mobility), or empty. Bounded: a cycle cannot loop.
std::string dynamic_ancestor(const engine::Scene& scene, const std::unordered_map<std::uint32_t, int>& node_of,
                             engine::Entity e) {
  const engine::Registry& reg = scene.registry;
  for (std::size_t steps = 0; !e.is_null() && reg.valid(e) && steps < 4096; ++steps) {
    const auto n = node_of.find(e.index);
    const bool dynamic = reg.has<engine::DynamicTag>(e) ||
                         (n != node_of.end() && scene.assets.nodes[static_cast<std::size_t>(n->second)].gi.mobility ==
                                                    engine::Mobility::Dynamic);
    if (dynamic) {
      const engine::Name* name = reg.try_get<engine::Name>(e);
      return name != nullptr && !name->value.empty() ? name->value : "entity " + std::to_string(e.index);
    }
    const engine::Transform* t = reg.try_get<engine::Transform>(e);
    e = t != nullptr ? t->parent : engine::Entity{};
  }
  return {};
}

engine::Error input_error(const std::string& location, const std::string& message) {
  return engine::Error{"<bake input>", location, message};
}

// The textures of a material the bakers check, with their names for messages.
std::array<std::pair<const char*, const BakeTexture*>, 4> material_textures(const BakeMaterial& m) {
  return {{{"base colour", &m.base_color_texture},
           {"metallic-roughness", &m.metallic_roughness_texture},
           {"emissive", &m.emissive_texture},
           {"normal", &m.normal_texture}}};
}

// What is wrong when material `m` reads a UV set primitive `p` lacks (empty: nothing).
std::string missing_uv_set(const BakeMaterial& m, const BakePrimitive& p) {
  for (const auto& [what, t] : material_textures(m)) {
    if (!t->present() || t == &m.normal_texture) continue;
    const std::vector<glm::vec2>& uv = t->texcoord == 1 ? p.uv1 : p.uv0;
    if (uv.size() != p.positions.size() && !p.positions.empty())
      return std::string("material '") + m.name + "' reads its " + what + " texture through TEXCOORD_" +
             std::to_string(t->texcoord) + ", which the primitive lacks";
  }
  return {};
}

}  // namespace

BakeMaterial bake_material(const BakeInput& input, const BakeInstance& instance, const BakePrimitive& p) {
  const int m = instance.material_override >= 0 ? instance.material_override : p.material;
  if (m >= 0 && static_cast<std::size_t>(m) < input.materials.size())
    return input.materials[static_cast<std::size_t>(m)];
  return material_from(engine::Material{});
}

BakeInput without_textures(BakeInput input) {
  for (BakeMaterial& m : input.materials) {
    m.base_color_texture = {};
    m.metallic_roughness_texture = {};
    m.emissive_texture = {};
    m.normal_texture = {};
    m.alpha_mode = engine::AlphaMode::Opaque;
  }
  input.images.clear();
  return input;
}

glm::mat4 node_world_matrix(const engine::SceneAsset& asset, int node) {
  GI_EXPECTS(node >= 0 && static_cast<std::size_t>(node) < asset.nodes.size(), "node indexes asset.nodes");
  glm::mat4 m(1.0f);
  std::size_t steps = 0;
  for (int i = node; i >= 0 && static_cast<std::size_t>(i) < asset.nodes.size() && steps <= asset.nodes.size();
       i = asset.nodes[static_cast<std::size_t>(i)].parent, ++steps) {
    const engine::Node& n = asset.nodes[static_cast<std::size_t>(i)];
    const glm::mat4 t = glm::translate(glm::mat4(1.0f), n.translation);
    const glm::mat4 s = glm::scale(glm::mat4(1.0f), n.scale);
    m = t * glm::mat4_cast(n.rotation) * s * m;
  }
  return m;
}

BakeInput bake_input_from(const engine::SceneAsset& asset) {
  BakeInput in;
  in.name = asset.source;
  in.environment.sky_radiance = asset.environment.sky_radiance;  // the sun is a light of a node
  in.environment.sky_gradient = asset.environment.sky_gradient;
  for (const engine::Mesh& m : asset.meshes) in.meshes.push_back(mesh_from(m));
  for (const engine::Material& m : asset.materials) in.materials.push_back(material_from(m));
  for (const engine::Image& i : asset.images) in.images.push_back(image_from(i));
  const NodeChains chains = node_chains(asset);
  for (std::size_t ni = 0; ni < asset.nodes.size(); ++ni) {
    const engine::Node& node = asset.nodes[ni];
    if (node.mesh >= 0 && static_cast<std::size_t>(node.mesh) < asset.meshes.size()) {
      BakeInstance inst;
      inst.name = node.name;
      inst.mesh = static_cast<std::uint32_t>(node.mesh);
      inst.object_to_world = chains.world[ni];
      inst.mobility = node.gi.mobility == engine::Mobility::Dynamic ? BakeMobility::Dynamic : BakeMobility::Static;
      inst.deforming = chains.deforming[ni] != 0;
      inst.id = static_cast<std::int64_t>(ni);
      in.instances.push_back(std::move(inst));
    }
    if (node.light >= 0 && static_cast<std::size_t>(node.light) < asset.lights.size()) {
      const engine::NamedLight& l = asset.lights[static_cast<std::size_t>(node.light)];
      const int dynamic = chains.dynamic_ancestor[ni];
      in.lights.push_back({.name = node.name.empty() ? l.name : node.name,
                           .light = l.light,
                           .light_to_world = chains.world[ni],
                           .dynamic_parent = dynamic >= 0 ? asset.nodes[static_cast<std::size_t>(dynamic)].name : ""});
    }
  }
  return in;
}

BakeInput bake_input_from(const engine::Scene& scene) {
  const engine::Registry& reg = scene.registry;
  BakeInput in;
  in.name = scene.assets.source;
  in.environment.sky_radiance = scene.assets.environment.sky_radiance;  // the sun is a light entity
  in.environment.sky_gradient = scene.assets.environment.sky_gradient;
  for (const engine::Mesh& m : scene.assets.meshes) in.meshes.push_back(mesh_from(m));
  for (const engine::Material& m : scene.assets.materials) in.materials.push_back(material_from(m));
  for (const engine::Image& i : scene.assets.images) in.images.push_back(image_from(i));

  const NodeChains chains = node_chains(scene.assets);
  std::unordered_map<std::uint32_t, int> node_of;  // entity index -> node index
  for (std::size_t i = 0; i < scene.node_entities.size(); ++i)
    node_of[scene.node_entities[i].index] = static_cast<int>(i);
  for (engine::Entity e : sorted(reg.view<engine::MeshRenderer, engine::WorldTransform>().entities())) {
    const engine::MeshRenderer& mr = reg.get<engine::MeshRenderer>(e);
    if (mr.mesh >= in.meshes.size()) continue;
    BakeInstance inst;
    if (const engine::Name* n = reg.try_get<engine::Name>(e)) inst.name = n->value;
    inst.mesh = mr.mesh;
    inst.object_to_world = reg.get<engine::WorldTransform>(e).matrix;
    inst.mobility = reg.has<engine::DynamicTag>(e) ? BakeMobility::Dynamic : BakeMobility::Static;
    inst.material_override = mr.material_override;
    inst.entity = e;
    const auto node = node_of.find(e.index);
    if (node != node_of.end() && scene.node_entities[static_cast<std::size_t>(node->second)] == e) {
      inst.id = node->second;
      inst.deforming = static_cast<std::size_t>(node->second) < chains.deforming.size() &&
                       chains.deforming[static_cast<std::size_t>(node->second)] != 0;
    }
    in.instances.push_back(std::move(inst));
  }
  for (engine::Entity e : sorted(reg.view<engine::Light, engine::WorldTransform>().entities())) {
    const engine::Light& l = reg.get<engine::Light>(e);
    BakeLight bl;
    if (const engine::Name* n = reg.try_get<engine::Name>(e)) bl.name = n->value;
    bl.light = l;
    bl.light_to_world = reg.get<engine::WorldTransform>(e).matrix;
    bl.dynamic_parent = dynamic_ancestor(scene, node_of, e);
    in.lights.push_back(std::move(bl));
  }
  return in;
}

namespace {

engine::Status check_materials(const BakeInput& input) {
  for (std::size_t mi = 0; mi < input.materials.size(); ++mi) {
    const BakeMaterial& m = input.materials[mi];
    const std::string where = "material " + std::to_string(mi) + " '" + m.name + "'";
    if (!engine::all_finite(m.base_color) || !engine::all_finite(m.specular_color) || !engine::all_finite(m.emission) ||
        !std::isfinite(m.metallic) || !std::isfinite(m.roughness) || !std::isfinite(m.specular))
      return input_error(where, "a factor is NaN or infinite");
    if (glm::any(glm::lessThan(m.base_color, glm::vec3(0.0f))) ||
        glm::any(glm::greaterThan(m.base_color, glm::vec3(1.0f))) || m.metallic < 0.0f || m.metallic > 1.0f ||
        m.roughness < 0.0f || m.roughness > 1.0f || m.specular < 0.0f || m.specular > 1.0f ||
        glm::any(glm::lessThan(m.specular_color, glm::vec3(0.0f))) ||
        glm::any(glm::lessThan(m.emission, glm::vec3(0.0f))))
      return input_error(where,
                         "base colour, metallic, roughness and specular must be in [0, 1], specular colour and "
                         "emission >= 0");
    if (!(m.base_alpha >= 0.0f && m.base_alpha <= 1.0f) || !(m.alpha_cutoff >= 0.0f && m.alpha_cutoff <= 1.0f))
      return input_error(where, "base colour alpha and alpha cutoff must be in [0, 1]");
    for (const auto& [what, t] : material_textures(m)) {
      if (!t->present()) continue;
      if (static_cast<std::size_t>(t->image) >= input.images.size())
        return input_error(where, std::string(what) + " texture: image " + std::to_string(t->image) +
                                      " out of range (" + std::to_string(input.images.size()) + " images)");
      if (t->texcoord < 0 || t->texcoord > 1)
        return input_error(where, std::string(what) + " texture: TEXCOORD_" + std::to_string(t->texcoord) +
                                      " (the bakers read TEXCOORD_0 and TEXCOORD_1)");
      if (!engine::all_finite(t->transform.offset) || !engine::all_finite(t->transform.scale) ||
          !std::isfinite(t->transform.rotation_rad))
        return input_error(where, std::string(what) + " texture: the transform is NaN or infinite");
    }
  }
  return {};
}

engine::Status check_images(const BakeInput& input) {
  // Only images a material's texture reads must hold texels: a loader need not decode the
  // others (a glTF's images for extensions the engine does not read, e.g. transmission).
  std::vector<bool> referenced(input.images.size(), false);
  for (const BakeMaterial& m : input.materials)
    for (const auto& [what, t] : material_textures(m))
      if (t->present()) referenced[static_cast<std::size_t>(t->image)] = true;
  for (std::size_t ii = 0; ii < input.images.size(); ++ii) {
    if (!referenced[ii]) continue;
    const BakeImage& img = input.images[ii];
    const std::string where = "image " + std::to_string(ii) + " '" + (img.uri.empty() ? img.name : img.uri) + "'";
    if (img.width <= 0 || img.height <= 0 || img.width > 65536 || img.height > 65536)
      return input_error(
          where, "size " + std::to_string(img.width) + " x " + std::to_string(img.height) + " is outside 1..65536");
    if (img.rgba8.size() != static_cast<std::size_t>(img.width) * static_cast<std::size_t>(img.height) * 4u)
      return input_error(where, std::to_string(img.rgba8.size()) + " bytes for " + std::to_string(img.width) + " x " +
                                    std::to_string(img.height) + " RGBA8 texels");
  }
  return {};
}

engine::Status check_primitive(const BakeInput& input, const BakePrimitive& p, const std::string& where) {
  if (p.indices.size() % 3 != 0) return input_error(where, "the index count is not a multiple of 3");
  if (!p.normals.empty() && p.normals.size() != p.positions.size())
    return input_error(
        where, std::to_string(p.normals.size()) + " normals for " + std::to_string(p.positions.size()) + " positions");
  for (std::uint32_t i : p.indices)
    if (i >= p.positions.size())
      return input_error(
          where, "index " + std::to_string(i) + " out of range (" + std::to_string(p.positions.size()) + " vertices)");
  for (const glm::vec3& v : p.positions)
    if (!engine::all_finite(v)) return input_error(where, "a position is NaN or infinite");
  for (const glm::vec3& v : p.normals)
    if (!engine::all_finite(v)) return input_error(where, "a normal is NaN or infinite");
  if (p.material >= static_cast<int>(input.materials.size()))
    return input_error(where, "material " + std::to_string(p.material) + " out of range (" +
                                  std::to_string(input.materials.size()) + " materials)");
  for (const auto* uv : {&p.uv0, &p.uv1}) {
    if (!uv->empty() && uv->size() != p.positions.size())
      return input_error(where, std::to_string(uv->size()) + " TEXCOORD_" + (uv == &p.uv0 ? "0" : "1") +
                                    " values for " + std::to_string(p.positions.size()) + " positions");
    for (const glm::vec2& t : *uv)
      if (!engine::all_finite(t)) return input_error(where, "a texture coordinate is NaN or infinite");
  }
  if (p.material >= 0)
    if (const std::string missing = missing_uv_set(input.materials[static_cast<std::size_t>(p.material)], p);
        !missing.empty())
      return input_error(where, missing);
  return {};
}

engine::Status check_meshes(const BakeInput& input) {
  for (std::size_t mi = 0; mi < input.meshes.size(); ++mi) {
    const BakeMesh& mesh = input.meshes[mi];
    for (std::size_t pi = 0; pi < mesh.primitives.size(); ++pi) {
      const std::string where = "mesh " + std::to_string(mi) + " '" + mesh.name + "' primitive " + std::to_string(pi);
      if (auto ok = check_primitive(input, mesh.primitives[pi], where); !ok) return ok;
    }
  }
  return {};
}

engine::Status check_instances(const BakeInput& input) {
  for (std::size_t ii = 0; ii < input.instances.size(); ++ii) {
    const BakeInstance& inst = input.instances[ii];
    const std::string where = "instance " + std::to_string(ii) + " '" + inst.name + "'";
    if (inst.mesh >= input.meshes.size())
      return input_error(where, "mesh " + std::to_string(inst.mesh) + " out of range (" +
                                    std::to_string(input.meshes.size()) + " meshes)");
    if (inst.material_override >= static_cast<int>(input.materials.size()))
      return input_error(where, "material override " + std::to_string(inst.material_override) + " out of range");
    if (!engine::all_finite(inst.object_to_world)) return input_error(where, "the transform is NaN or infinite");
    const float det = glm::determinant(glm::mat3(inst.object_to_world));
    if (!std::isfinite(det) || std::fabs(det) < 1e-18f) return input_error(where, "the transform is not invertible");
  }
  return {};
}

engine::Status check_lights_and_environment(const BakeInput& input) {
  for (std::size_t li = 0; li < input.lights.size(); ++li) {
    const BakeLight& l = input.lights[li];
    const std::string where = "light " + std::to_string(li) + " '" + l.name + "'";
    if (!engine::all_finite(l.light_to_world) || !engine::all_finite(l.light.color) ||
        !std::isfinite(l.light.intensity) || !std::isfinite(l.light.range_m) ||
        !std::isfinite(l.light.inner_cone_rad) || !std::isfinite(l.light.outer_cone_rad) ||
        !std::isfinite(l.light.area_size_m.x) || !std::isfinite(l.light.area_size_m.y))
      return input_error(where, "a value is NaN or infinite");
    if (l.light.intensity < 0.0f || glm::any(glm::lessThan(l.light.color, glm::vec3(0.0f))))
      return input_error(where, "colour and intensity must be >= 0");
  }
  if (!engine::all_finite(input.environment.sky_radiance) ||
      glm::any(glm::lessThan(input.environment.sky_radiance, glm::vec3(0.0f))))
    return input_error("environment", "the sky radiance must be finite and >= 0");
  for (const glm::vec3& g : {input.environment.sky_gradient.zenith, input.environment.sky_gradient.horizon,
                             input.environment.sky_gradient.ground})
    if (!engine::all_finite(g) || glm::any(glm::lessThan(g, glm::vec3(0.0f))))
      return input_error("environment", "the sky gradient's zenith, horizon and ground must be finite and >= 0");
  return {};
}

}  // namespace

engine::Status validate_bake_input(const BakeInput& input) {
  for (engine::Status (*check)(const BakeInput&) :
       {check_materials, check_images, check_meshes, check_instances, check_lights_and_environment})
    if (auto ok = check(input); !ok) return ok;
  return {};
}

}  // namespace gi
