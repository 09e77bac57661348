#include <engine/scene.h>

#include <algorithm>
#include <numeric>
#include <unordered_map>
#include <utility>
#include <vector>

namespace engine {

Scene instantiate(SceneAsset assets) {
  Scene scene;
  scene.assets = std::move(assets);
  Registry& reg = scene.registry;
  const std::vector<Node>& nodes = scene.assets.nodes;
  scene.node_entities.resize(nodes.size());
  // Entities in the file's node order (nodes not from a file after those, in their order),
  // so the camera of the lowest entity index is the file's first (find_camera).
  std::vector<std::size_t> creation(nodes.size());
  std::iota(creation.begin(), creation.end(), std::size_t{0});
  const auto file_order = [&](std::size_t i) {
    const bool from_file = nodes[i].file_index >= 0;
    return std::pair(!from_file, from_file ? static_cast<std::size_t>(nodes[i].file_index) : i);
  };
  std::stable_sort(creation.begin(), creation.end(),
                   [&](std::size_t a, std::size_t b) { return file_order(a) < file_order(b); });
  for (std::size_t i : creation) scene.node_entities[i] = reg.create();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const Node& n = nodes[i];
    const Entity e = scene.node_entities[i];
    reg.emplace<Name>(e, Name{n.name});
    Transform t;
    t.position = n.translation;
    t.rotation = n.rotation;
    t.scale = n.scale;
    if (n.parent >= 0) {
      GI_EXPECTS(static_cast<std::size_t>(n.parent) < nodes.size(), "node parent out of range");
      t.parent = scene.node_entities[static_cast<std::size_t>(n.parent)];
    }
    reg.emplace<Transform>(e, t);
    if (n.mesh >= 0) {
      reg.emplace<MeshRenderer>(e, MeshRenderer{static_cast<std::uint32_t>(n.mesh), -1, true});
      if (n.gi.mobility == Mobility::Dynamic) {
        reg.emplace<DynamicTag>(e);
        reg.emplace<RigidBody>(e);
      } else {
        reg.emplace<StaticTag>(e);
      }
    }
    if (n.light >= 0) reg.emplace<Light>(e, scene.assets.lights[static_cast<std::size_t>(n.light)].light);
    if (n.camera >= 0) reg.emplace<Camera>(e, scene.assets.cameras[static_cast<std::size_t>(n.camera)].camera);
  }
  update_world_transforms(reg);
  return scene;
}

namespace {

// World matrix of e, computing parents first; `done` memoizes this frame's results.
const glm::mat4& world_of(Registry& reg, Entity e, std::unordered_map<Entity, glm::mat4>& done, int depth) {
  if (auto it = done.find(e); it != done.end()) return it->second;
  GI_EXPECTS(depth < 4096, "transform hierarchy too deep or cyclic");
  const Transform& t = reg.get<Transform>(e);
  glm::mat4 m = t.local_matrix();
  if (t.parent && reg.valid(t.parent) && reg.has<Transform>(t.parent)) m = world_of(reg, t.parent, done, depth + 1) * m;
  return done.emplace(e, m).first->second;
}

bool ancestor_changed(const Registry& reg, Entity e) {
  for (int depth = 0; e && depth < 4096; ++depth) {
    const Transform* t = reg.try_get<Transform>(e);
    if (!t) return false;
    if (reg.changed<Transform>(e)) return true;
    e = t->parent;
  }
  return false;
}

}  // namespace

void update_world_transforms(Registry& reg) {
  std::unordered_map<Entity, glm::mat4> done;
  for (Entity e : reg.view<Transform>().entities()) {
    const bool missing = !reg.has<WorldTransform>(e);
    if (!missing && !ancestor_changed(reg, e)) continue;
    const glm::mat4& m = world_of(reg, e, done, 0);
    if (missing) {
      reg.emplace<WorldTransform>(e, WorldTransform{m});
    } else if (reg.get<WorldTransform>(e).matrix != m) {
      reg.write<WorldTransform>(e).matrix = m;
    }
  }
}

Entity find_camera(const Registry& registry) {
  Entity first;
  for (Entity e : registry.entities_with<Camera>())
    if (!first || e.index < first.index) first = e;
  return first;
}

Entity find_by_name(const Registry& registry, std::string_view name) {
  for (Entity e : registry.entities_with<Name>())
    if (registry.get<Name>(e).value == name) return e;
  return kNullEntity;
}

}  // namespace engine
