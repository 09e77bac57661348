// Direct lighting of the forward pass: light records and the evaluation of point, spot,
// directional and rectangular area lights in engine units (engine/units.h) with glTF's BRDF
// (gltf_brdf.glsl). Shadows come from shadow_common.glsl.

#include "gltf_brdf.glsl"

const float PI = GLTF_PI;
// Specular of area lights: 0, the integral of a linearly transformed cosine fitted to the GGX
// lobe (area_ltc_specular); 1..4, AREA_SPECULAR_SIDE^2 fixed points on the rectangle.
#ifndef AREA_SPECULAR_SIDE
#define AREA_SPECULAR_SIDE 0
#endif
const int LIGHT_POINT = 0;
const int LIGHT_SPOT = 1;
const int LIGHT_DIRECTIONAL = 2;
const int LIGHT_AREA = 3;

// Mirrors engine/src/render/gpu_light.h (std430, 208 bytes).
struct GpuLight {
  vec4 position_type;    // xyz: world position (m); w: LIGHT_* type
  vec4 direction_range;  // xyz: unit emission direction (the light's -Z); w: range (m), 0 = unlimited
  vec4 radiant;          // rgb: colour x intensity (W/sr, W/m^2 or W/(m^2 sr) by type)
  // x: cos(outer), y: cos(inner), z: 2-D shadow layer or -1, w: shadow cube or -1 (point; area: the grazing band)
  vec4 cone;
  vec4 area_half_x;       // xyz: half of the rectangle along the light's X axis (m)
  vec4 area_half_y;       // xyz: half of the rectangle along the light's Y axis (m)
  mat4 shadow_view_proj;  // world -> clip of the 2-D shadow map
  vec4 shadow_eye;        // xyz: shadow camera position (m); w: far distance that maps to depth 1 (m)
  // x: 0 ortho / 1 distance; y: texel footprint (m, or m per m of distance); z: area lights: index among them;
  // w: area lights: texel footprint of the cube map (cone.w) beyond the 2-D map
  vec4 shadow_params;
  vec4 flags;  // x: 1 when the light does not move (Light::moves false): a bake may hold its direct light
};

layout(std430, binding = 0) readonly buffer Lights { GpuLight lights[]; };

// The fitted inverse transforms of area_ltc_specular (engine/src/render/area_ltc_table.h,
// written by tools/area-ltc-fit): AREA_LTC_SIDE^2 nodes, node (i, j) at [j AREA_LTC_SIDE + i].
// A buffer, not a GLSL constant array: llvmpipe took ~25 s to compile the forward pass with
// the 1024-entry array inlined.
#ifndef AREA_LTC_BINDING
#define AREA_LTC_BINDING 9
#endif
const int AREA_LTC_SIDE = 32;
layout(std430, binding = AREA_LTC_BINDING) readonly buffer AreaLtc { vec4 area_ltc_table[]; };

// The shading point: where, which way, and glTF's BRDF there (gltf_brdf.glsl).
struct Surface {
  vec3 position;
  vec3 normal;  // unit, facing the viewer's side for double-sided materials
  vec3 view;    // unit, towards the camera
  GltfBrdf brdf;
};

// The glTF BRDF times cos(theta_l) for a unit light direction l, both lobes.
vec3 brdf_cos(Surface s, vec3 l) {
  GltfBrdfValue f = gltf_eval_cos(s.brdf, s.normal, s.view, l);
  return f.diffuse + f.specular;
}

// glTF KHR_lights_punctual range window: (1 - (d/range)^4)^2 clamped, 1 when range is 0.
float range_window(float distance_m, float range_m) {
  if (range_m <= 0.0) return 1.0;
  float r = distance_m / range_m;
  float w = clamp(1.0 - r * r * r * r, 0.0, 1.0);
  return w * w;
}

// One edge of Lambert's formula for the vector integral of the unit direction over the
// solid angle of a polygon, divided by 2 pi: angle(a, b) * normalize(a x b) / (2 pi) for unit
// vectors a, b (its dot product with n is the edge's term of the integral of cos(theta)).
// theta / (2 pi sin(theta)) uses the rational fit of Heitz et al. 2016 ("Real-time
// polygonal-light shading with linearly transformed cosines", IntegrateEdge), which avoids
// acos/atan; the integral is pi times the sum over the closed polygon.
vec3 edge_vector_term(vec3 ua, vec3 ub) {
  float x = dot(ua, ub);
  float y = abs(x);
  float a = 0.8543985 + (0.4965155 + 0.0145206 * y) * y;
  float b = 3.4175940 + (4.1616724 + y) * y;
  float v = a / b;
  float theta_over_sin = x > 0.0 ? v : 0.5 * inversesqrt(max(1.0 - x * x, 1e-7)) - v;
  return cross(ua, ub) * theta_over_sin;
}

