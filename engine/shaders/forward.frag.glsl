#version 450 core
// Forward HDR pass: direct light of every enabled light with shadows, emission, and the
// indirect term (provider atlas / per-vertex irradiance / glossy texture, or the constant
// ambient stand-in). Output: linear radiance, W/(m^2 sr).
//
// The light list is sorted by type (point, spot, directional, area) and the count of each
// type is a compile-time constant (one program variant per combination, built on demand):
// llvmpipe executes dynamic loops and branches for all SIMD lanes with masks, so a generic
// per-light switch would run every light type's code for every light.
#ifndef POINT_LIGHTS
#define POINT_LIGHTS 0
#endif
#ifndef SPOT_LIGHTS
#define SPOT_LIGHTS 0
#endif
#ifndef DIRECTIONAL_LIGHTS
#define DIRECTIONAL_LIGHTS 0
#endif
#ifndef AREA_LIGHTS
#define AREA_LIGHTS 0
#endif
// 1: area lights soft-shadowed over their rectangle (shadow_area), 0: from their centre.
#ifndef AREA_SOFT_SHADOWS
#define AREA_SOFT_SHADOWS 1
#endif
// 1: area lights' visibility from the half-resolution pass (area_shadow.frag.glsl, upsampled
// per pixel into u_area_visibility, channel GpuLight::shadow_params.z); 0: shadow_area here.
#ifndef AREA_SHADOW_HALF
#define AREA_SHADOW_HALF 0
#endif
// 0: the scene has no sky (radiance and gradient all zero): its term is zero and left out.
#ifndef SKY_TERM
#define SKY_TERM 1
#endif
// 1: the frame's yardstick (RenderSettings::flat_shading): the base colour, unlit.
#ifndef FLAT_SHADING
#define FLAT_SHADING 0
#endif

#include "lighting_common.glsl"
#include "shadow_common.glsl"
#include "directional_radiance.glsl"
#include "material_common.glsl"
#include "reflection_probes.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;
in vec4 v_tangent;
in vec3 v_vertex_irradiance;
// Per-vertex view-dependent indirect light (forward.vert.glsl, vertex_radiance_lobes): terms > 0: use v_lobe_radiance.
in vec3 v_lobe_radiance;
uniform int u_lobe_terms;

uniform vec3 u_camera_position;
uniform vec4 u_base_color;
uniform float u_metallic;
uniform float u_roughness;
uniform vec3 u_emissive;
// 0: none, 1: constant ambient stand-in, 2: irradiance atlas at TEXCOORD_1, 3: per-vertex irradiance.
uniform int u_indirect_mode;
uniform float u_ambient_radiance;
// Pixels with x < u_split_x get direct light only (SplitView::DirectLeftFullRight); -1: off.
uniform float u_split_x;
uniform int u_use_glossy;
uniform int u_double_sided;
uniform float u_specular_factor;       // KHR_materials_specular
uniform vec3 u_specular_color_factor;  // KHR_materials_specular
// Directional radiance of static surfaces (engine/indirect_light.h): bins and elements, 0: none.
uniform int u_directional_bins;
uniform int u_directional_elements;
// 1: the bins are in the tangent frame of the vertex normal (IndirectLightFrame::directional_tangent_frame).
uniform int u_directional_tangent_frame;
// The scene's sky (RenderSettings::sky_radiance), W/(m^2 sr): unshadowed ambient direct light.
uniform vec3 u_sky_radiance;
// The sky's gradient (RenderSettings::sky_gradient, engine/sky.h): horizon, zenith - horizon,
// ground - horizon.
uniform vec3 u_sky_gradient[3];
// The sky's visibility on this item (IndirectLightFrame::sky_visibility; 1 = unoccluded):
// an ambient cube, +X +Y +Z faces and -X -Y -Z faces.
uniform vec3 u_sky_visibility_pos;
uniform vec3 u_sky_visibility_neg;
// What this item's baked irradiance (u_indirect_mode 2) holds besides indirect light
// (IndirectLightFrame::atlas_holds_*), so it is not drawn twice: bit 0 the sky's direct light
// (no sky term here), bit 1 the direct light of the lights that do not move (GpuLight::flags.x:
// those lights add nothing here).
uniform int u_baked_direct;

// 1 for a light drawn live on this item, 0 for one whose direct light its bake holds.
float live(GpuLight light) { return (u_baked_direct & 2) != 0 ? 1.0 - light.flags.x : 1.0; }

