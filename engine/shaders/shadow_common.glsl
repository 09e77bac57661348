// Shadow-map lookups of the forward pass. Every shadow map stores a linear depth:
// distance from the light / far for point, spot and area lights, distance along the light
// direction / far for directional lights. Filtering: hardware 2x2 compare (bilinear PCF)
// over a 3x3 grid (2-D maps of directional and centre-shadowed area lights) or one tap
// (point lights' cube maps, spot lights' maps); the receiver is offset along its
// normal by one texel and the depth reference is biased by texel * (1 + spacing * tan(theta))
// (slope-scaled).
// Lights with a size are soft-shadowed PCSS-style: the sun's disc (shadow_2d_disc) and
// rectangular area lights (shadow_area) search the map for blockers, then spread their
// compare taps over the light's shape as seen through the blockers' depth.

layout(binding = 4) uniform sampler2DArrayShadow u_shadow_maps;
layout(binding = 5) uniform samplerCubeArrayShadow u_point_shadow_maps;
layout(binding = 12) uniform sampler2DArray u_shadow_depths;  // the same 2-D maps, raw depths
// Directional lights' maps: an array of its own, larger (each covers the whole level).
layout(binding = 10) uniform sampler2DArrayShadow u_sun_shadow_maps;
layout(binding = 11) uniform sampler2DArray u_sun_shadow_depths;  // the same, raw depths

float slope_tangent(vec3 n, vec3 to_light) {
  float n_dot_l = clamp(dot(n, to_light), 0.05, 1.0);
  return min(sqrt(1.0 - n_dot_l * n_dot_l) / n_dot_l, 8.0);
}

// Beyond an area light's 2-D map, which covers 150 degrees around its normal: the grazing band
// its rectangle still lights (75-90 degrees off the normal, e.g. through a wall's far side
// at a grazing angle). There the shadow comes from the cube map of the rectangle's centre
// (GpuLight::cone.w, one bilinear compare tap: a hard shadow from the centre, where the
// emitted light is at most cos 75 = 26% of the normal's). Without a cube (more area lights
// than ShadowCapacity::max_area_cubes): unshadowed, as before.
float shadow_area_grazing(GpuLight light, vec3 p, vec3 n, vec3 to_light) {
  int cube = int(light.cone.w);
  if (cube < 0) return 1.0;
  vec3 eye = light.shadow_eye.xyz;
  float texel = light.shadow_params.w * length(p - eye);
  vec3 d = p + n * texel - eye;
  float bias = texel * (1.0 + slope_tangent(n, to_light));
  return texture(u_point_shadow_maps, vec4(d, float(cube)), (length(d) - bias) / light.shadow_eye.w);
}

// A 3x3 grid of bilinear compare taps `spacing` texels apart (1: 4x4 texel footprint,
// 2: 6x6, the softened area-light kernel). `spacing` and `area` (an area light: beyond the
// map, its grazing band's cube) are passed as literals.
float shadow_2d_in(sampler2DArrayShadow maps, GpuLight light, vec3 p, vec3 n, vec3 to_light, float spacing, bool area) {
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
  // Beyond the map: an area light's grazing band (its centre-shadowed variant), else unshadowed.
  float beyond = area ? shadow_area_grazing(light, p, n, to_light) : 1.0;
  if (clip.w <= 0.0) return beyond;
  vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) return beyond;
  float d = ortho ? dot(po - eye, axis) : length(po - eye);
  float bias = texel * (1.0 + spacing * slope_tangent(n, to_light));
  float ref = (d - bias) / far_m;
  vec2 texel_uv = 1.0 / vec2(textureSize(maps, 0).xy);
  float sum = 0.0;
  for (int y = -1; y <= 1; ++y)
    for (int x = -1; x <= 1; ++x) sum += texture(maps, vec4(uv + vec2(x, y) * spacing * texel_uv, float(layer), ref));
  return sum / 9.0;
}
// Spot and area lights' maps.
float shadow_2d(GpuLight light, vec3 p, vec3 n, vec3 to_light, float spacing, bool area) {
  return shadow_2d_in(u_shadow_maps, light, p, n, to_light, spacing, area);
}
// A directional light without a disc (a point sun): its own array, the 4 x 4 texel footprint.
float shadow_2d_sun(GpuLight light, vec3 p, vec3 n, vec3 to_light) {
  return shadow_2d_in(u_sun_shadow_maps, light, p, n, to_light, 1.0, false);
}

