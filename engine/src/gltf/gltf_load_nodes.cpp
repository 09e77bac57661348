// The node hierarchy of the glTF loader (glTF 2.0 §3.5): the chosen scene's trees, in
// parent-before-child order, with TRS transforms (a node matrix is decomposed), mesh /
// camera / light references and the "gi" extras.

#include <engine/finite.h>

#include <cmath>
#include <glm/gtx/matrix_decompose.hpp>

#include "gltf/gltf_load_internal.h"

namespace engine::gltf_load {
namespace {

/// Reads `count` numbers as floats; not an array of numbers -> Error; non-finite -> Error.
Result<std::vector<float>> numbers(const Context& ctx, const Json& value, std::size_t count, const std::string& where,
                                   const char* name) {
  if (!value.is_array() || value.size() != count) {
    return ctx.error(where, std::string("'") + name + "' must be an array of " + std::to_string(count) + " numbers");
  }
  std::vector<float> out;
  for (const Json& v : value) {
    if (!v.is_number()) return ctx.error(where, std::string("'") + name + "' must hold numbers");
    const float f = static_cast<float>(v.get<double>());
    if (!std::isfinite(f)) return ctx.error(where, std::string("'") + name + "' is not finite (NaN or Inf) as a float");
    out.push_back(f);
  }
  return out;
}

Result<int> optional_index(const Context& ctx, const Json& node, const char* key, std::size_t size,
                           const std::string& where) {
  const Json* v = find_member(node, key);
  if (v == nullptr) return -1;
  if (!(v->is_number_integer() || v->is_number_unsigned()) || v->get<std::int64_t>() < 0 ||
      static_cast<std::uint64_t>(v->get<std::int64_t>()) >= size) {
    return ctx.error(where,
                     std::string("'") + key + "' refers to a missing " + key + " (" + std::to_string(size) + " exist)");
  }
  return v->get<int>();
}

/// §3.5.2: a node has either `matrix` or TRS; the matrix must decompose into TRS.
Status read_transform(const Context& ctx, const Json& src, const std::string& where, Node& node) {
  const Json* matrix = find_member(src, "matrix");
  const Json* t = find_member(src, "translation");
  const Json* r = find_member(src, "rotation");
  const Json* s = find_member(src, "scale");
  if (matrix != nullptr) {
    if (t != nullptr || r != nullptr || s != nullptr) return ctx.error(where, "has both 'matrix' and TRS properties");
    auto m = numbers(ctx, *matrix, 16, where, "matrix");
    if (!m) return m.error();
    glm::mat4 mat(1.0f);
    for (int c = 0; c < 4; ++c) {
      for (int row = 0; row < 4; ++row) mat[c][row] = (*m)[static_cast<std::size_t>(c * 4 + row)];  // column-major
    }
    if (std::abs(mat[0][3]) > 1e-5f || std::abs(mat[1][3]) > 1e-5f || std::abs(mat[2][3]) > 1e-5f ||
        std::abs(mat[3][3] - 1.0f) > 1e-5f) {
      return ctx.error(where, "'matrix' has a projective last row (must be 0 0 0 1)");
    }
    glm::vec3 skew;
    glm::vec4 perspective;
    if (!glm::decompose(mat, node.scale, node.rotation, node.translation, skew, perspective) ||
        !engine::all_finite(node.scale) || !engine::all_finite(node.translation) ||
        !engine::all_finite(node.rotation)) {
      return ctx.error(where, "'matrix' is degenerate: its decomposition is not finite (NaN or Inf)");
    }
    node.rotation = glm::normalize(node.rotation);
    return {};
  }
  if (t != nullptr) {
    auto v = numbers(ctx, *t, 3, where, "translation");
    if (!v) return v.error();
    node.translation = {(*v)[0], (*v)[1], (*v)[2]};
  }
  if (r != nullptr) {
    auto v = numbers(ctx, *r, 4, where, "rotation");
    if (!v) return v.error();
    const glm::quat q((*v)[3], (*v)[0], (*v)[1], (*v)[2]);  // glTF stores x, y, z, w
    const float len = glm::length(q);
    // §5.25: rotation is a unit quaternion. Rounding error is renormalized; anything
    // further off is ambiguous (normalize? scale?) and rejected.
    if (!std::isfinite(len) || std::abs(len - 1.0f) > 1e-2f) {
      return ctx.error(where, "'rotation' is not a unit quaternion (length " + std::to_string(len) + ")");
    }
    node.rotation = q / len;
  }
  if (s != nullptr) {
    auto v = numbers(ctx, *s, 3, where, "scale");
    if (!v) return v.error();
    node.scale = {(*v)[0], (*v)[1], (*v)[2]};
  }
  return {};
}

struct FileNode {
  Node node;
  std::vector<int> children;
  int punctual_light = -1;
  GiExtras gi;
};

// One file node's fields, and its children recorded in `parent` (one parent each, no self).
Status read_file_node(const Context& ctx, const Json& src, std::size_t i, std::size_t n, std::size_t meshes,
                      const std::vector<int>& camera_map, std::size_t punctual_lights, FileNode& fn,
                      std::vector<int>& parent) {
  const std::string where = "node " + std::to_string(i);
  if (const Json* name = find_member(src, "name"); name != nullptr && name->is_string()) {
    fn.node.name = name->get<std::string>();
  }
  auto mesh = optional_index(ctx, src, "mesh", meshes, where);
  if (!mesh) return mesh.error();
  fn.node.mesh = *mesh;
  auto camera = optional_index(ctx, src, "camera", camera_map.size(), where);
  if (!camera) return camera.error();
  fn.node.camera = *camera >= 0 ? camera_map[static_cast<std::size_t>(*camera)] : -1;
  if (const Json* exts = find_member(src, "extensions")) {
    if (const Json* lp = find_member(*exts, "KHR_lights_punctual")) {
      auto light = optional_index(ctx, *lp, "light", punctual_lights, where + " KHR_lights_punctual");
      if (!light) return light.error();
      if (*light < 0) return ctx.error(where + " KHR_lights_punctual", "'light' is required");
      fn.punctual_light = *light;
    }
  }
  if (auto ok = read_transform(ctx, src, where, fn.node); !ok) return ok.error();
  auto gi = parse_gi_extras(ctx, src, where);
  if (!gi) return gi.error();
  fn.gi = std::move(gi.value());
  fn.node.gi.mobility = fn.gi.mobility;
  fn.node.gi.region = fn.gi.region;
  if (fn.gi.area_light && fn.punctual_light >= 0) {
    return ctx.error(where, "has both a KHR_lights_punctual light and a gi area_light");
  }
  if (const Json* children = find_member(src, "children")) {
    if (!children->is_array()) return ctx.error(where, "'children' must be an array");
    for (const Json& c : *children) {
      if (!(c.is_number_integer() || c.is_number_unsigned()) || c.get<std::int64_t>() < 0 ||
          static_cast<std::uint64_t>(c.get<std::int64_t>()) >= n) {
        return ctx.error(where, "'children' refers to a missing node");
      }
      const int child = c.get<int>();
      // §3.5.3: nodes form disjoint strict trees: one parent at most, no cycles.
      if (parent[static_cast<std::size_t>(child)] != -1 || child == static_cast<int>(i)) {
        return ctx.error("node " + std::to_string(child),
                         child == static_cast<int>(i)
                             ? "is its own child (cycle)"
                             : "has two parents (nodes " + std::to_string(parent[static_cast<std::size_t>(child)]) +
                                   " and " + std::to_string(i) + ")");
      }
      parent[static_cast<std::size_t>(child)] = static_cast<int>(i);
      fn.children.push_back(child);
    }
  }
  return {};
}

// With at most one parent each, a node not reachable from a root lies on a cycle.
Status check_no_cycles(const Context& ctx, const std::vector<FileNode>& nodes, const std::vector<int>& roots) {
  std::vector<bool> reached(nodes.size(), false);
  std::vector<int> stack(roots.begin(), roots.end());
  while (!stack.empty()) {
    const int v = stack.back();
    stack.pop_back();
    reached[static_cast<std::size_t>(v)] = true;
    for (int c : nodes[static_cast<std::size_t>(v)].children) stack.push_back(c);
  }
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    if (!reached[i]) return ctx.error("node " + std::to_string(i), "is part of a cycle in the node hierarchy");
  }
  return {};
}

// The root nodes scene `scene_index` lists (each a root, once).
Result<std::vector<int>> listed_roots(const Context& ctx, const Json& scene, int scene_index,
                                      const std::vector<int>& parent) {
  const std::size_t n = parent.size();
  const std::string where = "scene " + std::to_string(scene_index);
  std::vector<int> scene_roots;
  const Json* list = find_member(scene, "nodes");
  if (list != nullptr && !list->is_array()) return ctx.error(where, "'nodes' must be an array");
  std::vector<bool> seen(n, false);
  for (const Json& v : list != nullptr ? *list : Json::array()) {
    if (!(v.is_number_integer() || v.is_number_unsigned()) || v.get<std::int64_t>() < 0 ||
        static_cast<std::uint64_t>(v.get<std::int64_t>()) >= n) {
      return ctx.error(where, "'nodes' refers to a missing node");
    }
    const int r = v.get<int>();
    if (parent[static_cast<std::size_t>(r)] != -1) {
      return ctx.error(where, "lists node " + std::to_string(r) + ", which is a child of node " +
                                  std::to_string(parent[static_cast<std::size_t>(r)]));
    }
    if (seen[static_cast<std::size_t>(r)]) return ctx.error(where, "lists node " + std::to_string(r) + " twice");
    seen[static_cast<std::size_t>(r)] = true;
    scene_roots.push_back(r);
  }
  return scene_roots;
}

// The scene's nodes depth-first, pre-order (every parent before its children), with their
// lights: a KHR light shared by several nodes moves if any of them says so; a gi area light
// is added to scene.lights.
void write_nodes(std::vector<FileNode>& nodes, const std::vector<int>& scene_roots, SceneAsset& scene) {
  std::vector<std::pair<int, int>> stack;  // (file node, output parent)
  for (auto it = scene_roots.rbegin(); it != scene_roots.rend(); ++it) stack.emplace_back(*it, -1);
  while (!stack.empty()) {
    const auto [index, out_parent] = stack.back();
    stack.pop_back();
    FileNode& fn = nodes[static_cast<std::size_t>(index)];
    Node node = fn.node;
    node.parent = out_parent;
    node.file_index = index;
    const bool moves = fn.gi.light_moves.value_or(false);
    if (fn.punctual_light >= 0) {
      node.light = fn.punctual_light;
      if (moves) scene.lights[static_cast<std::size_t>(fn.punctual_light)].light.moves = true;
    } else if (fn.gi.area_light) {
      NamedLight area = *fn.gi.area_light;
      area.light.moves = moves;
      node.light = static_cast<int>(scene.lights.size());
      scene.lights.push_back(std::move(area));
    }
    const int out_index = static_cast<int>(scene.nodes.size());
    scene.nodes.push_back(std::move(node));
    for (auto c = fn.children.rbegin(); c != fn.children.rend(); ++c) stack.emplace_back(*c, out_index);
  }
}

}  // namespace

