// engine::render::ForwardRenderer's light reach (engine/light_reach.h): the grid of which static
// and moving lights can reach each voxel past the static walls, and the light groups (one per
// stencil mask the depth pre-pass writes) the forward pass shades with.
#include "render/forward_renderer.h"

#include <algorithm>
#include <cstdint>

namespace engine::render {

std::vector<LightGroup> ForwardRenderer::light_groups(const Registry& registry, const std::vector<DrawItem>& items,
                                                      const render::LightList& lights) {
  // Culled by reach: static (not Light::moves), shadowed point, spot and area lights (an
  // unshadowed light shines through walls in this renderer; a directional one reaches
  // everything it is not shadowed from), then moving shadowed point lights (their reach is
  // recomputed on every frame they move; a moving spot, the flashlight, lights what the
  // camera sees and stays on). The first LightReachGrid::kMaxLights of them; bit i of a
  // mask is cullable[i].
  std::vector<int> cullable;
  int n_static = 0;
  // With half-resolution area shadows the stencil's top bit flags their fallback pixels.
  const std::size_t max_cullable = LightReachGrid::kMaxLights - (area_lights_.empty() ? 0 : 1);
  if (settings_.light_reach_culling)
    for (int pass = 0; pass < 2; ++pass) {
      for (std::size_t i = 0; i < lights.lights.size() && cullable.size() < max_cullable; ++i) {
        const render::GpuLight& g = lights.lights[i];
        const Light* l = registry.try_get<Light>(lights.entities[i]);
        const bool shadowed = g.cone.z >= 0.0f || g.cone.w >= 0.0f;
        if (l == nullptr || !shadowed || l->type == LightType::Directional) continue;
        if (pass == 0 ? !l->moves : (l->moves && l->type == LightType::Point)) cullable.push_back(static_cast<int>(i));
      }
      if (pass == 0) n_static = static_cast<int>(cullable.size());
    }
  LightGroup everything;
  everything.lights = lights.lights;
  everything.count_by_type = lights.count_by_type;
  if (cullable.empty()) return {everything};
  update_reach(items, lights, cullable, n_static);
  if (reach_.grid.empty()) return {everything};
  std::vector<LightGroup> groups;
  for (int mask = 0; mask < 256; ++mask) {
    const int bi = reach_.mask_bounds_index[static_cast<std::size_t>(mask)];
    if (bi < 0 && mask != reach_.grid.all) continue;
    LightGroup g;
    g.mask = mask;
    // The all-lights mask also covers everything outside the grid: no bounds.
    if (mask != reach_.grid.all) g.bounds = reach_.bounds[static_cast<std::size_t>(bi)];
    for (std::size_t i = 0; i < lights.lights.size(); ++i) {
      const auto it = std::find(cullable.begin(), cullable.end(), static_cast<int>(i));
      if (it != cullable.end() && (mask & (1 << (it - cullable.begin()))) == 0) continue;
      g.lights.push_back(lights.lights[i]);
      ++g.count_by_type[static_cast<std::size_t>(lights.lights[i].position_type.w)];
    }
    groups.push_back(std::move(g));
  }
  return groups;
}

namespace {

// The cullable lights as the reach grid sees them, static and moving apart, and the keys that
// tell whether either set changed (entity ids and geometry).
struct ReachLights {
  std::vector<float> key, moving_key;
  std::vector<ReachLight> static_lights, moving_lights;
};

ReachLights reach_lights(const render::LightList& lights, const std::vector<int>& cullable, int n_static) {
  ReachLights out;
  for (std::size_t c = 0; c < cullable.size(); ++c) {
    const std::size_t i = static_cast<std::size_t>(cullable[c]);
    const render::GpuLight& g = lights.lights[i];
    ReachLight r;
    r.position = glm::vec3(g.position_type);
    r.direction = glm::vec3(g.direction_range);
    if (static_cast<int>(g.position_type.w) == static_cast<int>(render::GpuLightType::Area)) {
      r.half_x = glm::vec3(g.area_half_x);
      r.half_y = glm::vec3(g.area_half_y);
    }
    const bool is_static = static_cast<int>(c) < n_static;
    (is_static ? out.static_lights : out.moving_lights).push_back(r);
    std::vector<float>& k = is_static ? out.key : out.moving_key;
    k.push_back(static_cast<float>(lights.entities[i].id()));
    for (const glm::vec3& v : {r.position, r.direction, r.half_x, r.half_y}) k.insert(k.end(), {v.x, v.y, v.z});
  }
  return out;
}

}  // namespace

// The static items' extent and, of those in `models`, their opaque triangles as occluders.
void ForwardRenderer::collect_reach_occluders(const std::vector<DrawItem>& items,
                                              const std::map<std::uint32_t, glm::mat4>& models) {
  reach_.occluders.clear();
  reach_.statics = render::SceneBounds{};
  render::SceneBounds& statics = reach_.statics;
  for (const DrawItem& item : items) {
    if (!item.is_static) continue;
    statics.min = statics.empty ? item.bounds.min : glm::min(statics.min, item.bounds.min);
    statics.max = statics.empty ? item.bounds.max : glm::max(statics.max, item.bounds.max);
    statics.empty = false;
    if (!models.contains(item.entity.id())) continue;
    ReachOccluder o;
    o.min = item.bounds.min;
    o.max = item.bounds.max;
    // Triangle corners in primitive order; MASK and BLEND primitives let light through
    // their holes, so they occlude nothing here (the grid stays conservative).
    const std::vector<glm::vec3>& c = item.mesh->triangle_corners;
    std::size_t first = 0;
    for (const render::GpuPrimitive& p : item.mesh->primitives) {
      const std::size_t end = std::min(c.size(), first + p.index_count);
      const bool opaque = !scene_.material(item.material_override >= 0 ? item.material_override : p.material).cut_out();
      for (std::size_t t = first; opaque && t + 2 < end; t += 3)
        o.triangles.push_back({glm::vec3(item.model * glm::vec4(c[t], 1.0f)),
                               glm::vec3(item.model * glm::vec4(c[t + 1], 1.0f)),
                               glm::vec3(item.model * glm::vec4(c[t + 2], 1.0f))});
      first = end;
    }
    reach_.occluders.push_back(std::move(o));
  }
}

// Per mask value of the grid, the box of the voxels holding it (reach_.bounds).
void ForwardRenderer::bound_reach_masks() {
  reach_.mask_bounds_index.assign(256, -1);
  reach_.bounds.clear();
  const LightReachGrid& g = reach_.grid;
  for (int z = 0; z < g.dims.z; ++z)
    for (int y = 0; y < g.dims.y; ++y)
      for (int x = 0; x < g.dims.x; ++x) {
        const std::uint8_t m = g.masks[static_cast<std::size_t>((z * g.dims.y + y) * g.dims.x + x)];
        int& bi = reach_.mask_bounds_index[m];
        if (bi < 0) {
          bi = static_cast<int>(reach_.bounds.size());
          reach_.bounds.emplace_back();
        }
        render::SceneBounds& b = reach_.bounds[static_cast<std::size_t>(bi)];
        const glm::vec3 lo = g.origin + glm::vec3(x, y, z) * g.voxel_m;
        const glm::vec3 hi = lo + glm::vec3(g.voxel_m);
        b.min = b.empty ? lo : glm::min(b.min, lo);
        b.max = b.empty ? hi : glm::max(b.max, hi);
        b.empty = false;
      }
}

// The grid's masks into reach_.texture (remade when the grid's dimensions are not `old_dims`).
void ForwardRenderer::upload_reach_masks(const glm::ivec3& old_dims) {
  const LightReachGrid& g = reach_.grid;
  if (reach_.texture.empty() || old_dims.x != g.dims.x || old_dims.y != g.dims.y || old_dims.z != g.dims.z) {
    reach_.texture = GlTexture::create(GL_TEXTURE_3D);
    glTextureStorage3D(reach_.texture.id(), 1, GL_R8UI, g.dims.x, g.dims.y, g.dims.z);
    glTextureParameteri(reach_.texture.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(reach_.texture.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }
  GLint unpack = 4;
  glGetIntegerv(GL_UNPACK_ALIGNMENT, &unpack);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTextureSubImage3D(reach_.texture.id(), 0, 0, 0, 0, g.dims.x, g.dims.y, g.dims.z, GL_RED_INTEGER, GL_UNSIGNED_BYTE,
                      g.masks.data());
  glPixelStorei(GL_UNPACK_ALIGNMENT, unpack);
}

// Rebuilds the static lights' reach grid when they or the static shadow casters changed
// since the last build. A static item seen at a new transform is never an occluder again
// (a door that swings): the grid stays conservative while it moves, and is not rebuilt for
// it every frame. The moving lights' bits are recomputed whenever one of them moved.
void ForwardRenderer::update_reach(const std::vector<DrawItem>& items, const render::LightList& lights,
                                   const std::vector<int>& cullable, int n_static) {
  ReachLights r = reach_lights(lights, cullable, n_static);
  std::map<std::uint32_t, glm::mat4> models;
  for (const DrawItem& item : items)
    if (item.is_static && item.cast_shadows && !reach_.moved.contains(item.entity.id()))
      models[item.entity.id()] = item.model;
  const bool built = reach_.builds > 0;
  const bool static_changed = !built || r.key != reach_.light_key || models != reach_.static_models;
  if (!static_changed && r.moving_key == reach_.moving_key) return;
  if (static_changed) {
    if (built)
      for (const auto& [id, m] : models) {
        const auto it = reach_.static_models.find(id);
        if (it != reach_.static_models.end() && it->second != m) reach_.moved.insert(id);
      }
    for (std::uint32_t id : reach_.moved) models.erase(id);
    collect_reach_occluders(items, models);
    reach_.light_key = std::move(r.key);
    reach_.static_models = std::move(models);
    ++reach_.builds;
    const render::SceneBounds& statics = reach_.statics;
    reach_.static_grid = statics.empty ? LightReachGrid{}
                                       : build_light_reach_grid(reach_.occluders, r.static_lights, statics.min,
                                                                statics.max, kReachVoxelM);
  }
  reach_.moving_key = std::move(r.moving_key);
  LightReachGrid moving;
  if (!r.moving_lights.empty() && !reach_.statics.empty)
    moving =
        build_light_reach_grid(reach_.occluders, r.moving_lights, reach_.statics.min, reach_.statics.max, kReachVoxelM);
  // Static bits low, moving bits above them (both grids span the same voxels).
  const glm::ivec3 old_dims = reach_.grid.dims;
  reach_.grid = !reach_.static_grid.empty() ? reach_.static_grid : moving;
  if (!reach_.static_grid.empty() && !moving.empty() && moving.dims == reach_.grid.dims)
    for (std::size_t v = 0; v < reach_.grid.masks.size(); ++v)
      reach_.grid.masks[v] = static_cast<std::uint8_t>(reach_.grid.masks[v] | (moving.masks[v] << n_static));
  reach_.grid.all = static_cast<std::uint8_t>((1u << cullable.size()) - 1u);
  if (reach_.grid.empty()) {
    reach_.mask_bounds_index.assign(256, -1);
    reach_.bounds.clear();
    return;
  }
  bound_reach_masks();
  upload_reach_masks(old_dims);
}

}  // namespace engine::render