layout(binding = 0) uniform sampler2D u_base_color_texture;
layout(binding = 1) uniform sampler2D u_metallic_roughness_texture;
layout(binding = 2) uniform sampler2D u_emissive_texture;
layout(binding = 3) uniform sampler2D u_irradiance_atlas;
layout(binding = 6) uniform sampler2D u_glossy_radiance;
layout(binding = 7) uniform isampler2D u_directional_index;
layout(binding = 15) uniform sampler2D u_normal_texture;
uniform float u_normal_scale;
uniform int u_normal_map;

#if AREA_SHADOW_HALF
layout(binding = 13) uniform sampler2D u_area_visibility;
#endif

layout(location = 0) out vec4 o_radiance;

// The shading normal: the vertex normal, or with a normal map (u_normal_map) the tangent-space
// normal n_t = (2 tex - 1) x (scale, scale, 1) in the frame (T, B = w cross(N, T), N), T made
// orthogonal to N (glTF 2.0 §3.9.3). Back faces of double-sided materials flip the frame.
vec3 shading_normal() {
  vec3 n = normalize(v_normal);
  const bool flip = u_double_sided != 0 && !gl_FrontFacing;
  if (u_normal_map != 0) {
    vec3 t = v_tangent.xyz - n * dot(n, v_tangent.xyz);
    if (dot(t, t) > 1e-12) {  // zero tangents (a material override's normal map): none
      t = normalize(t);
      const vec3 b = cross(n, t) * (v_tangent.w < 0.0 ? -1.0 : 1.0);
      vec3 tn = texture(u_normal_texture, material_uv(2, v_uv0, v_uv1)).xyz * 2.0 - 1.0;
      tn.xy *= u_normal_scale;
      n = normalize(mat3(t, b, n) * tn);
    }
  }
  return flip ? -n : n;
}

