#version 450 core
// The area lights' soft-shadow visibility (shadow_area, PCSS) at half resolution, upsampled
// to the full-resolution pixels that the forward pass reads (RenderSettings::area_shadow_res,
// docs/performance-frame.md). Channel c of every visibility texel is area light c of the
// frame's light list (GpuLight::shadow_params.z); at most 4 area lights.
//
// AREA_SHADOW_PASS 0 (half resolution, after a half-resolution depth pre-pass, GL_EQUAL):
//   out 0: the visibility of each area light at the pixel's surface;
//   out 1: that surface's normal and the offset of its tangent plane, dot(n, p) (RGBA32F).
// AREA_SHADOW_PASS 1 (full resolution, GL_EQUAL on the forward pass's depth): each pixel
//   weighs the 4 nearest half-resolution texels bilinearly, times whether each lies on the
//   pixel's own surface: its tangent plane within kPlaneTolerance of the pixel's position and
//   its normal within ~25 degrees of the pixel's. Where none does (geometry edges: a texel of
//   another surface must never lend its shadow), the pixel is flagged for pass 2 in the
//   stencil's top bit (gl_FragStencilRefARB) and writes nothing useful.
// AREA_SHADOW_PASS 2 (full resolution, GL_EQUAL and the stencil's top bit): shadow_area at
//   the flagged pixels, as the full-resolution path computes it.
#extension GL_ARB_shader_stencil_export : enable
#ifndef AREA_SHADOW_PASS
#define AREA_SHADOW_PASS 0
#endif

#include "lighting_common.glsl"
#include "shadow_common.glsl"

in vec3 v_world;
in vec3 v_normal;
uniform int u_double_sided;
// Area lights at the start of the Lights buffer (1..4), a compile-time count as in forward.frag.glsl.
#ifndef AREA_LIGHTS
#define AREA_LIGHTS 1
#endif

layout(binding = 13) uniform sampler2D u_half_visibility;
layout(binding = 14) uniform sampler2D u_half_plane;

layout(location = 0) out vec4 o_visibility;
#if AREA_SHADOW_PASS == 0
layout(location = 1) out vec4 o_plane;
#endif

vec3 surface_normal() {
  vec3 n = normalize(v_normal);
  return u_double_sided != 0 && !gl_FrontFacing ? -n : n;
}

vec4 visibility(vec3 p, vec3 n) {
  vec4 v = vec4(1.0);
  for (int i = 0; i < AREA_LIGHTS; ++i) {
    v[i] = shadow_area(lights[i], p, n, normalize(lights[i].position_type.xyz - p));
  }
  return v;
}

// Same surface: the half-resolution texel's tangent plane passes within this many metres
// plus kPlaneSlope x the camera distance of the pixel's position.
const float kPlaneTolerance = 0.02;
const float kPlaneSlope = 0.01;
const float kNormalCos = 0.9;
uniform vec3 u_camera_position;

void main() {
  vec3 n = surface_normal();
#if AREA_SHADOW_PASS == 0
  o_visibility = visibility(v_world, n);
  o_plane = vec4(n, dot(n, v_world));
#elif AREA_SHADOW_PASS == 1
  ivec2 size = textureSize(u_half_visibility, 0);
  vec2 h = gl_FragCoord.xy * 0.5 - 0.5;  // the pixel's centre in half-resolution texels
  ivec2 base = ivec2(floor(h));
  vec2 f = h - vec2(base);
  float tolerance = kPlaneTolerance + kPlaneSlope * length(u_camera_position - v_world);
  vec4 sum = vec4(0.0);
  float weight = 0.0;
  for (int k = 0; k < 4; ++k) {
    ivec2 o = ivec2(k & 1, k >> 1);
    ivec2 t = clamp(base + o, ivec2(0), size - 1);
    vec4 plane = texelFetch(u_half_plane, t, 0);
    float bilinear = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
    float w = bilinear * step(abs(dot(plane.xyz, v_world) - plane.w), tolerance) * step(kNormalCos, dot(plane.xyz, n));
    sum += w * texelFetch(u_half_visibility, t, 0);
    weight += w;
  }
  bool matched = weight > 1e-3;
  o_visibility = matched ? sum / weight : vec4(1.0);
  gl_FragStencilRefARB = matched ? 0 : 0x80;
#else
  o_visibility = visibility(v_world, n);
#endif
}
