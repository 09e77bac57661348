// Specular reflection of incoming light stored per direction bin: the GLSL twin of
// engine/include/engine/directional_radiance.h (the header explains the model; a test keeps
// the two equal). Include after gltf_brdf.glsl.
//
// Data (engine/indirect_light.h, IndirectLightFrame::directional_*):
//   DirectionalDirections  vec4 per bin: xyz the unit direction psi_k, w the bin's layer scale
//   DirectionalRadiance    uvec2 per (bin, element), bin-major: packHalf2x16(r, g),
//                          packHalf2x16(b, 0); radiance = unpacked x the bin's scale (W/(m^2 sr))

#ifndef DIRECTIONAL_RADIANCE_BINDING
#define DIRECTIONAL_RADIANCE_BINDING 2
#endif
#ifndef DIRECTIONAL_DIRECTION_BINDING
#define DIRECTIONAL_DIRECTION_BINDING 3
#endif

const float DIRECTIONAL_MIN_COS = 0.1;

layout(std430, binding = DIRECTIONAL_RADIANCE_BINDING) readonly buffer DirectionalRadiance { uvec2 dr_values[]; };
layout(std430, binding = DIRECTIONAL_DIRECTION_BINDING) readonly buffer DirectionalDirections { vec4 dr_directions[]; };

float directional_bin_alpha(int bin_count) {
  float n = float(max(bin_count, 2));
  float theta = acos(clamp(1.0 - 2.0 / n, -1.0, 1.0));
  return tan(0.5 * theta);
}

vec3 directional_bin_radiance(int bin, int element, int element_count) {
  uvec2 p = dr_values[bin * element_count + element];
  return vec3(unpackHalf2x16(p.x), unpackHalf2x16(p.y).x) * dr_directions[bin].w;
}

// L_spec of engine::directional_specular for stored element `element`.
vec3 directional_specular(GltfBrdf m, vec3 n, vec3 v, int element, int bin_count, int element_count) {
  float a_bin = directional_bin_alpha(bin_count);
  float a = sqrt(m.alpha * m.alpha + a_bin * a_bin);
  float n_dot_v = max(dot(n, v), 1e-4);
  float sum_w = 0.0;
  vec3 sum = vec3(0.0);
  for (int k = 0; k < bin_count; ++k) {
    vec3 l = dr_directions[k].xyz;
    float n_dot_l = dot(n, l);
    if (!(n_dot_l > DIRECTIONAL_MIN_COS)) continue;
    vec3 s = l + v;
    float len2 = dot(s, s);
    vec3 h = len2 > 1e-12 ? s * inversesqrt(len2) : n;
    float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
    float w = gltf_ggx_distribution(n_dot_h, a) * gltf_smith_visibility(n_dot_v, n_dot_l, a) * n_dot_l;
    sum_w += w;
    sum += w * directional_bin_radiance(k, element, element_count);
  }
  if (!(sum_w > 0.0)) return vec3(0.0);
  return gltf_directional_albedo(m, dot(n, v)).specular * (sum / sum_w);
}