void main() {
  // MASK's cut-out texels never get here: the depth pre-pass discarded them (alpha_test), and
  // this pass shades only where its depth equals the pre-pass's. A discard here would cost
  // llvmpipe its early depth test on every material. OPAQUE ignores alpha; BLEND outputs it.
  vec4 base = u_base_color * texture(u_base_color_texture, material_uv(0, v_uv0, v_uv1));
  const float alpha = u_alpha_mode == 2 ? base.a : 1.0;
#if FLAT_SHADING
  o_radiance = vec4(base.rgb, alpha);
  return;
#endif
  vec4 mr = texture(u_metallic_roughness_texture, material_uv(1, v_uv0, v_uv1));

  Surface s;
  s.position = v_world;
  s.normal = shading_normal();
  s.view = normalize(u_camera_position - v_world);
  s.brdf = gltf_brdf(base.rgb, u_metallic * mr.b, u_roughness * mr.g, u_specular_factor, u_specular_color_factor);

  vec3 radiance = u_emissive * texture(u_emissive_texture, material_uv(3, v_uv0, v_uv1)).rgb;
  // #if guards: llvmpipe runs a loop body at least once (masked) even for zero iterations.
  vec3 to_light;
#if POINT_LIGHTS > 0
  for (int i = 0; i < POINT_LIGHTS; ++i)
    radiance += live(lights[i]) * point_light_radiance(lights[i], s, to_light) *
                shadow_cube(lights[i], s.position, s.normal, to_light);
#endif
#if SPOT_LIGHTS > 0
  for (int k = 0; k < SPOT_LIGHTS; ++k) {
    const int i = POINT_LIGHTS + k;
    radiance += live(lights[i]) * spot_light_radiance(lights[i], s, to_light) *
                shadow_2d_point(lights[i], s.position, s.normal, to_light);
  }
#endif
#if DIRECTIONAL_LIGHTS > 0
  for (int k = 0; k < DIRECTIONAL_LIGHTS; ++k) {
    const int i = POINT_LIGHTS + SPOT_LIGHTS + k;
    radiance +=
        live(lights[i]) * directional_light_radiance(lights[i], s, to_light) *
        (lights[i].radiant.w > 0.0 ? shadow_2d_disc(lights[i], s.position, s.normal, to_light)  // the sun's disc
                                   : shadow_2d_sun(lights[i], s.position, s.normal, to_light));
  }
#endif
#if AREA_LIGHTS > 0
  for (int k = 0; k < AREA_LIGHTS; ++k) {
    const int i = POINT_LIGHTS + SPOT_LIGHTS + DIRECTIONAL_LIGHTS + k;
    to_light = normalize(lights[i].position_type.xyz - s.position);
    radiance += live(lights[i]) * area_light_radiance(lights[i], s) *
#if AREA_SHADOW_HALF
                texelFetch(u_area_visibility, ivec2(gl_FragCoord.xy), 0)[int(lights[i].shadow_params.z)];
#elif AREA_SOFT_SHADOWS
                shadow_area(lights[i], s.position, s.normal, to_light);
#else
                shadow_2d(lights[i], s.position, s.normal, to_light, 2.0, true);
#endif
  }
#endif

  // The sky as direct light from every direction: E = pi L, reflected as uniformly arriving
  // light is (E / pi x directional albedo). Both halves of a split view. A gradient adds its
  // irradiance at this normal, E / pi as a uniform radiance (engine::sky_irradiance:
  // E = pi horizon + (zenith - horizon) K(t) + (ground - horizon) K(pi - t), t = acos(n.y),
  // K(t) = 2/3 ((pi - t) cos t + sin t)). On a dynamic entity scaled by the provider's
  // measured sky visibility; none where the item's bake holds the sky (shadowed by the level).
#if SKY_TERM
  if ((u_baked_direct & 1) == 0) {
    float sky_t = acos(clamp(s.normal.y, -1.0, 1.0));
    float sky_k_up = (2.0 / 3.0) * ((PI - sky_t) * cos(sky_t) + sin(sky_t));
    float sky_k_down = (2.0 / 3.0) * (sky_t * cos(PI - sky_t) + sin(sky_t));
    vec3 sky_l =
        u_sky_radiance +
        max(u_sky_gradient[0] + (u_sky_gradient[1] * sky_k_up + u_sky_gradient[2] * sky_k_down) / PI, vec3(0.0));
    vec3 n2 = s.normal * s.normal;
    sky_l *= dot(n2, mix(u_sky_visibility_neg, u_sky_visibility_pos, step(vec3(0.0), s.normal)));
    if (any(greaterThan(sky_l, vec3(0.0)))) {
      GltfBrdfValue sky_albedo = gltf_directional_albedo(s.brdf, dot(s.normal, s.view));
      radiance += sky_l * (sky_albedo.diffuse + sky_albedo.specular);
    }
  }
#endif

  if (gl_FragCoord.x >= u_split_x && u_indirect_mode != 0) {
    // Indirect irradiance E (W/m^2) without direction information, reflected as uniformly
    // arriving light is: E / pi x the BRDF's directional albedo, per lobe. A provider's
    // glossy texture replaces the specular lobe's share where its alpha (coverage) says so;
    // on a static texel with directional radiance, the specular lobe integrated against it
    // replaces that share (the diffuse lobe keeps E).
    vec3 e = vec3(0.0);
    if (u_indirect_mode == 1) e = vec3(PI * u_ambient_radiance);
    if (u_indirect_mode == 2) e = texture(u_irradiance_atlas, v_uv1).rgb;
    if (u_indirect_mode == 3) e = v_vertex_irradiance;
    GltfBrdfValue albedo = gltf_directional_albedo(s.brdf, dot(s.normal, s.view));
    vec3 specular = e / PI * albedo.specular;
    if (u_indirect_mode == 2 && u_directional_bins > 0) {
      // Bilinear over the texels with maps (directional_footprint), where the texel under v_uv1 has them.
      int element;
      DirectionalTexels texels = directional_footprint(u_directional_index, v_uv1, element);
      // Tangent-frame bins turn about the vertex normal (the bake's texel normal), not the normal-mapped one.
      vec3 bin_normal = normalize(v_normal) * (u_double_sided != 0 && !gl_FrontFacing ? -1.0 : 1.0);
      if (element >= 0)
        specular = directional_specular(s.brdf, s.normal, s.view, texels, u_directional_bins, u_directional_elements,
                                        u_directional_tangent_frame != 0, bin_normal);
    }
    // A dynamic mesh's per-vertex radiance lobes replace the specular lobe's share (the diffuse keeps E).
    if (u_indirect_mode == 3 && u_lobe_terms > 0) specular = v_lobe_radiance;
    // Reflection probes replace the specular share on sharp static surfaces and on dynamic
    // meshes without their own lobes, where a probe's box holds the point (reflection_probes.glsl).
    if (reads_probes(s, u_indirect_mode == 2, u_indirect_mode == 3 && u_lobe_terms == 0)) {
      vec3 probe;
      if (probe_specular(s, albedo.specular, probe)) specular = probe;
    }
    if (u_use_glossy != 0) {
      vec4 glossy = texelFetch(u_glossy_radiance, ivec2(gl_FragCoord.xy), 0);
      specular = mix(specular, glossy.rgb, clamp(glossy.a, 0.0, 1.0));
    }
    radiance += e / PI * albedo.diffuse + specular;
  }
  o_radiance = vec4(radiance, alpha);
}
