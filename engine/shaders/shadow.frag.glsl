#version 450 core
// Shadow-map pass: writes linear depth (see shadow_common.glsl): distance to the eye / far,
// or, for orthographic (directional) maps, distance along the light direction / far.
// ALPHA_TEST 1: cut-out casters (MASK and BLEND materials) discard their transparent texels.
#include "material_common.glsl"
in vec3 v_world;
uniform vec3 u_eye;
uniform float u_far_m;
uniform int u_ortho;
uniform vec3 u_axis;
void main() {
  alpha_test();
  float d = u_ortho != 0 ? dot(v_world - u_eye, u_axis) : length(v_world - u_eye);
  gl_FragDepth = clamp(d / u_far_m, 0.0, 1.0);
}