// Where a receiver p (normal n) falls in a light's perspective 2-D map (spot and area lights):
// p offset along n by one texel at its distance, in the map's clip space and uv. False when
// it falls outside the map or behind the eye.
struct MapLookup {
  vec3 eye;     // the map's eye (m)
  float far_m;  // the distance that maps to depth 1 (m)
  float texel;  // one texel's footprint at p (m)
  vec3 po;      // p offset along its normal by one texel
  vec4 clip;    // po in the map's clip space
  vec2 uv;
};
bool perspective_lookup(GpuLight light, vec3 p, vec3 n, out MapLookup m) {
  m.eye = light.shadow_eye.xyz;
  m.far_m = light.shadow_eye.w;
  m.texel = light.shadow_params.y * length(p - m.eye);
  m.po = p + n * m.texel;
  m.clip = light.shadow_view_proj * vec4(m.po, 1.0);
  if (m.clip.w <= 0.0) return false;
  m.uv = m.clip.xy / m.clip.w * 0.5 + 0.5;
  return !(any(lessThan(m.uv, vec2(0.0))) || any(greaterThan(m.uv, vec2(1.0))));
}

// A spot light's 2-D map: one bilinear compare tap. The spot is a point source, its shadow
// hard: the bilinear weights anti-alias the edge (shadow_2d's 3 x 3 grid widened it to 4 x 4
// texels for 9 lookups on every pixel the flashlight covers).
float shadow_2d_point(GpuLight light, vec3 p, vec3 n, vec3 to_light) {
  int layer = int(light.cone.z);
  if (layer < 0) return 1.0;
  MapLookup m;
  if (!perspective_lookup(light, p, n, m)) return 1.0;
  float bias = m.texel * (1.0 + slope_tangent(n, to_light));
  return texture(u_shadow_maps, vec4(m.uv, float(layer), (length(m.po - m.eye) - bias) / m.far_m));
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
  float bias = texel * (1.0 + slope_tangent(n, to_light));
  float ref = (dist - bias) / far_m;
  // One bilinear compare tap (a 2 x 2 texel footprint). A point light's shadow is hard: the
  // bilinear weights only anti-alias its edge. Cube-array compare lookups are the costliest
  // taps on llvmpipe: a 2 x 2 grid of them 1.5 texels apart (the previous filter) cost ~10%
  // of the demo level's frame CPU for a wider, softer edge than a point light casts
  // (docs/performance-frame.md).
  return texture(u_point_shadow_maps, vec4(d, float(cube)), ref);
}

// Points spread uniformly over the unit disc (Vogel's spiral, golden-angle steps): the
// fraction of them behind a straight edge follows the fraction of the disc's area there,
// so a filter over them has the penumbra profile of a disc-shaped light.
const vec2 kDisc16[16] =
    vec2[16](vec2(0.1768, 0.0000), vec2(-0.2258, 0.2068), vec2(0.0346, -0.3938), vec2(0.2846, 0.3712),
             vec2(-0.5222, -0.0924), vec2(0.4947, -0.3147), vec2(-0.1655, 0.6155), vec2(-0.3156, -0.6076),
             vec2(0.6846, 0.2500), vec2(-0.7123, 0.2940), vec2(0.3434, -0.7337), vec2(0.2537, 0.8089),
             vec2(-0.7647, -0.4432), vec2(0.8971, -0.1972), vec2(-0.5475, 0.7788), vec2(-0.1265, -0.9761));