// Vector integral (pi times the edge sum, up to the winding's sign) over the quad q[0..3]
// (vertices relative to the shading point) clipped to the horizon dot(n, x) >= 0: every edge
// is clipped on its own and the horizon segment from the exit to the entry point closes the
// polygon. Its dot product with n is the integral of cos(theta) d(omega); its direction is
// the clipped quad's mean direction. Written without dynamic indexing or data-dependent loops
// (cheap on llvmpipe's SIMD code).
vec3 clipped_quad_vector_integral(vec3 q[4], vec3 n) {
  vec3 u[4] = vec3[4](normalize(q[0]), normalize(q[1]), normalize(q[2]), normalize(q[3]));
  vec3 sum = vec3(0.0);
  vec3 exit_point = vec3(0.0);
  vec3 entry_point = vec3(0.0);
  bool crosses = false;
  for (int i = 0; i < 4; ++i) {
    vec3 a = q[i];
    vec3 b = q[(i + 1) & 3];
    float da = dot(n, a);
    float db = dot(n, b);
    bool a_up = da >= 0.0;
    bool b_up = db >= 0.0;
    // Only edges that cross the horizon need the (normalized) crossing point.
    vec3 c = a_up != b_up ? normalize(a + (b - a) * (da / (da - db))) : u[i];
    if (a_up && !b_up) exit_point = c;
    if (!a_up && b_up) entry_point = c;
    crosses = crosses || (a_up != b_up);
    if (a_up || b_up) sum += edge_vector_term(a_up ? u[i] : c, b_up ? u[(i + 1) & 3] : c);
  }
  if (crosses) sum += edge_vector_term(exit_point, entry_point);
  return PI * sum;
}

// Integral of cos(theta) d(omega) over the quad q[0..3] clipped to the horizon of n.
float clipped_quad_cosine_integral(vec3 q[4], vec3 n) { return abs(dot(clipped_quad_vector_integral(q, n), n)); }

// The fitted inverse transform (AreaLtc) at a view cosine and
// perceptual roughness: bilinear between the table's nodes, as the table's spacing.
vec4 area_ltc_inverse(float n_dot_v, float roughness) {
  const float last = float(AREA_LTC_SIDE - 1);
  float x = sqrt(clamp(1.0 - n_dot_v, 0.0, 1.0)) * last;
  float y = clamp((roughness - GLTF_MIN_ROUGHNESS) / (1.0 - GLTF_MIN_ROUGHNESS), 0.0, 1.0) * last;
  int i0 = min(int(x), AREA_LTC_SIDE - 2);
  int j0 = min(int(y), AREA_LTC_SIDE - 2);
  float fx = x - float(i0);
  float fy = y - float(j0);
  int k = j0 * AREA_LTC_SIDE + i0;
  vec4 lo = mix(area_ltc_table[k], area_ltc_table[k + 1], fx);
  vec4 hi = mix(area_ltc_table[k + AREA_LTC_SIDE], area_ltc_table[k + AREA_LTC_SIDE + 1], fx);
  return mix(lo, hi, fy);
}

