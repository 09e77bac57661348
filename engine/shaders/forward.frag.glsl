#version 450 core
// Forward HDR pass: direct light of every enabled light with shadows, emission, and the
// indirect term (provider atlas / per-vertex irradiance / glossy texture, or the constant
// ambient stand-in). Output: linear radiance, W/(m^2 sr).

#include "lighting_common.glsl"
#include "shadow_common.glsl"

in vec3 v_world;
in vec3 v_normal;
in vec2 v_uv0;
in vec2 v_uv1;
in vec3 v_vertex_irradiance;

layout(location = 16) uniform vec3 u_camera_position;
layout(location = 17) uniform int u_light_count;
layout(location = 18) uniform vec4 u_base_color;
layout(location = 19) uniform float u_metallic;
layout(location = 20) uniform float u_roughness;
layout(location = 21) uniform vec3 u_emissive;
// 0: none, 1: constant ambient stand-in, 2: irradiance atlas at TEXCOORD_1, 3: per-vertex irradiance.
layout(location = 22) uniform int u_indirect_mode;
layout(location = 23) uniform float u_ambient_radiance;
// Pixels with x < u_split_x get direct light only (SplitView::DirectLeftFullRight); -1: off.
layout(location = 24) uniform float u_split_x;
layout(location = 25) uniform int u_use_glossy;
layout(location = 26) uniform int u_double_sided;

layout(binding = 0) uniform sampler2D u_base_color_texture;
layout(binding = 1) uniform sampler2D u_metallic_roughness_texture;
layout(binding = 2) uniform sampler2D u_emissive_texture;
layout(binding = 3) uniform sampler2D u_irradiance_atlas;
layout(binding = 6) uniform sampler2D u_glossy_radiance;

layout(location = 0) out vec4 o_radiance;

void main() {
  vec4 base = u_base_color * texture(u_base_color_texture, v_uv0);
  vec4 mr = texture(u_metallic_roughness_texture, v_uv0);
  float metallic = clamp(u_metallic * mr.b, 0.0, 1.0);
  float roughness = clamp(u_roughness * mr.g, 0.045, 1.0);

  Surface s;
  s.position = v_world;
  s.normal = normalize(v_normal);
  if (u_double_sided != 0 && !gl_FrontFacing) s.normal = -s.normal;
  s.view = normalize(u_camera_position - v_world);
  s.diffuse_albedo = (1.0 - metallic) * base.rgb;
  s.f0 = mix(vec3(0.04), base.rgb, metallic);
  s.alpha = roughness * roughness;

  vec3 radiance = u_emissive * texture(u_emissive_texture, v_uv0).rgb;
  for (int i = 0; i < u_light_count; ++i) {
    vec3 to_light;
    vec3 lit = light_radiance(lights[i], s, to_light);
    if (all(equal(lit, vec3(0.0)))) continue;
    radiance += lit * light_shadow(lights[i], s.position, s.normal, to_light);
  }

  if (gl_FragCoord.x >= u_split_x) {
    // Indirect irradiance E (W/m^2) reflected by the diffuse lobe: albedo / pi * E.
    if (u_indirect_mode == 1) radiance += s.diffuse_albedo * u_ambient_radiance;  // E = pi * L_ambient
    if (u_indirect_mode == 2) radiance += s.diffuse_albedo / PI * texture(u_irradiance_atlas, v_uv1).rgb;
    if (u_indirect_mode == 3) radiance += s.diffuse_albedo / PI * v_vertex_irradiance;
    if (u_use_glossy != 0) radiance += texelFetch(u_glossy_radiance, ivec2(gl_FragCoord.xy), 0).rgb;
  }
  o_radiance = vec4(radiance, 1.0);
}
