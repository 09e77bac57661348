// Direct lighting of the forward pass: light records and the evaluation of point, spot,
// directional and rectangular area lights in engine units (engine/units.h) with glTF's BRDF
// (gltf_brdf.glsl). Shadows come from shadow_common.glsl.

#include "gltf_brdf.glsl"

const float PI = GLTF_PI;
#ifndef AREA_SPECULAR_SIDE
#define AREA_SPECULAR_SIDE 3
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

// One edge term of Lambert's formula for the integral of cos(theta) over the solid angle of
// a polygon, divided by 2 pi: angle(a, b) * dot(n, normalize(a x b)) / (2 pi) for unit
// vectors a, b. theta / (2 pi sin(theta)) uses the rational fit of Heitz et al. 2016
// ("Real-time polygonal-light shading with linearly transformed cosines", IntegrateEdge),
// which avoids acos/atan; the integral is pi times the sum over the closed polygon.
float edge_cosine_term(vec3 ua, vec3 ub, vec3 n) {
  float x = dot(ua, ub);
  float y = abs(x);
  float a = 0.8543985 + (0.4965155 + 0.0145206 * y) * y;
  float b = 3.4175940 + (4.1616724 + y) * y;
  float v = a / b;
  float theta_over_sin = x > 0.0 ? v : 0.5 * inversesqrt(max(1.0 - x * x, 1e-7)) - v;
  return dot(cross(ua, ub), n) * theta_over_sin;
}

// Integral of cos(theta) d(omega) over the quad q[0..3] (vertices relative to the shading
// point) clipped to the horizon dot(n, x) >= 0: every edge is clipped on its own and the
// horizon segment from the exit to the entry point closes the polygon. Written without
// dynamic indexing or data-dependent loops (cheap on llvmpipe's SIMD code).
float clipped_quad_cosine_integral(vec3 q[4], vec3 n) {
  vec3 u[4] = vec3[4](normalize(q[0]), normalize(q[1]), normalize(q[2]), normalize(q[3]));
  float sum = 0.0;
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
    if (a_up || b_up) sum += edge_cosine_term(a_up ? u[i] : c, b_up ? u[(i + 1) & 3] : c, n);
  }
  if (crosses) sum += edge_cosine_term(exit_point, entry_point, n);
  return abs(PI * sum);
}

// Rectangular area light of radiance L (W/(m^2 sr)), one-sided towards its emission
// direction. Diffuse: the exact irradiance of the rectangle clipped to the horizon
// (clipped_quad_cosine_integral) times the diffuse lobe's Fresnel weight averaged over the
// light (glTF's 1 - F(v.h) changes across it). Specular: AREA_SPECULAR_SIDE^2 stratified
// points on the rectangle, each weighted by its solid angle cos(theta_light) dA / d^2
// (converges to the integral); the same points give the diffuse weight's average, weighted
// by cos(theta_surface) x solid angle as the irradiance integral weights them.
vec3 area_light_radiance(GpuLight light, Surface s) {
  vec3 centre = light.position_type.xyz;
  vec3 dir = light.direction_range.xyz;
  if (dot(s.position - centre, dir) <= 0.0) return vec3(0.0);
  vec3 hx = light.area_half_x.xyz;
  vec3 hy = light.area_half_y.xyz;
  vec3 rel = centre - s.position;
  vec3 q[4] = vec3[4](rel - hx - hy, rel + hx - hy, rel + hx + hy, rel - hx + hy);
  float irradiance_per_radiance = clipped_quad_cosine_integral(q, s.normal);
  const int kSide = AREA_SPECULAR_SIDE;
  float sample_area = 4.0 * length(hx) * length(hy) / float(kSide * kSide);
  vec3 specular = vec3(0.0);
  float weight_sum = 0.0;
  float diffuse_weight_sum = 0.0;
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      vec2 t = (vec2(i, j) + 0.5) / float(kSide) * 2.0 - 1.0;
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
  float diffuse_weight = weight_sum > 0.0
                             ? diffuse_weight_sum / weight_sum
                             : gltf_diffuse_weight(s.brdf, dot(s.view, normalize(normalize(rel) + s.view)));
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
