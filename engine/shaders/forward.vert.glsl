#version 450 core
// Forward pass vertex stage: world position, normal, both UV sets and (for dynamic meshes
// with a provider buffer) the per-vertex indirect irradiance.

layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec2 a_uv0;
layout(location = 3) in vec2 a_uv1;

layout(location = 0) uniform mat4 u_model;
layout(location = 4) uniform mat4 u_normal_matrix;
layout(location = 8) uniform mat4 u_view_proj;
// Vertex of the whole-scene vertex buffer where this entity's mesh starts: gl_VertexID -
// u_mesh_first_vertex indexes the mesh's primitives concatenated in order.
layout(location = 12) uniform int u_mesh_first_vertex;
layout(location = 13) uniform int u_use_vertex_irradiance;

layout(std430, binding = 1) readonly buffer VertexIrradiance { vec4 vertex_irradiance[]; };

out vec3 v_world;
out vec3 v_normal;
out vec2 v_uv0;
out vec2 v_uv1;
out vec3 v_vertex_irradiance;

// The depth pre-pass (shadow.vert.glsl) and the forward pass must produce identical depths.
invariant gl_Position;

void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(u_normal_matrix) * a_normal;
  v_uv0 = a_uv0;
  v_uv1 = a_uv1;
  v_vertex_irradiance = u_use_vertex_irradiance != 0 ? vertex_irradiance[gl_VertexID - u_mesh_first_vertex].xyz : vec3(0.0);
  gl_Position = u_view_proj * world;
}