// Specular of a rectangle (q: its corners relative to the shading point) per unit radiance:
// the GGX lobe (Fresnel 1) is approximated by a cosine lobe under a linear transform M
// fitted per view angle and roughness (Heitz et al. 2016), so the lobe's mass over the
// rectangle is the cosine integral of the rectangle under M^-1, exact for polygons; the
// lobe's directional albedo with glTF's Fresnel (gltf_directional_albedo) scales it.
vec3 area_ltc_specular(Surface s, vec3 q[4]) {
  float n_dot_v = clamp(dot(s.normal, s.view), 1e-4, 1.0);
  vec3 t1 = s.view - s.normal * dot(s.normal, s.view);
  float len2 = dot(t1, t1);
  vec3 side = abs(s.normal.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
  t1 = len2 > 1e-10 ? t1 * inversesqrt(len2) : normalize(cross(s.normal, side));
  vec3 t2 = cross(s.normal, t1);
  vec4 m = area_ltc_inverse(n_dot_v, sqrt(s.brdf.alpha));
  vec3 p[4];
  for (int k = 0; k < 4; ++k) {
    vec3 l = vec3(dot(q[k], t1), dot(q[k], t2), dot(q[k], s.normal));
    p[k] = vec3(m.x * l.x + m.y * l.z, l.y, m.z * l.x + m.w * l.z);
  }
  float fraction = clipped_quad_cosine_integral(p, vec3(0.0, 0.0, 1.0)) / PI;
  return gltf_directional_albedo(s.brdf, n_dot_v).specular * fraction;
}

// Specular of a rectangle (corners centre +- hx +- hy, `rel` = centre - shading point, one-sided
// towards `dir`) from side^2 stratified points, each weighted by its solid angle
// cos(theta_light) dA / d^2: converges to the integral for wide lobes, but draws a sharp one
// (roughness below ~0.3) as side^2 separate highlights. The same points give the diffuse
// lobe's Fresnel weight averaged as the irradiance integral weights them (out).
vec3 area_points_specular(Surface s, vec3 rel, vec3 hx, vec3 hy, vec3 dir, const int side, out float diffuse_weight) {
  float sample_area = 4.0 * length(hx) * length(hy) / float(side * side);
  vec3 specular = vec3(0.0);
  float weight_sum = 0.0;
  float diffuse_weight_sum = 0.0;
  for (int j = 0; j < side; ++j) {
    for (int i = 0; i < side; ++i) {
      vec2 t = (vec2(i, j) + 0.5) / float(side) * 2.0 - 1.0;
      vec3 to_light = rel + t.x * hx + t.y * hy;
      float d2 = max(dot(to_light, to_light), 1e-8);
      vec3 l = to_light * inversesqrt(d2);
      float solid_angle = max(-dot(dir, l), 0.0) * sample_area / d2;
      specular += gltf_eval_cos(s.brdf, s.normal, s.view, l).specular * solid_angle;
      float w = max(dot(s.normal, l), 0.0) * solid_angle;
      weight_sum += w;
      diffuse_weight_sum += w * gltf_diffuse_weight(s.brdf, dot(s.view, normalize(l + s.view)));
    }
  }
  // All sample points below the horizon while the clipped rectangle is not: the weight
  // towards the light's centre.
  diffuse_weight = weight_sum > 0.0 ? diffuse_weight_sum / weight_sum
                                    : gltf_diffuse_weight(s.brdf, dot(s.view, normalize(normalize(rel) + s.view)));
  return specular;
}

// Rectangular area light of radiance L (W/(m^2 sr)), one-sided towards its emission
// direction. Diffuse: the exact irradiance of the rectangle clipped to the horizon
// (clipped_quad_cosine_integral) times the diffuse lobe's Fresnel weight (glTF's 1 - F(v.h)
// changes across the light). Specular, AREA_SPECULAR_SIDE 0: area_ltc_specular (the renderer
// draws materials sharper than roughness 0.3 with it, forward_shading.cpp's sharp_for_ltc),
// with the diffuse weight at the clipped rectangle's mean direction. AREA_SPECULAR_SIDE n > 0:
// n x n points (area_points_specular).
vec3 area_light_radiance(GpuLight light, Surface s) {
  vec3 centre = light.position_type.xyz;
  vec3 dir = light.direction_range.xyz;
  if (dot(s.position - centre, dir) <= 0.0) return vec3(0.0);
  vec3 hx = light.area_half_x.xyz;
  vec3 hy = light.area_half_y.xyz;
  vec3 rel = centre - s.position;
  vec3 q[4] = vec3[4](rel - hx - hy, rel + hx - hy, rel + hx + hy, rel - hx + hy);
  vec3 vector_integral = clipped_quad_vector_integral(q, s.normal);
  float irradiance_per_radiance = abs(dot(vector_integral, s.normal));
  float diffuse_weight = 1.0;
#if AREA_SPECULAR_SIDE == 0
  vec3 specular = area_ltc_specular(s, q);
  vec3 mean_dir = vector_integral * sign(dot(vector_integral, s.normal));
  float mean_len2 = dot(mean_dir, mean_dir);
  vec3 l_mean = mean_len2 > 1e-12 ? mean_dir * inversesqrt(mean_len2) : normalize(rel);
  diffuse_weight = gltf_diffuse_weight(s.brdf, dot(s.view, normalize(l_mean + s.view)));
#else
  vec3 specular = area_points_specular(s, rel, hx, hy, dir, AREA_SPECULAR_SIDE, diffuse_weight);
#endif
  vec3 diffuse = (1.0 - s.brdf.metallic) * s.brdf.base_color / PI * diffuse_weight * irradiance_per_radiance;
  return light.radiant.rgb * (diffuse + specular);
}

// Unshadowed outgoing radiance towards the viewer from one light of each type; `to_light`
// (out) is the unit direction used for shadow biasing.
vec3 directional_light_radiance(GpuLight light, Surface s, out vec3 to_light) {
  to_light = -light.direction_range.xyz;
  return light.radiant.rgb * brdf_cos(s, to_light);
}

// Point light: E = I cos / d^2 times the glTF range window.
vec3 point_light_radiance(GpuLight light, Surface s, out vec3 to_light) {
  vec3 d = light.position_type.xyz - s.position;
  float dist2 = max(dot(d, d), 1e-8);
  float dist = sqrt(dist2);
  to_light = d / dist;
  float attenuation = range_window(dist, light.direction_range.w) / dist2;
  return light.radiant.rgb * attenuation * brdf_cos(s, to_light);
}

// Spot light: a point light times smoothstep(cos outer, cos inner, cos angle to the axis).
vec3 spot_light_radiance(GpuLight light, Surface s, out vec3 to_light) {
  vec3 radiance = point_light_radiance(light, s, to_light);
  float cos_axis = dot(-to_light, light.direction_range.xyz);
  float cos_outer = light.cone.x;
  float cos_inner = light.cone.y;
  return radiance *
         (cos_inner - cos_outer > 1e-5 ? smoothstep(cos_outer, cos_inner, cos_axis) : step(cos_outer, cos_axis));
}
