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

// Element layouts: engine/indirect_light.h's DirectionalRadiance and DirectionalBin (std430, asserted there).
struct DirectionalRadianceElement {
  uint red_green;  // packHalf2x16(r, g)
  uint blue;       // packHalf2x16(b, 0)
};
struct DirectionalBin {
  vec3 direction;
  float scale;
};
layout(std430, binding = DIRECTIONAL_RADIANCE_BINDING) readonly buffer DirectionalRadiance { DirectionalRadianceElement dr_values[]; };
layout(std430, binding = DIRECTIONAL_DIRECTION_BINDING) readonly buffer DirectionalDirections { DirectionalBin dr_directions[]; };

float directional_bin_alpha(int bin_count) {
  float n = float(max(bin_count, 2));
  float theta = acos(clamp(1.0 - 2.0 / n, -1.0, 1.0));
  return tan(0.5 * theta);
}

vec3 directional_bin_radiance(int bin, int element, int element_count) {
  DirectionalRadianceElement p = dr_values[bin * element_count + element];
  return vec3(unpackHalf2x16(p.red_green), unpackHalf2x16(p.blue).x) * dr_directions[bin].scale;
}

const int DIRECTIONAL_LOBE_SAMPLES = 8;
const float DIRECTIONAL_LOBE_WIDENING = 0.5;

vec2 directional_lobe_sample_point(int j) {
  uint bits = uint(j);
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return vec2((float(j) + 0.5) / float(DIRECTIONAL_LOBE_SAMPLES), float(bits) * 2.3283064365386963e-10);
}

int directional_bin_of(vec3 n, vec3 l, int bin_count) {
  int best = -1;
  float best_dot = -2.0;
  for (int k = 0; k < bin_count; ++k) {
    vec3 psi = dr_directions[k].direction;
    if (!(dot(n, psi) > DIRECTIONAL_MIN_COS)) continue;
    float d = dot(l, psi);
    if (d > best_dot) {
      best_dot = d;
      best = k;
    }
  }
  return best;
}

// L_spec of engine::directional_specular for stored element `element`.
vec3 directional_specular(GltfBrdf m, vec3 n, vec3 v, int element, int bin_count, int element_count) {
  float a_bin = DIRECTIONAL_LOBE_WIDENING * directional_bin_alpha(bin_count);
  float a = sqrt(m.alpha * m.alpha + a_bin * a_bin);
  float n_dot_v = max(dot(n, v), 1e-4);
  vec3 t = abs(n.x) > 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  t = normalize(t - n * dot(n, t));
  vec3 b = cross(n, t);
  vec3 ve = vec3(dot(v, t), dot(v, b), n_dot_v);
  vec3 vh = normalize(vec3(a * ve.x, a * ve.y, ve.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 0.0 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float g1 = 2.0 * n_dot_v / (n_dot_v + sqrt(a * a + (1.0 - a * a) * n_dot_v * n_dot_v));
  float sum_w = 0.0;
  vec3 sum = vec3(0.0);
  for (int j = 0; j < DIRECTIONAL_LOBE_SAMPLES; ++j) {
    vec2 u = directional_lobe_sample_point(j);
    float r = sqrt(u.x);
    float phi = 6.28318530718 * u.y;
    float p1 = r * cos(phi);
    float s = 0.5 * (1.0 + vh.z);
    float p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    vec3 ne = normalize(vec3(a * nh.x, a * nh.y, max(0.0, nh.z)));
    vec3 h = ne.x * t + ne.y * b + ne.z * n;
    vec3 l = 2.0 * dot(v, h) * h - v;
    float n_dot_l = dot(n, l);
    if (!(n_dot_l > 0.0)) continue;
    int k = directional_bin_of(n, l, bin_count);
    if (k < 0) continue;
    float w = 4.0 * n_dot_l * n_dot_v * gltf_smith_visibility(n_dot_v, n_dot_l, a) / g1;
    sum_w += w;
    sum += w * directional_bin_radiance(k, element, element_count);
  }
  if (!(sum_w > 0.0)) return vec3(0.0);
  return gltf_directional_albedo(m, dot(n, v)).specular * (sum / sum_w);
}