const vec2 kDisc24[24] = vec2[24](
    vec2(0.1443, 0.0000), vec2(-0.1843, 0.1689), vec2(0.0282, -0.3215), vec2(0.2324, 0.3031), vec2(-0.4264, -0.0754),
    vec2(0.4039, -0.2569), vec2(-0.1351, 0.5026), vec2(-0.2577, -0.4961), vec2(0.5590, 0.2041), vec2(-0.5816, 0.2401),
    vec2(0.2803, -0.5991), vec2(0.2072, 0.6605), vec2(-0.6244, -0.3619), vec2(0.7325, -0.1610), vec2(-0.4470, 0.6359),
    vec2(-0.1033, -0.7970), vec2(0.6340, 0.5343), vec2(-0.8532, 0.0353), vec2(0.6223, -0.6193), vec2(-0.0416, 0.9004),
    vec2(-0.5922, -0.7096), vec2(0.9380, 0.1262), vec2(-0.7948, 0.5530), vec2(0.2172, -0.9654));

// A directional light with a disc (the sun; light.radiant.w = tan r, r its angular radius):
// the penumbra a blocker at distance b in front of the receiver casts is 2 b tan r wide, so
// (as PCSS does) the mean depth of the blockers in a search disc of radius d tan r (d the
// receiver's depth: the widest any blocker can make) gives b, and 24 compare taps spread
// uniformly over a disc of radius b tan r (kDisc24) average the visibility of the sun's
// disc: their fraction behind an edge follows the disc's area, so the 10-90% width of the
// edge is the disc's 1.37 b tan r (a square grid of taps spread it over 2 b tan r).
// Ortho maps only (directional lights). The search and the taps reach at most 192 texels
// (a 5 degree disc 1 m behind its blocker on a 4 m scene at 4096 texels: 87): the tap count
// is fixed, so the cap only bounds how sparse the taps get on a huge penumbra.
const float kSunMaxTexels = 192.0;
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
  vec2 texel_uv = 1.0 / vec2(textureSize(u_sun_shadow_maps, 0).xy);
  float search = clamp(d * tan_r / texel, 1.0, kSunMaxTexels);  // texels
  float blockers = 0.0, blocker_depth = 0.0;
  for (int i = 0; i < 16; ++i) {
    float z = texture(u_sun_shadow_depths, vec3(uv + kDisc16[i] * search * texel_uv, float(layer))).r;
    if (z < ref) {
      blockers += 1.0;
      blocker_depth += z;
    }
  }
  if (blockers == 0.0) return 1.0;
  float b = max(d - blocker_depth / blockers * far_m, 0.0);     // receiver - blocker, metres
  float radius = clamp(b * tan_r / texel, 1.0, kSunMaxTexels);  // penumbra half-width, texels
  float sum = 0.0;
  for (int i = 0; i < 24; ++i)
    sum += texture(u_sun_shadow_maps, vec4(uv + kDisc24[i] * radius * texel_uv, float(layer), ref));
  return sum / 24.0;
}

// 12 points over the square [-1, 1]^2, one in each row and each column of a 12 x 12 grid
// (a rank-1 lattice, row 5 i mod 12), so a penumbra along either axis of a rectangle gets 12
// steps (a 4 x 3 grid would give 3 or 4), smoothed by each tap's bilinear compare.
const vec2 kRect12[12] =
    vec2[12](vec2(-0.9167, -0.9167), vec2(-0.7500, -0.0833), vec2(-0.5833, 0.7500), vec2(-0.4167, -0.4167),
             vec2(-0.2500, 0.4167), vec2(-0.0833, -0.7500), vec2(0.0833, 0.0833), vec2(0.2500, 0.9167),
             vec2(0.4167, -0.2500), vec2(0.5833, 0.5833), vec2(0.7500, -0.5833), vec2(0.9167, 0.2500));
// Where the blocker search gathers 2 x 2 texels: the receiver's own texels, then two rotated
// rings over the rectangle's disc (a ring alone misses a blocker smaller than its radius).
const vec2 kSearch9[9] =
    vec2[9](vec2(0.0, 0.0), vec2(-0.15, -0.45), vec2(0.45, -0.15), vec2(0.15, 0.45), vec2(-0.45, 0.15),
            vec2(-0.35, -1.05), vec2(1.05, -0.35), vec2(0.35, 1.05), vec2(-1.05, 0.35));

