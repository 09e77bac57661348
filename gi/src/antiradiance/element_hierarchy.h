#pragma once
// The elements of an antiradiance solve (Dachsbacher et al. 2007, §3.1-3.2, §4.1): patches of
// the deforming region's surfaces and of the static surfaces near it, in one hierarchy laid
// out depth-first. Leaves are triangle pieces (a triangle halved at its longest edge until
// the edge is at most patch_size_m, or near_patch_size_m near the deforming instances:
// adaptive leaves, issue 37); above a triangle's pieces, a median-split cluster tree
// over triangles (no normal: "clustering ... we do not need a normal"). The root's children
// are one subtree per group: group 0 is the static surfaces, group g >= 1 the deforming
// instance deforming_instances[g - 1], so a moved instance is one contiguous node range.
//   gi::ElementHierarchy h = gi::build_element_hierarchy(input, settings).value();
//   h.set_instance_transform(0, door_matrix);   // moves group 1's elements

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <gi/bake_input.h>

#include "antiradiance/antiradiance_settings.h"

namespace gi {

struct ElementNode {
  glm::vec3 center{0.0f};  ///< World space (m).
  float radius_m = 0.0f;   ///< Bounding sphere radius around center.
  glm::vec3 normal{0.0f};  ///< Unit normal of a surface element (a triangle or its pieces); 0 for clusters.
  float area_m2 = 0.0f;    ///< Surface area below this node.
  glm::vec3 albedo{0.0f};  ///< Leaves: diffuse hemispherical albedo of the material (glTF BRDF).
  std::int32_t parent = -1;
  std::int32_t first_child = 0;  ///< Into ElementHierarchy::children.
  std::int32_t child_count = 0;
  std::int32_t leaf_begin = 0;  ///< Leaves below: [leaf_begin, leaf_end) in leaf order.
  std::int32_t leaf_end = 0;
  std::int32_t group = 0;  ///< 0: static surfaces; g >= 1: deforming instance g - 1.
  std::int32_t end = 0;    ///< One past the last node of this subtree (depth-first).
};

struct ElementHierarchy {
  std::vector<ElementNode> nodes;      ///< Depth-first pre-order; node 0 is the root.
  std::vector<std::int32_t> children;  ///< Child node indices, referenced by first_child/child_count.
  std::vector<std::int32_t> leaves;    ///< Leaf order -> node index (subtrees are contiguous).
  std::vector<std::int32_t>
      group_root;  ///< Node index of each group's subtree (group 0: static; may be -1 when empty).
  /// BakeInput instance index of each deforming group (group g -> deforming_instances[g - 1]).
  std::vector<std::uint32_t> deforming_instances;
  /// Per node: BakeInput instance it came from (clusters: -1 unless inside a deforming group).
  std::vector<std::int32_t> node_instance;
  /// Object-space centre, normal, radius and area of every node of a deforming group (world
  /// values of static nodes are fixed), and the matrix each group is placed with now.
  std::vector<glm::vec3> object_center, object_normal;
  std::vector<float> object_radius, object_area;
  std::vector<glm::mat4> group_transform;  ///< [g - 1].
  /// The triangle of every surface node (a triangle piece), 3 corners per node (zeros for a
  /// cluster), world space now and object space: what precise near links sample
  /// (settings.near_link_samples). Filled by build_element_hierarchy; empty in a hierarchy
  /// loaded from a bundle (not stored: a precise link then samples a disc of the piece's area).
  std::vector<glm::vec3> corners, object_corners;

  std::size_t leaf_count() const { return leaves.size(); }
  int group_count() const { return static_cast<int>(group_root.size()); }
  bool is_leaf(std::size_t node) const { return nodes[node].child_count == 0; }

  /// Places deforming group g (>= 1) with `object_to_world` (rigid, or uniformly scaled):
  /// recomputes the world centre, normal, radius and area of its nodes.
  void set_group_transform(int group, const glm::mat4& object_to_world);
};

/// Builds the elements from `input`: every triangle of the deforming instances, and every
/// triangle of the Static, non-deforming instances whose bounds come within
/// settings.exchange_radius_m of the deforming instances' swept bounds (a sphere around each
/// instance origin through its farthest vertex: any rotation about the origin stays inside).
/// Pieces of the deforming instances, and static pieces whose bounding sphere comes within
/// settings.near_radius_m of a swept sphere, are split to settings.near_patch_size_m when that
/// is set (> 0) and finer than patch_size_m.
/// Degenerate triangles are skipped. Errors: no deforming instance, invalid input, no
/// triangle, patch_size_m not positive, near_patch_size_m or near_radius_m negative.
engine::Result<ElementHierarchy> build_element_hierarchy(const BakeInput& input, const AntiradianceSettings& settings);

}  // namespace gi
