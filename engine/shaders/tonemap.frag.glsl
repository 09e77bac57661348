#version 450 core
// Exposure, tonemap and sRGB encoding. Tonemap: the ACES filmic curve fitted by Narkowicz
// (2015), x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), per channel, clamped to [0, 1];
// then the exact sRGB transfer function (renderer.h documents it for CPU-side checks).
layout(binding = 0) uniform sampler2D u_hdr;
layout(location = 0) uniform float u_exposure;
layout(location = 0) out vec4 o_color;

vec3 aces_narkowicz(vec3 x) {
  return clamp(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

vec3 srgb_encode(vec3 c) {
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main() {
  vec3 hdr = texelFetch(u_hdr, ivec2(gl_FragCoord.xy), 0).rgb;
  o_color = vec4(srgb_encode(aces_narkowicz(max(hdr, vec3(0.0)) * u_exposure)), 1.0);
}
