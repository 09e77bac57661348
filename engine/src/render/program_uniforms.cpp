#include "render/program_uniforms.h"

namespace engine::render {

MaterialUniforms MaterialUniforms::locate(const UniformLookup& at) {
  return {.alpha_mode = at.location("u_alpha_mode"),
          .alpha_cutoff = at.location("u_alpha_cutoff"),
          .texcoord_sets = at.location("u_texcoord_sets"),
          .uv_transforms = at.location("u_uv_transforms"),
          .base_alpha = at.location("u_base_alpha")};
}

ForwardUniforms ForwardUniforms::locate(const UniformLookup& at) {
  return {.model = at.location("u_model"),
          .normal_matrix = at.location("u_normal_matrix"),
          .view_proj = at.location("u_view_proj"),
          .mesh_first_vertex = at.location("u_mesh_first_vertex"),
          .use_vertex_irradiance = at.location("u_use_vertex_irradiance"),
          .camera_position = at.location("u_camera_position"),
          .lobe_terms = at.location("u_lobe_terms"),
          .lobe_resolution = at.location("u_lobe_resolution"),
          .lobe_first = at.location("u_lobe_first"),
          .lobe_stride = at.location("u_lobe_stride"),
          .base_color = at.location("u_base_color"),
          .metallic = at.location("u_metallic"),
          .roughness = at.location("u_roughness"),
          .emissive = at.location("u_emissive"),
          .indirect_mode = at.location("u_indirect_mode"),
          .ambient_radiance = at.location("u_ambient_radiance"),
          .split_x = at.location("u_split_x"),
          .use_glossy = at.location("u_use_glossy"),
          .double_sided = at.location("u_double_sided"),
          .specular_factor = at.location("u_specular_factor"),
          .specular_color_factor = at.location("u_specular_color_factor"),
          .directional_bins = at.location("u_directional_bins"),
          .directional_elements = at.location("u_directional_elements"),
          .directional_tangent_frame = at.location("u_directional_tangent_frame"),
          .probe_count = at.location("u_probe_count"),
          .probe_levels = at.location("u_probe_levels"),
          .probe_max_roughness = at.location("u_probe_max_roughness"),
          .probe_has_distances = at.location("u_probe_has_distances"),
          .probe_lobe_samples = at.location("u_probe_lobe_samples"),
          .probe_lobe_samples_max = at.location("u_probe_lobe_samples_max"),
          .sky_radiance = at.location("u_sky_radiance"),
          .sky_gradient = at.location("u_sky_gradient"),
          .sky_visibility_pos = at.location("u_sky_visibility_pos"),
          .sky_visibility_neg = at.location("u_sky_visibility_neg"),
          .baked_direct = at.location("u_baked_direct"),
          .normal_scale = at.location("u_normal_scale"),
          .normal_map = at.location("u_normal_map"),
          .material = MaterialUniforms::locate(at)};
}

AreaShadowUniforms AreaShadowUniforms::locate(const UniformLookup& at) {
  return {.model = at.location("u_model"),
          .normal_matrix = at.location("u_normal_matrix"),
          .view_proj = at.location("u_view_proj"),
          .mesh_first_vertex = at.location("u_mesh_first_vertex"),
          .use_vertex_irradiance = at.location("u_use_vertex_irradiance"),
          .camera_position = at.location("u_camera_position"),
          .lobe_terms = at.location("u_lobe_terms"),
          .double_sided = at.location("u_double_sided")};
}

DepthUniforms DepthUniforms::locate(const UniformLookup& at) {
  DepthUniforms u;
  u.model = at.location("u_model");
  u.view_proj = at.location("u_view_proj");
  // Each fragment stage's group, whole, when the stage is the one that declares it.
  if (at.declares("u_eye")) {
    u.eye = at.location("u_eye");
    u.far_m = at.location("u_far_m");
    u.ortho = at.location("u_ortho");
    u.axis = at.location("u_axis");
  }
  if (at.declares("u_reach_origin")) {
    u.reach_origin = at.location("u_reach_origin");
    u.reach_inv_voxel = at.location("u_reach_inv_voxel");
    u.reach_all = at.location("u_reach_all");
  }
  if (at.declares("u_alpha_mode")) u.material = MaterialUniforms::locate(at);
  return u;
}

TonemapUniforms TonemapUniforms::locate(const UniformLookup& at) {
  return {.exposure = at.location("u_exposure"), .metered = at.location("u_metered")};
}

ExposureHistogramUniforms ExposureHistogramUniforms::locate(const UniformLookup& at) {
  return {.size = at.location("u_size")};
}

ExposureAdaptUniforms ExposureAdaptUniforms::locate(const UniformLookup& at) {
  return {.dt_s = at.location("u_dt_s"),
          .snap = at.location("u_snap"),
          .percentiles = at.location("u_percentiles"),
          .ev100_range = at.location("u_ev100_range"),
          .compensation_ev = at.location("u_compensation_ev"),
          .rates_per_s = at.location("u_rates_per_s")};
}

}  // namespace engine::render
