#include <game_demo/collision_world.h>

#include <algorithm>
#include <cmath>

#include <engine/components.h>

namespace game_demo {

namespace {

// Projects the triangle (already relative to the box centre) and the box onto `axis`;
// true when the projections are disjoint (a separating axis).
bool separated_on(const glm::vec3& axis, const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2,
                  const glm::vec3& half) {
  const float len2 = glm::dot(axis, axis);
  if (len2 < 1e-20f) return false;  // degenerate axis (parallel edges): not a separator
  const float p0 = glm::dot(axis, v0), p1 = glm::dot(axis, v1), p2 = glm::dot(axis, v2);
  const float r = half.x * std::abs(axis.x) + half.y * std::abs(axis.y) + half.z * std::abs(axis.z);
  const float lo = std::min({p0, p1, p2}), hi = std::max({p0, p1, p2});
  // Touching counts as separated, matching Aabb::overlaps (interiors only).
  return lo >= r || hi <= -r;
}

}  // namespace

bool triangle_overlaps_box(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const Aabb& box) {
  const glm::vec3 center = box.center();
  const glm::vec3 half = 0.5f * (box.max - box.min);
  const glm::vec3 v0 = a - center, v1 = b - center, v2 = c - center;
  const glm::vec3 edges[3] = {v1 - v0, v2 - v1, v0 - v2};
  const glm::vec3 box_axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (const glm::vec3& u : box_axes)
    if (separated_on(u, v0, v1, v2, half)) return false;
  const glm::vec3 normal = glm::cross(edges[0], edges[1]);
  if (glm::dot(normal, normal) > 1e-20f) {
    const float d = glm::dot(normal, v0);
    const float r = half.x * std::abs(normal.x) + half.y * std::abs(normal.y) + half.z * std::abs(normal.z);
    if (std::abs(d) >= r) return false;
  }
  for (const glm::vec3& u : box_axes)
    for (const glm::vec3& e : edges)
      if (separated_on(glm::cross(u, e), v0, v1, v2, half)) return false;
  return true;
}

void CollisionWorld::add_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
  const Aabb tb{glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c))};
  bounds_.min = glm::min(bounds_.min, tb.min);
  bounds_.max = glm::max(bounds_.max, tb.max);
  const glm::vec3 n = glm::cross(b - a, c - a);
  const float len = glm::length(n);
  if (!(len > 1e-12f)) return;  // degenerate (or NaN): no wall
  (std::abs(n.y / len) >= 0.7f ? floors_ : walls_).push_back(Triangle{a, b, c, tb});
}

CollisionWorld CollisionWorld::build(const engine::Scene& scene) {
  CollisionWorld world;
  const engine::Registry& reg = scene.registry;
  for (engine::Entity e : reg.view<engine::MeshRenderer, engine::StaticTag, engine::WorldTransform>().entities()) {
    const std::uint32_t mesh = reg.get<engine::MeshRenderer>(e).mesh;
    if (mesh >= scene.assets.meshes.size()) continue;
    const glm::mat4& m = reg.get<engine::WorldTransform>(e).matrix;
    for (const engine::Primitive& p : scene.assets.meshes[mesh].primitives) {
      auto world_pos = [&](std::uint32_t i) { return glm::vec3(m * glm::vec4(p.positions[i], 1.0f)); };
      const std::size_t n = p.indices.empty() ? p.positions.size() : p.indices.size();
      for (std::size_t t = 0; t + 2 < n; t += 3) {
        std::uint32_t i[3];
        for (int k = 0; k < 3; ++k)
          i[k] = p.indices.empty() ? static_cast<std::uint32_t>(t + static_cast<std::size_t>(k))
                                   : p.indices[t + static_cast<std::size_t>(k)];
        if (i[0] >= p.positions.size() || i[1] >= p.positions.size() || i[2] >= p.positions.size()) continue;
        world.add_triangle(world_pos(i[0]), world_pos(i[1]), world_pos(i[2]));
      }
    }
  }
  return world;
}

bool CollisionWorld::overlaps_wall(const Aabb& box) const {
  for (const Triangle& t : walls_)
    if (t.bounds.overlaps(box) && triangle_overlaps_box(t.a, t.b, t.c, box)) return true;
  return false;
}

bool CollisionWorld::blocks_move(const Aabb& from, const Aabb& box) const { return blocks(walls_, from, box); }

bool CollisionWorld::blocks_vertical_move(const Aabb& from, const Aabb& box) const {
  return blocks(floors_, from, box) || blocks(walls_, from, box);
}

bool CollisionWorld::blocks(const std::vector<Triangle>& tris, const Aabb& from, const Aabb& box) {
  for (const Triangle& t : tris) {
    // Broad phase: flat bounds of axis-aligned walls still pass the strict interior test
    // when the box straddles their plane.
    if (!t.bounds.overlaps(box)) continue;
    if (!triangle_overlaps_box(t.a, t.b, t.c, box)) continue;
    if (!triangle_overlaps_box(t.a, t.b, t.c, from)) return true;
  }
  return false;
}

}  // namespace game_demo
