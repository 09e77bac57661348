#version 450 core
// Shadow-map and depth pre-pass vertex stage: positions, and both UV sets for the
// alpha-tested variants (material_common.glsl, ALPHA_TEST).
layout(location = 0) in vec3 a_position;
layout(location = 2) in vec2 a_uv0;
layout(location = 3) in vec2 a_uv1;
uniform mat4 u_model;
uniform mat4 u_view_proj;
out vec3 v_world;
out vec2 v_uv0;
out vec2 v_uv1;
// The depth pre-pass (shadow.vert.glsl) and the forward pass must produce identical depths.
invariant gl_Position;

void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_uv0 = a_uv0;
  v_uv1 = a_uv1;
  gl_Position = u_view_proj * world;
}