// Rectangular area light, soft-shadowed over its rectangle (PCSS). The light's 2-D map is a
// perspective distance map from the rectangle's centre c. The light's point
// c + s hx + t hy (s, t in [-1, 1]) is hidden from the receiver p (at distance d) by a
// blocker at distance b from c where the segment between them crosses it. Clip space is
// linear along the segment and the rectangle lies in the eye's plane (w = 0), so that
// crossing is at uv_p + k (s ax + t ay), k = (d - b) / b, ax and ay the half axes projected
// at the receiver. A blocker search over the rectangle's footprint (9 gathers of 2 x 2
// depths, at the k of a blocker kAreaSearchTexels away) gives the mean blocker distance,
// then 12 compare taps over the footprint at that k average the visibility of 12 points of
// the light. Each tap compares against the receiver's tangent plane (its depth along the
// tap's ray from c, linear in s and t), so a wide footprint on a slanted receiver does not
// shadow the receiver itself. On llvmpipe every fragment pays every tap (no branch skips
// work), so the tap counts are the cost: 21 lookups against the centre filter's 9.
// How far from the light's centre the ray towards `ray` meets the receiver's tangent plane
// (normal n, at `plane` = dot(n, receiver - centre), negative when the centre is in front of
// the receiver): the depth a tap off the receiver's own texel compares against, so a slanted
// receiver does not shadow itself. The receiver's distance d when the centre is behind the
// plane or the ray nearly parallel to it.
float receiver_plane_distance(vec3 ray, vec3 n, float plane, float d) {
  float along = dot(n, ray);
  return plane < 0.0 && along < 0.25 * plane ? plane * length(ray) / along : d;
}

const float kAreaSearchTexels = 24.0;
const float kAreaFilterTexels = 32.0;
float shadow_area(GpuLight light, vec3 p, vec3 n, vec3 to_light) {
  int layer = int(light.cone.z);
  if (layer < 0) return 1.0;
  MapLookup m;
  if (!perspective_lookup(light, p, n, m)) return shadow_area_grazing(light, p, n, to_light);
  float far_m = m.far_m, texel = m.texel;
  vec4 clip = m.clip;
  vec2 uv = m.uv;
  vec3 rel = m.po - m.eye;
  float d = length(rel);
  float bias = texel * (1.0 + slope_tangent(n, to_light));
  vec2 size = vec2(textureSize(u_shadow_maps, 0).xy);
  vec3 hx = light.area_half_x.xyz;
  vec3 hy = light.area_half_y.xyz;
  vec2 ax = 0.5 * (light.shadow_view_proj * vec4(hx, 0.0)).xy / clip.w;
  vec2 ay = 0.5 * (light.shadow_view_proj * vec4(hy, 0.0)).xy / clip.w;
  float reach = max(length((abs(ax) + abs(ay)) * size), 1e-4);  // texels of the footprint's half-extent at k = 1
  float k_search = kAreaSearchTexels / reach;
  float plane = dot(n, rel);  // the receiver's tangent plane (through po)
  float blockers = 0.0, blocker_depth = 0.0;
  for (int i = 0; i < 9; ++i) {
    vec2 st = kSearch9[i];
    float r = (receiver_plane_distance(rel + k_search * (st.x * hx + st.y * hy), n, plane, d) - bias) / far_m;
    vec4 z = textureGather(u_shadow_depths, vec3(uv + k_search * (st.x * ax + st.y * ay), float(layer)));
    vec4 hit = vec4(lessThan(z, vec4(r)));
    blockers += dot(hit, vec4(1.0));
    blocker_depth += dot(hit, z);
  }
  if (blockers == 0.0) return 1.0;
  float b = max(blocker_depth / blockers * far_m, 1e-3);
  float k = clamp((d - b) / b, 1.0 / reach, kAreaFilterTexels / reach);
  float ds = receiver_plane_distance(rel + k * hx, n, plane, d) - d;
  float dt = receiver_plane_distance(rel + k * hy, n, plane, d) - d;
  float sum = 0.0;
  for (int i = 0; i < 12; ++i) {
    vec2 st = kRect12[i];
    float tap_ref = (d + st.x * ds + st.y * dt - bias) / far_m;
    sum += texture(u_shadow_maps, vec4(uv + k * (st.x * ax + st.y * ay), float(layer), tap_ref));
  }
  return sum / 12.0;
}
