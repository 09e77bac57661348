#version 450 core
// Forward pass vertex stage: world position, normal, tangent, both UV sets and (for dynamic meshes
// with a provider buffer) the per-vertex indirect irradiance.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv0;
layout(location = 3) in vec2 a_uv1;
layout(location = 4) in vec4 a_tangent;  // xyz tangent, w handedness (zero: no normal map)

uniform mat4 u_model;
uniform mat4 u_normal_matrix;
uniform mat4 u_view_proj;
// Vertex of the whole-scene vertex buffer where this entity's mesh starts: gl_VertexID -
// u_mesh_first_vertex indexes the mesh's primitives concatenated in order.
uniform int u_mesh_first_vertex;
uniform int u_use_vertex_irradiance;

// Element layouts: engine/indirect_light.h's structs of the same names (std430, asserted there).
struct VertexIrradianceElement {
  vec3 irradiance;
  float unused;
};
layout(std430, binding = 1) readonly buffer VertexIrradiance { VertexIrradianceElement vertex_irradiance[]; };

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv0;
out vec2 v_uv1;
out vec4 v_tangent;  // world-space tangent; w the handedness, mirrored with the model matrix
out vec3 v_vertex_irradiance;

// --- Per-vertex view-dependent indirect light (IndirectLightFrame::vertex_radiance_lobes) ---
// L_spec toward the camera = sum_k c_k,j h_k(view in the vertex's frame); 0 terms: none.
uniform vec3 u_camera_position;
uniform int u_lobe_terms;
uniform int u_lobe_resolution;
uniform int u_lobe_first;
uniform int u_lobe_stride;
struct LobeCoefficient {
  vec3 radiance;
  float unused;
};
struct LobeCell {
  float value;
};
layout(std430, binding = 6) readonly buffer LobeCoefficients { LobeCoefficient lobe_coefficients[]; };
layout(std430, binding = 7) readonly buffer LobeTable { LobeCell lobe_table[]; };
out vec3 v_lobe_radiance;

float lobe_at(int k, int res, vec2 s) {
  const float n = float(res);
  const float fu = clamp((s.x + 1.0) * 0.5 * n - 0.5, 0.0, n - 1.0);
  const float fv = clamp((s.y + 1.0) * 0.5 * n - 0.5, 0.0, n - 1.0);
  const int u0 = int(fu), v0 = int(fv);
  const int u1 = min(u0 + 1, res - 1), v1 = min(v0 + 1, res - 1);
  const float tu = fu - float(u0), tv = fv - float(v0);
  const int base = k * res * res;
  return (1.0 - tv) *
             ((1.0 - tu) * lobe_table[base + v0 * res + u0].value + tu * lobe_table[base + v0 * res + u1].value) +
         tv * ((1.0 - tu) * lobe_table[base + v1 * res + u0].value + tu * lobe_table[base + v1 * res + u1].value);
}

vec3 lobe_radiance(vec3 world) {
  if (u_lobe_terms <= 0) return vec3(0.0);
  // The vertex's frame: Duff et al. 2017 around the object-space normal.
  const vec3 n = normalize(a_normal);
  const float sgn = n.z >= 0.0 ? 1.0 : -1.0;
  const float a = -1.0 / (sgn + n.z);
  const float bb = n.x * n.y * a;
  const vec3 t = vec3(1.0 + sgn * n.x * n.x * a, sgn * bb, -sgn * n.x);
  const vec3 b = vec3(bb, sgn + n.y * n.y * a, -n.y);
  const vec3 w = normalize(transpose(mat3(u_model)) * normalize(u_camera_position - world));
  const vec3 local = vec3(dot(t, w), dot(b, w), dot(n, w));
  if (local.z <= 0.0) return vec3(0.0);
  const float sum = abs(local.x) + abs(local.y) + local.z;
  const vec2 s = vec2(local.x + local.y, local.x - local.y) / sum;
  const int j = gl_VertexID - u_mesh_first_vertex;
  vec3 radiance = vec3(0.0);
  for (int k = 0; k < u_lobe_terms; ++k)
    radiance += lobe_coefficients[u_lobe_first + k * u_lobe_stride + j].radiance * lobe_at(k, u_lobe_resolution, s);
  return radiance;
}
// --- end per-vertex view-dependent indirect light ---

// The depth pre-pass (shadow.vert.glsl) and the forward pass must produce identical depths.
invariant gl_Position;

void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_normal_matrix) * a_normal;
  v_uv0 = a_uv0;
  v_uv1 = a_uv1;
  const mat3 linear = mat3(u_model);
  v_tangent = vec4(linear * a_tangent.xyz, determinant(linear) < 0.0 ? -a_tangent.w : a_tangent.w);
  v_vertex_irradiance =
      u_use_vertex_irradiance != 0 ? vertex_irradiance[gl_VertexID - u_mesh_first_vertex].irradiance : vec3(0.0);
  v_lobe_radiance = lobe_radiance(world.xyz);
  gl_Position = u_view_proj * world;
}
