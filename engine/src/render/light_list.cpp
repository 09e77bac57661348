#include "render/light_list.h"

#include <engine/runtime_limits.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/gtc/matrix_transform.hpp>

#include <engine/components.h>

namespace engine::render {

namespace {

constexpr float kAreaShadowFov = glm::radians(150.0f);

glm::vec3 any_perpendicular_up(const glm::vec3& dir) {
  return std::abs(dir.y) < 0.99f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
}

// Distance from p to the farthest corner of the bounds (at least 1 mm).
float farthest_corner(const glm::vec3& p, const SceneBounds& b) {
  float d = 1e-3f;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z);
    d = std::max(d, glm::length(c - p));
  }
  return d;
}

}  // namespace

SceneBounds item_bounds(const GpuMesh& mesh, const glm::mat4& model) {
  SceneBounds b;
  for (int i = 0; i < 8; ++i) {
    const glm::vec3& lo = mesh.bounds_min;
    const glm::vec3& hi = mesh.bounds_max;
    const glm::vec3 c((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
    const glm::vec3 w = glm::vec3(model * glm::vec4(c, 1.0f));
    b.min = b.empty ? w : glm::min(b.min, w);
    b.max = b.empty ? w : glm::max(b.max, w);
    b.empty = false;
  }
  return b;
}

SceneBounds scene_bounds(const std::vector<DrawItem>& items) {
  SceneBounds b;
  for (const DrawItem& item : items) {
    b.min = b.empty ? item.bounds.min : glm::min(b.min, item.bounds.min);
    b.max = b.empty ? item.bounds.max : glm::max(b.max, item.bounds.max);
    b.empty = false;
  }
  return b;
}

namespace {

// A light's GpuLight record without shadows (position, direction, radiance, cone, rectangle).
GpuLight gpu_light_of(const Light& light, const glm::mat4& m) {
  const glm::vec3 position(m[3]);
  const glm::vec3 axis_x = glm::normalize(glm::vec3(m[0]));
  const glm::vec3 axis_y = glm::normalize(glm::vec3(m[1]));
  const glm::vec3 dir = -glm::normalize(glm::vec3(m[2]));  // lights emit along local -Z
  GpuLight g;
  g.position_type = glm::vec4(position, 0.0f);
  g.direction_range = glm::vec4(dir, light.range_m);
  g.radiant = glm::vec4(light.color * light.intensity, 0.0f);
  g.flags.x = light.moves ? 0.0f : 1.0f;
  if (light.type == LightType::Directional && light.angular_radius_rad > 0.0f)  // the sun's disc
    g.radiant.w = std::tan(std::min(light.angular_radius_rad, 0.7853982f));
  g.cone = glm::vec4(std::cos(light.outer_cone_rad), std::cos(std::min(light.inner_cone_rad, light.outer_cone_rad)),
                     -1.0f, -1.0f);
  switch (light.type) {
    case LightType::Point:
      g.position_type.w = static_cast<float>(GpuLightType::Point);
      break;
    case LightType::Spot:
      g.position_type.w = static_cast<float>(GpuLightType::Spot);
      break;
    case LightType::Directional:
      g.position_type.w = static_cast<float>(GpuLightType::Directional);
      break;
    case LightType::Area:
      g.position_type.w = static_cast<float>(GpuLightType::Area);
      g.area_half_x = glm::vec4(axis_x * (0.5f * light.area_size_m.x), 0.0f);
      g.area_half_y = glm::vec4(axis_y * (0.5f * light.area_size_m.y), 0.0f);
      break;
  }
  return g;
}

// Six 90 degree faces from `position` into the next slice of the cube-map array; its index.
int add_cube_views(LightList& out, const glm::vec3& position, float far_m) {
  const float near_m = std::max(0.01f, far_m * 1e-4f);
  const glm::mat4 proj = glm::perspective(glm::radians(90.0f), 1.0f, near_m, far_m);
  // GL cube-map face order and orientation (+X, -X, +Y, -Y, +Z, -Z).
  const glm::vec3 face_dir[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const glm::vec3 face_up[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  for (int f = 0; f < 6; ++f) {
    ShadowView v;
    v.view_proj = proj * glm::lookAt(position, position + face_dir[f], face_up[f]);
    v.eye = position;
    v.far_m = far_m;
    v.cube = true;
    v.layer = out.cubes * 6 + f;
    out.shadow_views.push_back(v);
  }
  return out.cubes++;
}

// A point light's cube map, reaching its range or the farthest corner of the scene.
void plan_point_shadow(LightList& out, GpuLight& g, const Light& light, const SceneBounds& bounds,
                       const ShadowCapacity& capacity) {
  const glm::vec3 position(g.position_type);
  const float far_m = (light.range_m > 0.0f ? light.range_m : farthest_corner(position, bounds)) * 1.01f;
  g.cone.w = static_cast<float>(add_cube_views(out, position, far_m));
  g.shadow_eye = glm::vec4(position, far_m);
  g.shadow_params = glm::vec4(1.0f, 2.0f / static_cast<float>(capacity.cube_size), 0.0f, 0.0f);
}

// Orthographic along the light, its window fitted to the scene bounds' corners as the light
// sees them (a level longer than it is wide gets its texels along its length), the depth
// range to the bounding sphere.
void plan_sun_shadow(LightList& out, GpuLight& g, const SceneBounds& bounds, const ShadowCapacity& capacity) {
  const glm::vec3 dir(g.direction_range);
  ShadowView v;
  v.axis = dir;
  v.sun = true;
  v.ortho = true;
  v.layer = out.sun_layers;
  const glm::vec3 centre = 0.5f * (bounds.min + bounds.max);
  const float radius = std::max(0.5f * glm::length(bounds.max - bounds.min), 1e-3f) * 1.01f;
  v.eye = centre - dir * radius;
  v.far_m = 2.0f * radius;
  const glm::mat4 view = glm::lookAt(v.eye, centre, any_perpendicular_up(dir));
  glm::vec2 lo(std::numeric_limits<float>::max()), hi(std::numeric_limits<float>::lowest());
  for (int i = 0; i < 8; ++i) {
    const glm::vec3 c((i & 1) ? bounds.max.x : bounds.min.x, (i & 2) ? bounds.max.y : bounds.min.y,
                      (i & 4) ? bounds.max.z : bounds.min.z);
    const glm::vec2 q(view * glm::vec4(c, 1.0f));
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  const glm::vec2 margin = glm::max(0.005f * (hi - lo), glm::vec2(1e-3f));
  lo -= margin;
  hi += margin;
  v.view_proj = glm::ortho(lo.x, hi.x, lo.y, hi.y, 0.0f, v.far_m) * view;
  out.shadow_views.push_back(v);
  g.cone.z = static_cast<float>(out.sun_layers++);
  g.shadow_view_proj = v.view_proj;
  g.shadow_eye = glm::vec4(v.eye, v.far_m);
  // The larger of the two texel sides: what the normal offset and the bias must clear.
  const glm::vec2 texel = (hi - lo) / static_cast<float>(capacity.sun_size);
  g.shadow_params = glm::vec4(0.0f, std::max(texel.x, texel.y), 0.0f, 0.0f);
}

// A spot light's map (its cone) or an area light's (kAreaShadowFov from the rectangle's
// centre), in the 2-D array.
void plan_perspective_shadow(LightList& out, GpuLight& g, const Light& light, const SceneBounds& bounds,
                             const ShadowCapacity& capacity) {
  const glm::vec3 position(g.position_type);
  const glm::vec3 dir(g.direction_range);
  ShadowView v;
  v.axis = dir;
  v.layer = out.layers_2d;
  const float fov = light.type == LightType::Spot
                        ? std::min(2.0f * light.outer_cone_rad + glm::radians(4.0f), glm::radians(170.0f))
                        : kAreaShadowFov;
  const float reach =
      light.type == LightType::Spot && light.range_m > 0.0f ? light.range_m : farthest_corner(position, bounds);
  v.eye = position;
  v.far_m = reach * 1.01f;
  const float near_m = std::max(0.01f, v.far_m * 1e-4f);
  v.view_proj =
      glm::perspective(fov, 1.0f, near_m, v.far_m) * glm::lookAt(position, position + dir, any_perpendicular_up(dir));
  const float texel = 2.0f * std::tan(0.5f * fov) / static_cast<float>(capacity.map_size);
  out.shadow_views.push_back(v);
  g.cone.z = static_cast<float>(out.layers_2d++);
  g.shadow_view_proj = v.view_proj;
  g.shadow_eye = glm::vec4(v.eye, v.far_m);
  g.shadow_params = glm::vec4(1.0f, texel, 0.0f, 0.0f);
}

// Sorted by type (point, spot, directional, area): the forward shader loops over each type
// with a compile-time count. Each area light gets its channel in the half-resolution
// visibility (area_shadow.frag.glsl): its order among the frame's area lights.
void add_sorted(LightList& out, std::vector<std::pair<GpuLight, Entity>>& collected) {
  std::stable_sort(collected.begin(), collected.end(),
                   [](const auto& a, const auto& b) { return a.first.position_type.w < b.first.position_type.w; });
  int area_index = 0;
  for (auto& [g, e] : collected) {
    if (static_cast<int>(g.position_type.w) == static_cast<int>(GpuLightType::Area))
      g.shadow_params.z = static_cast<float>(area_index++);
    out.lights.push_back(g);
    out.entities.push_back(e);
  }
  for (const GpuLight& g : out.lights) ++out.count_by_type[static_cast<std::size_t>(g.position_type.w)];
}

}  // namespace

LightList collect_lights(const Registry& registry, const SceneBounds& bounds, const ShadowCapacity& capacity,
                         std::vector<std::pair<Entity, const char*>>* skipped) {
  LightList out;
  std::vector<std::pair<GpuLight, Entity>> collected;
  int point_cubes = 0, area_cubes = 0;
  registry.view<Light, WorldTransform>().each([&](Entity e, const Light& light, const WorldTransform& wt) {
    if (!light.enabled) return;
    if (const char* why = unusable_light(light, wt.matrix)) {
      if (skipped) skipped->emplace_back(e, why);
      return;
    }
    GpuLight g = gpu_light_of(light, wt.matrix);
    const bool shadowed = light.cast_shadows && !bounds.empty;
    if (shadowed && light.type == LightType::Point && point_cubes < capacity.max_cubes) {
      ++point_cubes;
      plan_point_shadow(out, g, light, bounds, capacity);
    } else if (shadowed && light.type == LightType::Directional && out.sun_layers < capacity.max_sun_layers) {
      plan_sun_shadow(out, g, bounds, capacity);
    } else if (shadowed && light.type != LightType::Point && light.type != LightType::Directional &&
               out.layers_2d < capacity.max_2d_layers) {
      plan_perspective_shadow(out, g, light, bounds, capacity);
      // The 2-D map covers kAreaShadowFov; the rectangle lights its whole front half-space.
      // Beyond the map (the grazing band, 75-90 degrees off its normal) the shadow is looked up
      // in a cube map from the rectangle's centre (shadow_common.glsl's shadow_area_grazing).
      if (light.type == LightType::Area && area_cubes < capacity.max_area_cubes) {
        ++area_cubes;
        g.cone.w = static_cast<float>(add_cube_views(out, glm::vec3(g.position_type), g.shadow_eye.w));
        g.shadow_params.w = 2.0f / static_cast<float>(capacity.cube_size);
      }
    }
    collected.emplace_back(g, e);
  });
  add_sorted(out, collected);
  return out;
}

}  // namespace engine::render