Status convert_nodes(const Context& ctx, const ParsedFile& file, const std::vector<int>& camera_map,
                     SceneAsset& scene) {
  const Json* json_nodes = find_member(file.doc, "nodes");
  const std::size_t n = json_nodes != nullptr ? json_nodes->size() : 0;
  const std::size_t punctual_lights = scene.lights.size();  // only KHR lights so far
  std::vector<FileNode> nodes(n);
  std::vector<int> parent(n, -1);
  for (std::size_t i = 0; i < n; ++i)
    if (Status s = read_file_node(ctx, (*json_nodes)[i], i, n, scene.meshes.size(), camera_map, punctual_lights,
                                  nodes[i], parent);
        !s)
      return s.error();
  std::vector<int> roots;
  for (std::size_t i = 0; i < n; ++i) {
    if (parent[i] == -1) roots.push_back(static_cast<int>(i));
  }
  if (Status s = check_no_cycles(ctx, nodes, roots); !s) return s.error();

  // The scene: `scene`, else scene 0, else every root node (§3.5.1).
  std::vector<int> scene_roots = roots;
  const Json* scenes = find_member(file.doc, "scenes");
  const std::size_t scene_count = scenes != nullptr ? scenes->size() : 0;
  auto chosen = optional_index(ctx, file.doc, "scene", scene_count, "root");
  if (!chosen) return chosen.error();
  int scene_index = *chosen >= 0 ? *chosen : (scene_count > 0 ? 0 : -1);
  if (scene_index >= 0) {
    auto listed = listed_roots(ctx, (*scenes)[static_cast<std::size_t>(scene_index)], scene_index, parent);
    if (!listed) return listed.error();
    scene_roots = std::move(listed).value();
  }
  write_nodes(nodes, scene_roots, scene);
  // The scene's environment (sky, sun), after the nodes: the sun's node comes last.
  if (scene_index >= 0)
    return parse_scene_environment(ctx, (*scenes)[static_cast<std::size_t>(scene_index)],
                                   "scene " + std::to_string(scene_index), scene);
  return {};
}

}  // namespace engine::gltf_load
