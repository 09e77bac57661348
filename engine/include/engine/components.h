#pragma once
// The engine's components: plain structs, no behaviour beyond small derived helpers.
//   reg.emplace<engine::Transform>(e, engine::Transform{.position = {1, 0, 0}});
//   reg.emplace<engine::Light>(e, engine::Light{.type = engine::LightType::Point, .intensity = 5.0f});

#include <cstdint>
#include <string>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <engine/entity.h>

namespace engine {

/// Human-readable name (from the glTF node name).
struct Name {
  std::string value;
};

/// Local transform relative to `parent` (null: relative to the world). Metres.
struct Transform {
  glm::vec3 position{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
  Entity parent{};

  glm::mat4 local_matrix() const;
};

/// World matrix, derived from Transform and the parent chain by update_world_transforms().
/// Written only when the value changes, so changed<WorldTransform>() means "moved".
struct WorldTransform {
  glm::mat4 matrix{1.0f};
};

/// Draws mesh `mesh` of the scene's assets. Each primitive uses its own material unless
/// `material_override` >= 0.
struct MeshRenderer {
  std::uint32_t mesh = 0;
  std::int32_t material_override = -1;
  bool cast_shadows = true;
};

enum class LightType : std::uint8_t { Point, Spot, Directional, Area };

/// A light. It emits along its local -Z axis (spot, directional, area), as in glTF.
/// Units (engine/units.h): Point/Spot intensity in W/sr, Directional in W/m^2, Area in
/// W/(m^2 sr) radiance. `color` is linear RGB and multiplies `intensity`.
struct Light {
  LightType type = LightType::Point;
  glm::vec3 color{1.0f};
  float intensity = 1.0f;
  /// Range of influence in metres for point/spot lights; 0 means unlimited.
  float range_m = 0.0f;
  /// Spot cone angles (radians), measured from the axis; inner <= outer <= pi/2.
  float inner_cone_rad = 0.0f;
  float outer_cone_rad = 0.7853982f;
  /// Area light rectangle size in metres (local X by local Y).
  glm::vec2 area_size_m{1.0f, 1.0f};
  /// Directional: angular radius (radians) of the source's disc, e.g. the sun's 0.0047;
  /// 0: a single direction (hard shadows). The bakers sample the disc (soft shadows); the
  /// renderer widens its shadow filter by it (docs/scene-format.md). `intensity` stays the
  /// irradiance of a surface facing the disc's centre.
  float angular_radius_rad = 0.0f;
  /// The light moves or changes at runtime (flashlight, scripted lamp): GI must not bake it.
  bool moves = false;
  bool cast_shadows = true;
  /// Switched off lights contribute nothing (the flashlight toggle).
  bool enabled = true;
};

/// A perspective camera looking along its local -Z axis.
struct Camera {
  float yfov_rad = 0.8f;
  float znear_m = 0.05f;
  float zfar_m = 500.0f;
  /// Width / height; 0 means "use the viewport's".
  float aspect = 0.0f;
};

/// The entity never moves: its lighting may be baked.
struct StaticTag {};
/// The entity may move (rigid): it gets per-frame indirect light.
struct DynamicTag {};

/// Simple rigid-body state for gameplay (no rotation dynamics): integrated by the
/// gameplay systems with a fixed timestep.
struct RigidBody {
  glm::vec3 velocity_m_s{0.0f};
  float mass_kg = 1.0f;
  /// Fraction of velocity lost per second (friction-like damping), 0..1.
  float linear_damping = 0.0f;
  /// Half extents of the axis-aligned collision box in the entity's local frame.
  glm::vec3 half_extents_m{0.5f};
};

}  // namespace engine
