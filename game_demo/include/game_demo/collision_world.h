#pragma once
// The level's static collision geometry for gameplay: the wall-like triangles of every
// StaticTag mesh in world space (floors and ceilings never block horizontal movement, so
// they are left out) and the bounds of the whole static level.
//   game_demo::CollisionWorld world = game_demo::CollisionWorld::build(scene);
//   if (world.blocks_move(old_box, new_box)) ...

#include <vector>

#include <glm/glm.hpp>

#include <engine/scene.h>

namespace game_demo {

/// Axis-aligned box in world space, metres.
struct Aabb {
  glm::vec3 min{0.0f};
  glm::vec3 max{0.0f};

  /// True when the interiors intersect (touching faces do not count).
  bool overlaps(const Aabb& o) const {
    return min.x < o.max.x && max.x > o.min.x && min.y < o.max.y && max.y > o.min.y && min.z < o.max.z &&
           max.z > o.min.z;
  }
  Aabb shifted(const glm::vec3& d) const { return {min + d, max + d}; }
  glm::vec3 center() const { return 0.5f * (min + max); }
  bool empty() const { return min.x > max.x || min.y > max.y || min.z > max.z; }
};

/// Exact triangle/box overlap (separating-axis test on 13 axes).
bool triangle_overlaps_box(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const Aabb& box);

class CollisionWorld {
 public:
  /// Collects the wall-like triangles (|normal.y| < 0.7) of every StaticTag MeshRenderer
  /// entity, transformed by its WorldTransform. World transforms must be up to date.
  static CollisionWorld build(const engine::Scene& scene);

  /// Adds one triangle (world space); vertical-facing ones still count for the bounds only.
  void add_triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c);

  /// True when `box` overlaps a wall triangle that `from` does not overlap: moving from
  /// `from` to `box` would enter a wall. (Starting inside geometry never traps a mover.)
  bool blocks_move(const Aabb& from, const Aabb& box) const;

  /// Like blocks_move, against floor and ceiling triangles (vertical motion).
  bool blocks_vertical_move(const Aabb& from, const Aabb& box) const;

  /// True when `box` overlaps any wall triangle.
  bool overlaps_wall(const Aabb& box) const;

  /// Bounds of every static triangle (floors included); empty() when there is none.
  const Aabb& level_bounds() const { return bounds_; }
  std::size_t wall_triangle_count() const { return walls_.size(); }

 private:
  struct Triangle {
    glm::vec3 a, b, c;
    Aabb bounds;
  };
  static bool blocks(const std::vector<Triangle>& tris, const Aabb& from, const Aabb& box);
  std::vector<Triangle> walls_;
  std::vector<Triangle> floors_;  ///< Floors and ceilings (|normal.y| >= 0.7).
  Aabb bounds_{glm::vec3(1e30f), glm::vec3(-1e30f)};
};

}  // namespace game_demo
