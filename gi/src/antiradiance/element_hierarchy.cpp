#include "antiradiance/element_hierarchy.h"

#include <engine/check.h>
#include <engine/gltf_brdf.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>

#include <glm/gtc/constants.hpp>

#include "raytrace/material_lookup.h"
#include "raytrace/scene_adapter.h"

namespace gi {

namespace {

struct SourceTriangle {
  glm::vec3 p[3];  // world
  glm::vec3 q[3];  // object space (deforming groups) or world (static)
  glm::vec3 albedo;
  std::int32_t instance;
  std::int32_t group;
  glm::vec3 centroid;
};

// The sphere a deforming instance's vertices stay in under any rotation about its origin.
struct SweptSphere {
  glm::vec3 center{0.0f};
  float radius_m = 0.0f;
};

// Adaptive leaf sizes: near_patch within near_radius of a swept sphere (and on the deforming
// instances themselves), patch elsewhere.
struct LeafSizing {
  float patch = 0.5f;
  float near_patch = 0.0f;  // 0: off
  float near_radius = 0.0f;
  std::vector<SweptSphere> swept;

  // The largest longest-edge of a piece with this bounding sphere in this group.
  float limit(std::int32_t group, const glm::vec3& center, float radius) const {
    if (!(near_patch > 0.0f) || near_patch >= patch) return patch;
    if (group >= 1) return near_patch;
    for (const SweptSphere& s : swept)
      if (glm::length(center - s.center) - radius - s.radius_m <= near_radius) return near_patch;
    return patch;
  }
};

struct Builder {
  ElementHierarchy& h;
  const LeafSizing& sizing;

  std::int32_t new_node(std::int32_t parent, std::int32_t group, std::int32_t instance) {
    ElementNode n;
    n.parent = parent;
    n.group = group;
    h.nodes.push_back(n);
    h.node_instance.push_back(instance);
    h.object_center.emplace_back(0.0f);
    h.object_normal.emplace_back(0.0f);
    h.object_radius.push_back(0.0f);
    h.object_area.push_back(0.0f);
    h.corners.insert(h.corners.end(), 3, glm::vec3(0.0f));
    h.object_corners.insert(h.object_corners.end(), 3, glm::vec3(0.0f));
    return static_cast<std::int32_t>(h.nodes.size() - 1);
  }

  // A triangle piece (world a,b,c; object oa,ob,oc): split at the longest edge's midpoint
  // until that edge is at most the sizing's limit there. Children are recorded in a per-node list first
  // (depth-first: a node's children are emitted after it, each with its whole subtree).
  std::int32_t emit_triangle(std::int32_t parent, const SourceTriangle& t, const glm::vec3 (&w)[3],
                             const glm::vec3 (&o)[3]) {
    const std::int32_t id = new_node(parent, t.group, t.instance);
    const glm::vec3 cw = (w[0] + w[1] + w[2]) / 3.0f;
    const glm::vec3 co = (o[0] + o[1] + o[2]) / 3.0f;
    const glm::vec3 cross_w = glm::cross(w[1] - w[0], w[2] - w[0]);
    const glm::vec3 cross_o = glm::cross(o[1] - o[0], o[2] - o[0]);
    ElementNode& n = h.nodes[static_cast<std::size_t>(id)];
    n.center = cw;
    n.normal = glm::normalize(cross_w);
    n.area_m2 = 0.5f * glm::length(cross_w);
    n.radius_m = std::max({glm::length(w[0] - cw), glm::length(w[1] - cw), glm::length(w[2] - cw)});
    n.albedo = t.albedo;
    h.object_center[static_cast<std::size_t>(id)] = co;
    h.object_normal[static_cast<std::size_t>(id)] = glm::normalize(cross_o);
    h.object_area[static_cast<std::size_t>(id)] = 0.5f * glm::length(cross_o);
    h.object_radius[static_cast<std::size_t>(id)] =
        std::max({glm::length(o[0] - co), glm::length(o[1] - co), glm::length(o[2] - co)});
    for (std::size_t k = 0; k < 3; ++k) {
      h.corners[3 * static_cast<std::size_t>(id) + k] = w[k];
      h.object_corners[3 * static_cast<std::size_t>(id) + k] = o[k];
    }
    // Longest edge (world lengths decide; object space follows the same split).
    int e = 0;
    float longest = -1.0f;
    for (int k = 0; k < 3; ++k) {
      const float len = glm::length(w[(k + 1) % 3] - w[k]);
      if (len > longest) {
        longest = len;
        e = k;
      }
    }
    if (longest <= sizing.limit(t.group, cw, n.radius_m)) {
      n.leaf_begin = static_cast<std::int32_t>(h.leaves.size());
      h.leaves.push_back(id);
      n.leaf_end = n.leaf_begin + 1;
      n.end = id + 1;
      return id;
    }
    const int a = e, b = (e + 1) % 3, c = (e + 2) % 3;
    const glm::vec3 mw = 0.5f * (w[a] + w[b]), mo = 0.5f * (o[a] + o[b]);
    const glm::vec3 w0[3] = {w[a], mw, w[c]}, o0[3] = {o[a], mo, o[c]};
    const glm::vec3 w1[3] = {mw, w[b], w[c]}, o1[3] = {mo, o[b], o[c]};
    const std::int32_t leaf_begin = static_cast<std::int32_t>(h.leaves.size());
    std::vector<std::int32_t> kids;
    kids.push_back(emit_triangle(id, t, w0, o0));
    kids.push_back(emit_triangle(id, t, w1, o1));
    finish(id, kids, leaf_begin);
    return id;
  }

