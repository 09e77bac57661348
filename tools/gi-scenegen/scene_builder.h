#pragma once
// Helpers that build engine::SceneAsset content from quads, boxes and rooms, in metres,
// y up. Every quad gets a flat normal and planar TEXCOORD_0 in metres (planar_uv), taken
// from the mesh's coordinates so a texture runs on across neighbouring quads (the pieces
// of a wall around a door) at 1 repeat per metre (textures.h).
//   scenegen::SceneBuilder b;  int white = b.material("white", {0.7f, 0.7f, 0.7f});
//   scenegen::MeshBuilder m;   m.box(white, {0, 0.5f, 0}, {0.5f, 0.5f, 0.5f});  b.add_mesh_node("crate", m);

#include <map>
#include <string>
#include <vector>

#include <engine/scene_asset.h>

namespace scenegen {

/// An axis-aligned opening in a wall: [a0, a1] along the wall, [y0, y1] in height.
struct Opening {
  float a0, a1, y0, y1;
};

/// TEXCOORD_0 of point `p` of a quad facing `n`, in metres: floors and ceilings (|n.y| >= 0.7)
/// u = x, v = z; walls u along the wall to the right as seen from the front, v = -y (the
/// image's top row up).
glm::vec2 planar_uv(glm::vec3 p, glm::vec3 n);

/// Collects triangles per material; build() turns them into one engine::Mesh.
class MeshBuilder {
 public:
  /// A planar quad p0,p1,p2,p3 (in order around it). Its front faces `facing_hint`: the
  /// winding is flipped when the computed normal points away from the hint.
  void quad(int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 facing_hint);
  /// The quad split into n x n cells sharing their vertices (n >= 1): per-vertex lighting
  /// (basis radiance fields) needs vertices inside a face, not only at its corners.
  void quad_grid(int material, glm::vec3 p0, glm::vec3 p1, glm::vec3 p2, glm::vec3 p3, glm::vec3 facing_hint, int n);
  /// Closed axis-aligned box; faces point outward (`inward`: faces point inside, for rooms).
  void box(int material, glm::vec3 center, glm::vec3 half_extents, bool inward = false);
  /// Closed outward box whose faces are n x n grids (quad_grid).
  void tessellated_box(int material, glm::vec3 center, glm::vec3 half_extents, int n);
  /// Closed prism from a 4-corner top outline at height y_top down to y_bottom (with a bottom).
  void prism(int material, const glm::vec3 (&top)[4], float y_bottom);
  /// Wall in the plane x = `x`, spanning z in [z0, z1] and y in [y0, y1], facing +x
  /// (`facing` > 0) or -x, with openings (a = z) cut out.
  void wall_x(int material, float x, float z0, float z1, float y0, float y1, float facing,
              std::vector<Opening> openings = {});
  /// Wall in the plane z = `z`, spanning x in [x0, x1], facing +z or -z, openings along x.
  void wall_z(int material, float z, float x0, float x1, float y0, float y1, float facing,
              std::vector<Opening> openings = {});
  /// Horizontal rectangle at height y over [x0,x1] x [z0,z1], facing up (`facing` > 0) or down.
  void horizontal(int material, float y, float x0, float x1, float z0, float z1, float facing);

  engine::Mesh build(std::string name) const;
  std::size_t triangle_count() const;

 private:
  std::map<int, engine::Primitive> by_material_;
};

/// Owns the SceneAsset being built and adds materials and nodes to it.
class SceneBuilder {
 public:
  int material(std::string name, glm::vec3 base_color, float roughness = 1.0f, float metallic = 0.0f,
               glm::vec3 emissive_radiance = glm::vec3(0.0f));
  /// Adds an image for textures; returns its index.
  int image(engine::Image image);
  /// A material whose base colour is the sRGB image `image` (TEXCOORD_0, REPEAT, linear
  /// filtering with mipmaps) times `tint` (linear; 1: the texture's own colours).
  int textured_material(std::string name, int image, float roughness = 1.0f, glm::vec3 tint = glm::vec3(1.0f));
  /// A node drawing `mesh` (added as a new mesh named after the node).
  int add_mesh_node(const std::string& name, const MeshBuilder& mesh, engine::Mobility mobility,
                    glm::vec3 translation = glm::vec3(0.0f), glm::quat rotation = glm::quat(1, 0, 0, 0));
  /// A node drawing an already added mesh.
  int add_instance_node(const std::string& name, int mesh, engine::Mobility mobility, glm::vec3 translation,
                        glm::quat rotation = glm::quat(1, 0, 0, 0));
  int add_light_node(const std::string& name, const engine::Light& light, glm::vec3 translation,
                     glm::quat rotation = glm::quat(1, 0, 0, 0), int parent = -1);
  /// A camera node at `eye` looking at `target` (glTF cameras look along local -Z).
  int add_camera_node(const std::string& name, glm::vec3 eye, glm::vec3 target, float yfov_rad);
  /// An empty node (a pivot for children).
  int add_group_node(const std::string& name, glm::vec3 translation, engine::Mobility mobility);
  int add_mesh(const std::string& name, const MeshBuilder& mesh);
  int add_child_mesh_node(const std::string& name, int mesh, int parent, glm::vec3 translation);

  engine::SceneAsset& asset() { return asset_; }
  engine::SceneAsset take() { return std::move(asset_); }

 private:
  engine::SceneAsset asset_;
};

/// Rotation taking the area light's local -Z (its emission direction) to `direction`
/// (a unit axis vector) and local X to `x_axis`.
glm::quat facing(glm::vec3 direction, glm::vec3 x_axis);

/// Area light of `size_m` emitting `radiance` W/(m^2 sr).
engine::Light area_light(glm::vec2 size_m, glm::vec3 radiance);
/// Point light of intensity `intensity_w_sr` (W/sr per channel times `color`).
engine::Light point_light(float intensity_w_sr, glm::vec3 color = glm::vec3(1.0f), bool moves = false);

}  // namespace scenegen
