#version 450 core
// Exposure, tonemap and sRGB encoding. Tonemap: the ACES filmic curve fitted by Narkowicz
// (2015), x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), per channel, clamped to [0, 1];
// then the exact sRGB transfer function (renderer.h documents it for CPU-side checks).
// Exposure: u_exposure (fixed modes), or with u_metered the adapted exposure that
// exposure_adapt.comp.glsl wrote this frame (automatic, docs/exposure.md).
#ifndef EXPOSURE_STATE_BINDING
#define EXPOSURE_STATE_BINDING 4  // render/exposure_meter.h's kExposureStateBinding defines it
#endif
layout(binding = 0) uniform sampler2D u_hdr;
uniform float u_exposure;
uniform int u_metered;
layout(std430, binding = EXPOSURE_STATE_BINDING) readonly buffer ExposureState { float state_exposure; };
layout(location = 0) out vec4 o_color;

vec3 aces_narkowicz(vec3 x) { return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0); }

vec3 srgb_encode(vec3 c) { return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c)); }

void main() {
  vec3 hdr = texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb;
  const float exposure = u_metered != 0 ? state_exposure : u_exposure;
  o_color = vec4(srgb_encode(aces_narkowicz(max(hdr, vec3(0.0)) * exposure)), 1.0);
}
