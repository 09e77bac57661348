#version 450 core
// Shadow-map pass: positions only.
layout(location = 0) in vec3 a_position;
layout(location = 0) uniform mat4 u_model;
layout(location = 8) uniform mat4 u_view_proj;
out vec3 v_world;
// The depth pre-pass (shadow.vert.glsl) and the forward pass must produce identical depths.
invariant gl_Position;

void main() {
  vec4 world = u_model * vec4(a_position, 1.0);
  v_world = world.xyz;
  gl_Position = u_view_proj * world;
}
