#pragma once
// A live scene: its assets (meshes, materials, images) and the entities made from its nodes.
//   engine::Scene scene = engine::instantiate(std::move(asset));
//   engine::update_world_transforms(scene.registry);

#include <vector>

#include <engine/registry.h>
#include <engine/scene_asset.h>

namespace engine {

struct Scene {
  SceneAsset assets;
  Registry registry;
  /// node_entities[i] is the entity made from assets.nodes[i].
  std::vector<Entity> node_entities;
};

/// Creates one entity per node (in Node::file_index order) with Name, Transform (parented as in the file) and
/// WorldTransform, plus MeshRenderer, Light and Camera where the node has them. Mesh nodes
/// are tagged DynamicTag when their gi mobility is Dynamic, StaticTag otherwise; dynamic
/// mesh nodes also get a RigidBody. World transforms are computed before returning.
Scene instantiate(SceneAsset assets);

/// Recomputes WorldTransform of every entity with a Transform whose own or an ancestor's
/// Transform changed this frame (or that has no WorldTransform yet). Writes a
/// WorldTransform only when its value differs, so changed<WorldTransform>() means "moved".
void update_world_transforms(Registry& registry);

/// The entity with a Camera of the lowest index, or null: in an instantiated glTF scene, the
/// camera node that comes first in the file's "nodes" array (Node::file_index).
Entity find_camera(const Registry& registry);

/// The first entity whose Name equals `name`, or null.
Entity find_by_name(const Registry& registry, std::string_view name);

}  // namespace engine
