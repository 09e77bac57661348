#pragma once
// Every uniform the renderer sets, by program, as locations looked up by name once when the
// program links (render/uniform_lookup.h): the GLSL declares names only, so C++ and GLSL agree
// by construction, and a name one side renames aborts at link time naming the uniform.
//   auto forward = link_program<ForwardUniforms>(builder, {{ShaderStage::Vertex, "forward.vert.glsl"}, ...});
//   forward->use(); glUniformMatrix4fv(forward->uniforms.view_proj, 1, GL_FALSE, m);

#include <initializer_list>
#include <string_view>
#include <utility>
#include <vector>

#include <engine/gpu/shader_program.h>

#include "render/uniform_lookup.h"

namespace engine::render {

/// material_common.glsl: a material's texturing and alpha (set_material_texturing, bind_alpha_test).
struct MaterialUniforms {
  int alpha_mode = -1;     ///< int: 0 OPAQUE, 1 MASK, 2 BLEND
  int alpha_cutoff = -1;   ///< float: fragments with alpha below it are discarded (MASK)
  int texcoord_sets = -1;  ///< ivec4: each texture slot's TEXCOORD set (0 or 1)
  int uv_transforms = -1;  ///< vec4[8]: each slot's KHR_texture_transform, two rows of a 2x3 matrix
  int base_alpha = -1;     ///< float: baseColorFactor.a (alpha-tested depth passes)
  static MaterialUniforms locate(const UniformLookup& at);
};

/// forward.vert.glsl + forward.frag.glsl: the shading pass.
struct ForwardUniforms {
  int model = -1, normal_matrix = -1, view_proj = -1;
  int mesh_first_vertex = -1, use_vertex_irradiance = -1;
  int camera_position = -1;
  int lobe_terms = -1, lobe_resolution = -1, lobe_first = -1, lobe_stride = -1;
  int base_color = -1, metallic = -1, roughness = -1, emissive = -1;
  int indirect_mode = -1, ambient_radiance = -1, split_x = -1, use_glossy = -1, double_sided = -1;
  int specular_factor = -1, specular_color_factor = -1;
  int directional_bins = -1, directional_elements = -1, directional_tangent_frame = -1;
  int probe_count = -1, probe_levels = -1, probe_max_roughness = -1, probe_has_distances = -1, probe_lobe_samples = -1,
      probe_lobe_samples_max = -1;  ///< reflection_probes.glsl
  int sky_radiance = -1, sky_gradient = -1, sky_visibility_pos = -1, sky_visibility_neg = -1;
  int baked_direct = -1;
  int normal_scale = -1;  ///< float: normalTexture.scale
  int normal_map = -1;    ///< int: 1 when the material has a normal texture
  MaterialUniforms material;
  static ForwardUniforms locate(const UniformLookup& at);
};

/// forward.vert.glsl + area_shadow.frag.glsl: the half-resolution area shadow passes.
struct AreaShadowUniforms {
  int model = -1, normal_matrix = -1, view_proj = -1;
  int mesh_first_vertex = -1, use_vertex_irradiance = -1;
  int camera_position = -1, lobe_terms = -1, double_sided = -1;
  static AreaShadowUniforms locate(const UniformLookup& at);
};

/// shadow.vert.glsl + depth_only, depth_reach or shadow.frag.glsl (with ALPHA_TEST or not):
/// the depth passes. The groups a fragment stage does not declare stay -1 (ignored by GL).
struct DepthUniforms {
  int model = -1, view_proj = -1;
  int eye = -1, far_m = -1, ortho = -1, axis = -1;              ///< shadow.frag.glsl
  int reach_origin = -1, reach_inv_voxel = -1, reach_all = -1;  ///< depth_reach.frag.glsl
  MaterialUniforms material;                                    ///< material_common.glsl
  static DepthUniforms locate(const UniformLookup& at);
};

/// fullscreen.vert.glsl + tonemap.frag.glsl.
struct TonemapUniforms {
  int exposure = -1, metered = -1;
  static TonemapUniforms locate(const UniformLookup& at);
};

/// exposure_histogram.comp.glsl.
struct ExposureHistogramUniforms {
  int size = -1;
  static ExposureHistogramUniforms locate(const UniformLookup& at);
};

/// exposure_adapt.comp.glsl.
struct ExposureAdaptUniforms {
  int dt_s = -1, snap = -1, percentiles = -1, ev100_range = -1, compensation_ev = -1, rates_per_s = -1;
  static ExposureAdaptUniforms locate(const UniformLookup& at);
};

/// A linked program with its uniforms' locations (move-only, as ShaderProgram).
template <class Uniforms>
struct LocatedProgram {
  ShaderProgram program;
  Uniforms uniforms;
  void use() const { program.use(); }
};

/// Adds `stages` to `builder`, builds, and looks Uniforms' names up in the linked program.
template <class Uniforms>
Result<LocatedProgram<Uniforms>> link_program(ShaderProgramBuilder builder,
                                              std::initializer_list<std::pair<ShaderStage, std::string_view>> stages) {
  std::vector<std::string_view> files;
  for (const auto& [stage, file] : stages) {
    builder.stage(stage, file);
    files.push_back(file);
  }
  Result<ShaderProgram> program = builder.build();
  if (!program) return program.error();
  LocatedProgram<Uniforms> out{std::move(program).value(), {}};
  out.uniforms = Uniforms::locate(UniformLookup(out.program, builder, files));
  return Result<LocatedProgram<Uniforms>>(std::move(out));
}

}  // namespace engine::render
