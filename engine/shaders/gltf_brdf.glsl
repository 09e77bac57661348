// glTF 2.0's metallic-roughness BRDF (specification Appendix B) with KHR_materials_specular's
// factors: the GLSL twin of engine/include/engine/gltf_brdf.h, function by function (the
// header explains the model). A test evaluates both on a grid and keeps them equal.
//
// gltf_directional_albedo() reads the table of engine::gltf_albedo_table() from a 32 x 32
// RGBA32F texture (the renderer uploads it) at binding GLTF_ALBEDO_TABLE_BINDING, with the
// same manual bilinear interpolation as the C++ (texelFetch: no filtering precision loss).

#ifndef GLTF_ALBEDO_TABLE_BINDING
#define GLTF_ALBEDO_TABLE_BINDING 8
#endif

const float GLTF_PI = 3.14159265358979;
const float GLTF_MIN_ROUGHNESS = 0.045;
const float GLTF_DIELECTRIC_F0 = 0.04;
const int GLTF_ALBEDO_TABLE_SIZE = 32;

struct GltfBrdf {
  vec3 base_color;
  float metallic;
  float alpha;            // GGX alpha = clamped roughness^2
  float specular_weight;  // KHR_materials_specular specularFactor
  vec3 dielectric_f0;     // min(0.04 specularColorFactor, 1)
};

struct GltfBrdfValue {
  vec3 diffuse;
  vec3 specular;
};

GltfBrdf gltf_brdf(vec3 base_color, float metallic, float roughness, float specular_weight, vec3 specular_color) {
  GltfBrdf m;
  m.base_color = max(base_color, vec3(0.0));
  m.metallic = clamp(metallic, 0.0, 1.0);
  float r = clamp(roughness, GLTF_MIN_ROUGHNESS, 1.0);
  m.alpha = r * r;
  m.specular_weight = clamp(specular_weight, 0.0, 1.0);
  m.dielectric_f0 = min(GLTF_DIELECTRIC_F0 * max(specular_color, vec3(0.0)), vec3(1.0));
  return m;
}

float gltf_ggx_distribution(float n_dot_h, float alpha) {
  float a2 = alpha * alpha;
  float d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
  return a2 / (GLTF_PI * d * d);
}

// Height-correlated Smith visibility V = G2 / (4 n.l n.v) (Heitz 2014, eq. 99).
float gltf_smith_visibility(float n_dot_v, float n_dot_l, float alpha) {
  float a2 = alpha * alpha;
  float gv = n_dot_l * sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2);
  float gl = n_dot_v * sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2);
  return 0.5 / max(gv + gl, 1e-7);
}

// (1 - v.h)^5; pow(x, y) is undefined for x < 0, and a v.h rounded just above 1 (a light
// beside the camera, as a flashlight is) made NaN pixels, hence the clamp.
float gltf_schlick_weight(float v_dot_h) {
  float m = 1.0 - clamp(v_dot_h, 0.0, 1.0);
  float m2 = m * m;
  return m2 * m2 * m;
}

float gltf_max_component(vec3 v) { return max(v.x, max(v.y, v.z)); }

float gltf_diffuse_weight(GltfBrdf m, float v_dot_h) {
  float f0m = gltf_max_component(m.dielectric_f0);
  return 1.0 - m.specular_weight * (f0m + (1.0 - f0m) * gltf_schlick_weight(v_dot_h));
}

// f(v, l) cos(theta_l) per lobe; unit vectors, n on the side of v.
GltfBrdfValue gltf_eval_cos(GltfBrdf m, vec3 n, vec3 v, vec3 l) {
  GltfBrdfValue out_value;
  out_value.diffuse = vec3(0.0);
  out_value.specular = vec3(0.0);
  float n_dot_l = dot(n, l);
  if (!(n_dot_l > 0.0)) return out_value;
  float n_dot_v = max(dot(n, v), 1e-4);
  vec3 sum = l + v;
  float len2 = dot(sum, sum);
  vec3 h = len2 > 1e-12 ? sum * inversesqrt(len2) : n;
  float n_dot_h = clamp(dot(n, h), 0.0, 1.0);
  float v_dot_h = clamp(dot(v, h), 0.0, 1.0);
  float w = gltf_schlick_weight(v_dot_h);
  vec3 f_dielectric = m.dielectric_f0 + (vec3(1.0) - m.dielectric_f0) * w;
  vec3 f_metal = m.base_color + (vec3(1.0) - m.base_color) * w;
  float lobe = gltf_ggx_distribution(n_dot_h, m.alpha) * gltf_smith_visibility(n_dot_v, n_dot_l, m.alpha);
  out_value.diffuse = (1.0 - m.metallic) * gltf_diffuse_weight(m, v_dot_h) * m.base_color * (n_dot_l / GLTF_PI);
  out_value.specular =
      ((1.0 - m.metallic) * m.specular_weight * f_dielectric + m.metallic * f_metal) * (lobe * n_dot_l);
  return out_value;
}

layout(binding = GLTF_ALBEDO_TABLE_BINDING) uniform sampler2D u_gltf_albedo_table;

// engine::GltfAlbedoTable::sample: bilinear between nodes, linear in sqrt(cos_v) and roughness.
vec4 gltf_albedo_table_sample(float n_dot_v, float roughness) {
  const float last = float(GLTF_ALBEDO_TABLE_SIZE - 1);
  float x = sqrt(clamp(n_dot_v, 0.0, 1.0)) * last;
  float y = clamp((roughness - GLTF_MIN_ROUGHNESS) / (1.0 - GLTF_MIN_ROUGHNESS), 0.0, 1.0) * last;
  int i0 = min(int(x), GLTF_ALBEDO_TABLE_SIZE - 2);
  int j0 = min(int(y), GLTF_ALBEDO_TABLE_SIZE - 2);
  float fx = x - float(i0);
  float fy = y - float(j0);
  vec4 lo =
      mix(texelFetch(u_gltf_albedo_table, ivec2(i0, j0), 0), texelFetch(u_gltf_albedo_table, ivec2(i0 + 1, j0), 0), fx);
  vec4 hi = mix(texelFetch(u_gltf_albedo_table, ivec2(i0, j0 + 1), 0),
                texelFetch(u_gltf_albedo_table, ivec2(i0 + 1, j0 + 1), 0), fx);
  return mix(lo, hi, fy);
}

// Radiance reflected towards v per unit of uniform incident radiance, per lobe: a surface
// reflects irradiance E that arrives without direction information as E / pi x this.
GltfBrdfValue gltf_directional_albedo(GltfBrdf m, float n_dot_v) {
  vec4 abp = gltf_albedo_table_sample(n_dot_v, sqrt(m.alpha));
  float f0m = gltf_max_component(m.dielectric_f0);
  GltfBrdfValue out_value;
  out_value.diffuse = (1.0 - m.metallic) * m.base_color * (1.0 - m.specular_weight * (f0m + (1.0 - f0m) * abp.z));
  out_value.specular =
      (1.0 - m.metallic) * m.specular_weight * (m.dielectric_f0 * abp.x + (vec3(1.0) - m.dielectric_f0) * abp.y) +
      m.metallic * (m.base_color * abp.x + (vec3(1.0) - m.base_color) * abp.y);
  return out_value;
}