  void finish(std::int32_t id, const std::vector<std::int32_t>& kids, std::int32_t leaf_begin) {
    ElementNode& n = h.nodes[static_cast<std::size_t>(id)];
    n.first_child = static_cast<std::int32_t>(h.children.size());
    n.child_count = static_cast<std::int32_t>(kids.size());
    h.children.insert(h.children.end(), kids.begin(), kids.end());
    n.leaf_begin = leaf_begin;
    n.leaf_end = static_cast<std::int32_t>(h.leaves.size());
    n.end = static_cast<std::int32_t>(h.nodes.size());
  }

  // Median split over triangles [first, last) along the longest axis of their centroids.
  std::int32_t emit_cluster(std::int32_t parent, std::vector<SourceTriangle>& tris, std::size_t first, std::size_t last,
                            std::int32_t group) {
    if (last - first == 1) {
      const SourceTriangle& t = tris[first];
      return emit_triangle(parent, t, t.p, t.q);
    }
    const std::int32_t id = new_node(parent, group, -1);
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (std::size_t i = first; i < last; ++i) {
      lo = glm::min(lo, tris[i].centroid);
      hi = glm::max(hi, tris[i].centroid);
    }
    const glm::vec3 ext = hi - lo;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : ext.y >= ext.z ? 1 : 2;
    const std::size_t mid = first + (last - first) / 2;
    std::nth_element(tris.begin() + static_cast<std::ptrdiff_t>(first), tris.begin() + static_cast<std::ptrdiff_t>(mid),
                     tris.begin() + static_cast<std::ptrdiff_t>(last),
                     [axis](const SourceTriangle& x, const SourceTriangle& y) {
                       if (x.centroid[axis] != y.centroid[axis]) return x.centroid[axis] < y.centroid[axis];
                       // A total order so the result does not depend on the library's algorithm.
                       for (int k = 0; k < 3; ++k)
                         if (x.centroid[k] != y.centroid[k]) return x.centroid[k] < y.centroid[k];
                       return x.instance < y.instance;
                     });
    const std::int32_t leaf_begin = static_cast<std::int32_t>(h.leaves.size());
    std::vector<std::int32_t> kids;
    kids.push_back(emit_cluster(id, tris, first, mid, group));
    kids.push_back(emit_cluster(id, tris, mid, last, group));
    finish(id, kids, leaf_begin);
    return id;
  }
};

// Bounding spheres, areas of clusters from their children (children before parents: reverse
// depth-first order). `object`: the object-space copies (deforming groups) too.
void refit_clusters(ElementHierarchy& h, std::int32_t begin, std::int32_t end, bool object) {
  for (std::int32_t i = end - 1; i >= begin; --i) {
    ElementNode& n = h.nodes[static_cast<std::size_t>(i)];
    if (n.child_count == 0) continue;
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    float area = 0.0f;
    for (std::int32_t c = 0; c < n.child_count; ++c) {
      const ElementNode& k = h.nodes[static_cast<std::size_t>(h.children[static_cast<std::size_t>(n.first_child + c)])];
      lo = glm::min(lo, k.center - glm::vec3(k.radius_m));
      hi = glm::max(hi, k.center + glm::vec3(k.radius_m));
      area += k.area_m2;
    }
    const bool surface = n.normal != glm::vec3(0.0f);
    if (!surface) n.center = 0.5f * (lo + hi);
    float r = 0.0f;
    for (std::int32_t c = 0; c < n.child_count; ++c) {
      const ElementNode& k = h.nodes[static_cast<std::size_t>(h.children[static_cast<std::size_t>(n.first_child + c)])];
      r = std::max(r, glm::length(k.center - n.center) + k.radius_m);
    }
    if (!surface) {
      n.radius_m = r;
      n.area_m2 = area;
    }
    if (object && !surface) {
      h.object_center[static_cast<std::size_t>(i)] = n.center;
      h.object_radius[static_cast<std::size_t>(i)] = n.radius_m;
      h.object_area[static_cast<std::size_t>(i)] = n.area_m2;
    }
  }
}

engine::Error build_error(std::string message) {
  return engine::Error{"", "antiradiance elements", std::move(message)};
}

// The deforming instances into h (their indices and transforms), with the bounds they sweep
// about their origins widened by the exchange radius.
void find_deforming(const BakeInput& input, const AntiradianceSettings& settings, ElementHierarchy& h, glm::vec3& lo,
                    glm::vec3& hi, std::vector<SweptSphere>& swept) {
  lo = glm::vec3(std::numeric_limits<float>::max());
  hi = glm::vec3(-std::numeric_limits<float>::max());
  for (std::size_t i = 0; i < input.instances.size(); ++i) {
    const BakeInstance& inst = input.instances[i];
    if (!inst.deforming) continue;
    h.deforming_instances.push_back(static_cast<std::uint32_t>(i));
    h.group_transform.push_back(inst.object_to_world);
    float reach = 0.0f;
    for (const BakePrimitive& p : input.meshes[inst.mesh].primitives)
      for (const glm::vec3& v : p.positions)
        reach = std::max(reach, glm::length(glm::vec3(inst.object_to_world * glm::vec4(v, 1.0f)) -
                                            glm::vec3(inst.object_to_world[3])));
    const glm::vec3 origin(inst.object_to_world[3]);
    swept.push_back({origin, reach});
    lo = glm::min(lo, origin - glm::vec3(reach));
    hi = glm::max(hi, origin + glm::vec3(reach));
  }
  lo -= glm::vec3(settings.exchange_radius_m);
  hi += glm::vec3(settings.exchange_radius_m);
}

// The source triangles per group (0: the static ones within lo..hi; g >= 1: deforming
// instance g - 1's, with their object-space corners). Textured materials: each source
// triangle folds in its texture's mean (material_lookup.h).
std::vector<std::vector<SourceTriangle>> source_triangles(const BakeInput& input, int groups, const glm::vec3& lo,
                                                          const glm::vec3& hi) {
  std::vector<std::vector<SourceTriangle>> by_group(static_cast<std::size_t>(groups));
  std::int32_t deforming_index = 0;
  const bool any_textured =
      std::any_of(input.materials.begin(), input.materials.end(), [](const BakeMaterial& m) { return m.textured(); });
  const ReferenceScene looks = any_textured ? material_scene_from(input) : ReferenceScene{};
  for (std::size_t i = 0; i < input.instances.size(); ++i) {
    const BakeInstance& inst = input.instances[i];
    std::int32_t group = 0;
    if (inst.deforming)
      group = ++deforming_index;
    else if (inst.mobility != BakeMobility::Static)
      continue;
    const glm::mat4& m = inst.object_to_world;
    for (const BakePrimitive& prim : input.meshes[inst.mesh].primitives) {
      const BakeMaterial mat = bake_material(input, inst, prim);
      const glm::vec3 albedo = glm::clamp(engine::gltf_hemispherical_albedo(reference_material(mat).brdf).sum(),
                                          glm::vec3(0.0f), glm::vec3(1.0f));
      for (std::size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
        SourceTriangle s{};
        for (int k = 0; k < 3; ++k) {
          const glm::vec3 v = prim.positions[prim.indices[t + static_cast<std::size_t>(k)]];
          s.p[k] = glm::vec3(m * glm::vec4(v, 1.0f));
          s.q[k] = group > 0 ? v : s.p[k];
        }
        const float area = 0.5f * glm::length(glm::cross(s.p[1] - s.p[0], s.p[2] - s.p[0]));
        if (!(area > 1e-10f)) continue;  // degenerate
        s.centroid = (s.p[0] + s.p[1] + s.p[2]) / 3.0f;
        if (group == 0) {
          const glm::vec3 tlo = glm::min(glm::min(s.p[0], s.p[1]), s.p[2]);
          const glm::vec3 thi = glm::max(glm::max(s.p[0], s.p[1]), s.p[2]);
          if (glm::any(glm::lessThan(thi, lo)) || glm::any(glm::greaterThan(tlo, hi))) continue;
        }
        s.albedo = albedo;
        if (mat.textured())
          s.albedo = glm::clamp(triangle_albedo(looks, lookup_triangle(input, inst, prim, t / 3, s.p)), glm::vec3(0.0f),
                                glm::vec3(1.0f));
        s.instance = static_cast<std::int32_t>(i);
        s.group = group;
        by_group[static_cast<std::size_t>(group)].push_back(s);
      }
    }
  }
  return by_group;
}

// The tree over the groups' clusters under one root, refit; the deforming groups' clusters
// refit once in object space too.
void assemble_tree(ElementHierarchy& h, std::vector<std::vector<SourceTriangle>>& by_group, const LeafSizing& sizing) {
  const int groups = static_cast<int>(by_group.size());
  Builder b{h, sizing};
  const std::int32_t root = b.new_node(-1, -1, -1);
  std::vector<std::int32_t> kids;
  h.group_root.assign(static_cast<std::size_t>(groups), -1);
  for (int g = 0; g < groups; ++g) {
    auto& tris = by_group[static_cast<std::size_t>(g)];
    if (tris.empty()) continue;
    const std::int32_t r = b.emit_cluster(root, tris, 0, tris.size(), g);
    h.group_root[static_cast<std::size_t>(g)] = r;
    kids.push_back(r);
  }
  b.finish(root, kids, 0);
  refit_clusters(h, 0, static_cast<std::int32_t>(h.nodes.size()), false);
  // Object-space copies of the deforming groups' clusters: refit them in object space once.
  for (int g = 1; g < groups; ++g) {
    const std::int32_t r = h.group_root[static_cast<std::size_t>(g)];
    std::vector<ElementNode> saved(h.nodes.begin() + r, h.nodes.begin() + h.nodes[static_cast<std::size_t>(r)].end);
    for (std::int32_t i = r; i < h.nodes[static_cast<std::size_t>(r)].end; ++i) {
      ElementNode& n = h.nodes[static_cast<std::size_t>(i)];
      if (n.normal != glm::vec3(0.0f)) {
        n.center = h.object_center[static_cast<std::size_t>(i)];
        n.radius_m = h.object_radius[static_cast<std::size_t>(i)];
        n.area_m2 = h.object_area[static_cast<std::size_t>(i)];
      }
    }
    refit_clusters(h, r, h.nodes[static_cast<std::size_t>(r)].end, true);
    std::copy(saved.begin(), saved.end(), h.nodes.begin() + r);
  }
  h.nodes[0].group = -1;
}

}  // namespace

engine::Result<ElementHierarchy> build_element_hierarchy(const BakeInput& input, const AntiradianceSettings& settings) {
  if (engine::Status st = validate_bake_input(input); !st) return st.error();
  if (!(settings.patch_size_m > 0.0f) || !std::isfinite(settings.patch_size_m))
    return build_error("patch_size_m must be positive");
  if (!(settings.exchange_radius_m >= 0.0f)) return build_error("exchange_radius_m must not be negative");
  if (!(settings.near_patch_size_m >= 0.0f) || !std::isfinite(settings.near_patch_size_m))
    return build_error("near_patch_size_m must not be negative");
  if (!(settings.near_radius_m >= 0.0f)) return build_error("near_radius_m must not be negative");

  ElementHierarchy h;
  // The deforming region's swept bounds.
  glm::vec3 lo, hi;
  LeafSizing sizing{settings.patch_size_m, settings.near_patch_size_m, settings.near_radius_m, {}};
  find_deforming(input, settings, h, lo, hi, sizing.swept);
  if (h.deforming_instances.empty()) return build_error("no instance is flagged deforming");

  const int groups = 1 + static_cast<int>(h.deforming_instances.size());
  std::vector<std::vector<SourceTriangle>> by_group = source_triangles(input, groups, lo, hi);
  for (int g = 1; g < groups; ++g)
    if (by_group[static_cast<std::size_t>(g)].empty())
      return build_error("deforming instance '" +
                         input.instances[h.deforming_instances[static_cast<std::size_t>(g - 1)]].name +
                         "' has no triangle");
  assemble_tree(h, by_group, sizing);
  return h;
}

void ElementHierarchy::set_group_transform(int group, const glm::mat4& m) {
  GI_EXPECTS(group >= 1 && group < group_count(), "set_group_transform: not a deforming group");
  group_transform[static_cast<std::size_t>(group - 1)] = m;
  const std::int32_t r = group_root[static_cast<std::size_t>(group)];
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(glm::mat3(m)));
  const float scale =
      std::max({glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
  for (std::int32_t i = r; i < nodes[static_cast<std::size_t>(r)].end; ++i) {
    const auto k = static_cast<std::size_t>(i);
    ElementNode& n = nodes[k];
    n.center = glm::vec3(m * glm::vec4(object_center[k], 1.0f));
    if (object_normal[k] != glm::vec3(0.0f)) n.normal = glm::normalize(normal_matrix * object_normal[k]);
    n.radius_m = object_radius[k] * scale;
    n.area_m2 = object_area[k] * scale * scale;
    if (corners.size() == 3 * nodes.size() && object_corners.size() == corners.size())
      for (std::size_t c = 3 * k; c < 3 * k + 3; ++c) corners[c] = glm::vec3(m * glm::vec4(object_corners[c], 1.0f));
  }
  // The root's sphere and area cover all groups.
  refit_clusters(*this, 0, 1, false);
}

}  // namespace gi
