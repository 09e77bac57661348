// Shadow-map lookups of the forward pass. Every shadow map stores a linear depth:
// distance from the light / far for point, spot and area lights, distance along the light
// direction / far for directional lights. Filtering: hardware 2x2 compare (bilinear PCF)
// over a 3x3 grid; the receiver is offset along its normal by one texel and the depth
// reference is biased by texel * (1 + spacing * tan(theta)) (slope-scaled).

layout(binding = 4) uniform sampler2DArrayShadow u_shadow_maps;
layout(binding = 5) uniform samplerCubeArrayShadow u_point_shadow_maps;
layout(binding = 12) uniform sampler2DArray u_shadow_depths;  // the same 2-D maps, raw depths

float slope_tangent(vec3 n, vec3 to_light) {
  float n_dot_l = clamp(dot(n, to_light), 0.05, 1.0);
  return min(sqrt(1.0 - n_dot_l * n_dot_l) / n_dot_l, 8.0);
}

// A 3x3 grid of bilinear compare taps `spacing` texels apart (1: 4x4 texel footprint,
// 2: 6x6, the softened area-light kernel). `spacing` is passed as a literal.
float shadow_2d(GpuLight light, vec3 p, vec3 n, vec3 to_light, float spacing) {
  int layer = int(light.cone.z);
  if (layer < 0) return 1.0;
  bool ortho = light.shadow_params.x < 0.5;
  vec3 eye = light.shadow_eye.xyz;
  float far_m = light.shadow_eye.w;
  vec3 axis = light.direction_range.xyz;
  float dist = ortho ? dot(p - eye, axis) : length(p - eye);
  float texel = ortho ? light.shadow_params.y : light.shadow_params.y * dist;
  vec3 po = p + n * texel;
  vec4 clip = light.shadow_view_proj * vec4(po, 1.0);
  if (clip.w <= 0.0) return 1.0;
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
  float d = ortho ? dot(po - eye, axis) : length(po - eye);
  float bias = texel * (1.0 + spacing * slope_tangent(n, to_light));
  float ref = (d - bias) / far_m;
  vec2 texel_uv = 1.0 / vec2(textureSize(u_shadow_maps, 0).xy);
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x)
      sum += texture(u_shadow_maps, vec4(uv + vec2(x, y) * spacing * texel_uv, float(layer), ref));
  return sum / 9.0;
}

float shadow_cube(GpuLight light, vec3 p, vec3 n, vec3 to_light) {
  int cube = int(light.cone.w);
  if (cube < 0) return 1.0;
  vec3 eye = light.position_type.xyz;
  float far_m = light.shadow_eye.w;
  float texel = light.shadow_params.y * length(p - eye);
  vec3 po = p + n * texel;
  vec3 d = po - eye;
  float dist = length(d);
  vec3 w = d / max(dist, 1e-8);
  vec3 t = normalize(cross(abs(w.y) < 0.9 ? vec3(0, 1, 0) : vec3(1, 0, 0), w));
  vec3 b = cross(w, t);
  float bias = texel * (1.0 + slope_tangent(n, to_light));
  float ref = (dist - bias) / far_m;
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x)
      sum += texture(u_point_shadow_maps, vec4(d + (float(x) * t + float(y) * b) * texel, float(cube)), ref);
  return sum / 9.0;
}

// A directional light with a disc (the sun; light.radiant.w = tan r, r its angular radius):
// the penumbra a blocker at distance b in front of the receiver casts is 2 b tan r wide, so
// (as PCSS does) the mean depth of the blockers in a search window of half-width d tan r (d
// the receiver's depth: the widest any blocker can make) gives b, and a 5x5 grid of compare
// taps spans the penumbra, b tan r either side. Ortho maps only (directional lights).
float shadow_2d_disc(GpuLight light, vec3 p, vec3 n, vec3 to_light) {
  int layer = int(light.cone.z);
  if (layer < 0) return 1.0;
  float tan_r = light.radiant.w;
  vec3 eye = light.shadow_eye.xyz;
  float far_m = light.shadow_eye.w;
  vec3 axis = light.direction_range.xyz;
  float texel = light.shadow_params.y;  // metres per texel of the ortho map
  vec3 po = p + n * texel;
  vec4 clip = light.shadow_view_proj * vec4(po, 1.0);
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return 1.0;
  float d = dot(po - eye, axis);
  float bias = texel * (1.0 + slope_tangent(n, to_light));
  float ref = (d - bias) / far_m;
  vec2 texel_uv = 1.0 / vec2(textureSize(u_shadow_maps, 0).xy);
  float search = clamp(d * tan_r / texel, 1.0, 24.0);  // texels
  float blockers = 0.0, blocker_depth = 0.0;
  for (int y = -2; y <= 2; ++y)
    for (int x = -2; x <= 2; ++x) {
      float z = texture(u_shadow_depths, vec3(uv + vec2(x, y) * (0.5 * search) * texel_uv, float(layer))).r;
      if (z < ref) {
        blockers += 1.0;
        blocker_depth += z;
      }
    }
  if (blockers == 0.0) return 1.0;
  float b = max(d - blocker_depth / blockers * far_m, 0.0);  // receiver - blocker, metres
  float radius = clamp(b * tan_r / texel, 1.0, 24.0);       // penumbra half-width, texels
  float sum = 0.0;
  for (int y = -2; y <= 2; ++y)
    for (int x = -2; x <= 2; ++x)
      sum += texture(u_shadow_maps, vec4(uv + vec2(x, y) * (0.5 * radius) * texel_uv, float(layer), ref));
  return sum / 25.0;
}
