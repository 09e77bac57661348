// Reflection probes (engine/indirect_light.h, IndirectLightFrame::reflection_probe_*): the
// specular lobe's indirect light from prefiltered, parallax-corrected cube maps, blended per
// pixel (docs/reflection_probes.md). Include after lighting_common.glsl.
//
// Per pixel: the probes whose box holds the point (grown by PROBE_BOX_MARGIN_M, so the floor
// and walls the box was fitted to are inside it) each give their radiance along the
// reflection direction corrected for parallax, by the capture's own distances when the probes
// carry them (gi's distance_corrected_direction, probe_cube.h: the box first where the probe
// saw the box's side, else a distance-impostor search along the ray), else by the box
// (box_projected_direction), read at
// mip roughness x (levels - 1); they are blended by probe_weight (equal inside a room, faded
// across the overlap of a corridor's segments) times probe_visibility (a probe that did not see
// the point weighs 1e-3: a second viewpoint in the same box takes it). The split sum multiplies
// that by the specular lobe's directional albedo (gltf_directional_albedo: Karis 2013's
// environment BRDF). No probe holds the point: the caller keeps its specular.

#ifndef REFLECTION_PROBE_BINDING
#define REFLECTION_PROBE_BINDING 8
#endif
#ifndef REFLECTION_PROBE_UNIT
#define REFLECTION_PROBE_UNIT 16
#endif
#ifndef REFLECTION_PROBE_DISTANCE_UNIT
#define REFLECTION_PROBE_DISTANCE_UNIT 17
#endif

const float PROBE_BOX_MARGIN_M = 0.05;
// gi's probe_placement.h: kProbeFadeM (how far a corridor's segments reach into each other).
const float PROBE_FADE_M = 0.5;

// engine/indirect_light.h's ReflectionProbeBox (std430, asserted there).
struct ReflectionProbeBox {
  vec4 centre;
  vec4 box_min;
  vec4 box_max;
};
layout(std430, binding = REFLECTION_PROBE_BINDING) readonly buffer ReflectionProbes { ReflectionProbeBox rp_probes[]; };
layout(binding = REFLECTION_PROBE_UNIT) uniform samplerCubeArray u_probe_cubes;
layout(binding = REFLECTION_PROBE_DISTANCE_UNIT) uniform samplerCubeArray u_probe_distances;
uniform int u_probe_count;
uniform int u_probe_has_distances;  // 1: u_probe_distances holds each probe's level-0 distances
uniform int u_probe_levels;
uniform float u_probe_max_roughness;
uniform int u_probe_lobe_samples;      // 0: the split sum's single read; 1..PROBE_MAX_LOBE_SAMPLES: probe_lobe
uniform int u_probe_lobe_samples_max;  // the most a grazing view takes (probe_lobe_count)

// gi's probe_cube.h: kProbeSearchSteps, kProbeSecantSteps, kProbeMinSearchScaleM.
const int PROBE_SEARCH_STEPS = 12;
const int PROBE_SECANT_STEPS = 3;
const float PROBE_MIN_SEARCH_SCALE_M = 0.05;
// gi's probe_cube.h: kProbeBoxSideTolerance (the box first: the probe saw its side there).
const float PROBE_BOX_SIDE_TOLERANCE = 0.1;
// gi's probe_cube.h: kProbeRimNearest (the box first at an opening's rim).
const bool PROBE_RIM_NEAREST = true;
// gi's probe_cube.h: kProbeOpeningLevelBias (levels read finer beyond the box's side, an opening).
const float PROBE_OPENING_LEVEL_BIAS = 1.0;
// gi's probe_cube.h: kProbeLobeLevelBias (levels every lobe sample reads finer than its width asks).
const float PROBE_LOBE_LEVEL_BIAS = 0.5;
// gi's probe_cube.h: kProbeMaxLobeSamples.
const int PROBE_MAX_LOBE_SAMPLES = 64;

// The lobe samples a view at cos theta_v = nv takes (gi's probe_lobe_sample_count): the base count
// doubled while the count times nv stays below it, up to u_probe_lobe_samples_max.
int probe_lobe_count(float nv) {
  int base = clamp(u_probe_lobe_samples, 1, PROBE_MAX_LOBE_SAMPLES);
  int cap = clamp(u_probe_lobe_samples_max, base, PROBE_MAX_LOBE_SAMPLES);
  float c = clamp(nv, 0.0, 1.0);
  int count = base;
  while (count * 2 <= cap && float(count) * c < float(base)) count *= 2;
  return count;
}

// Where the ray from p (clamped onto the box) along r leaves the box (gi's box_exit).
vec3 probe_box_exit(vec3 p, vec3 r, ReflectionProbeBox probe) {
  vec3 q = clamp(p, probe.box_min.xyz, probe.box_max.xyz);
  vec3 far_side = mix(probe.box_min.xyz, probe.box_max.xyz, step(vec3(0.0), r));
  vec3 t = (far_side - q) / mix(vec3(1e-20), r, notEqual(r, vec3(0.0)));
  t = mix(t, vec3(1e30), equal(r, vec3(0.0)));
  return q + min(t.x, min(t.y, t.z)) * r;
}

// The direction from the probe's centre to where the ray from p along r leaves the box.
vec3 probe_box_direction(vec3 p, vec3 r, ReflectionProbeBox probe) {
  vec3 d = probe_box_exit(p, r, probe) - probe.centre.xyz;
  return dot(d, d) > 1e-12 ? d : r;
}

// Behind (> 0) or in front of (< 0) the surface probe i saw in the direction of q (from its centre).
float probe_behind(vec3 q, int i) { return length(q) - textureLod(u_probe_distances, vec4(q, float(i)), 0.0).r; }

// The nearest (x) and farthest (y) of the four distance texels the bilinear read of probe i
// blends in the direction of q (gi's cube_distance_footprint).
vec2 probe_distance_footprint(vec3 q, int i) {
  vec4 d = textureGather(u_probe_distances, vec4(q, float(i)));
  return vec2(min(min(d.x, d.y), min(d.z, d.w)), max(max(d.x, d.y), max(d.z, d.w)));
}

// The box first at an opening's rim (gi's rim_is_side): the ray x + t r leaves the box at t_exit,
// where the bilinear mean distance is `mean`; whether the exit's texels that saw the box's side
// there weigh at least half, and the ray passes behind that side (there, or within the tolerance past it).
bool probe_rim_is_side(vec3 x, vec3 r, float t_exit, float mean, float tolerance, int i) {
  vec3 q = x + t_exit * r;
  vec2 f = probe_distance_footprint(q, i);
  if (mean > 0.5 * (f.x + f.y)) return false;
  float g = length(q) - f.x;
  if (g >= 0.0) return g <= tolerance;
  vec3 beyond = x + (t_exit + tolerance) * r;
  return g >= -tolerance && length(beyond) >= probe_distance_footprint(beyond, i).x;
}

// The direction from the probe's centre to where the ray from p along r meets the surface the
// probe captured (distance_corrected_direction in gi's probe_cube.cpp, the same search).
vec3 probe_direction(vec3 p, vec3 r, ReflectionProbeBox probe, int i) {
  vec3 boxed = probe_box_direction(p, r, probe);
  if (u_probe_has_distances == 0) return boxed;
  vec3 x = p - probe.centre.xyz;
  float scale = max(length(x), PROBE_MIN_SEARCH_SCALE_M);
  float t_lo = 0.0, g_lo = 0.0, t0 = 0.0;
  bool in_front = false;
  // The box first: the probe saw its side where the ray leaves it (the ray passes behind the
  // surface there), or (farther, or a surface the ray grazes) an opening, searched on from the side.
  float t_exit = dot(probe_box_exit(p, r, probe) - p, r);
  float g_exit = probe_behind(x + t_exit * r, i), exit_distance = length(x + t_exit * r);
  float tolerance = PROBE_BOX_SIDE_TOLERANCE * exit_distance;
  // An object the ray passes clearly behind before the exit: the search as before.
  bool blocked = false, front = false;
  for (int k = 1; k <= PROBE_SEARCH_STEPS && !blocked; ++k) {
    float a = float(k) / float(PROBE_SEARCH_STEPS + 1);
    float t = scale * a / (1.0 - a);
    if (t >= t_exit) break;
    float g = probe_behind(x + t * r, i);
    if (g < 0.0)
      front = true;
    else if (front && g > PROBE_BOX_SIDE_TOLERANCE * length(x + t * r))
      blocked = true;
  }
  if (!blocked && g_exit >= 0.0 && g_exit <= tolerance) return boxed;
  if (!blocked && g_exit < 0.0 && g_exit >= -tolerance && probe_behind(x + (t_exit + tolerance) * r, i) >= 0.0)
    return boxed;
  // At an opening's rim the mean distances mix the side's and the far room's (a thin jamb beside it).
  if (PROBE_RIM_NEAREST && !blocked && g_exit < -tolerance &&
      probe_rim_is_side(x, r, t_exit, exit_distance - g_exit, tolerance, i))
    return boxed;
  if (!blocked && g_exit < 0.0) {
    t0 = t_exit;
    t_lo = t_exit;
    g_lo = g_exit;
    in_front = true;
    scale = max(exit_distance, PROBE_MIN_SEARCH_SCALE_M);
  }
  for (int k = 1; k <= PROBE_SEARCH_STEPS; ++k) {
    float a = float(k) / float(PROBE_SEARCH_STEPS + 1);
    float t = t0 + scale * a / (1.0 - a);
    float g = probe_behind(x + t * r, i);
    if (g < 0.0) {
      t_lo = t;
      g_lo = g;
      in_front = true;
      continue;
    }
    if (!in_front) continue;
    float t_hi = t, g_hi = g;
    for (int j = 0; j < PROBE_SECANT_STEPS; ++j) {
      float tm = t_lo + (t_hi - t_lo) * g_lo / (g_lo - g_hi);
      float gm = probe_behind(x + tm * r, i);
      if (gm < 0.0) {
        t_lo = tm;
        g_lo = gm;
      } else {
        t_hi = tm;
        g_hi = gm;
      }
    }
    vec3 q = x + (t_lo + (t_hi - t_lo) * g_lo / (g_lo - g_hi)) * r;
    return dot(q, q) > 1e-12 ? q : r;
  }
  return in_front ? r : boxed;
}

// Whether probe i saw beyond its box's side in direction d (gi's beyond_box_side): the captured
// distance more than the box-side tolerance past where the ray from the centre along d leaves the box.
bool probe_beyond_side(vec3 d, ReflectionProbeBox probe, int i) {
  vec3 dn = normalize(d);
  float side = length(probe_box_exit(probe.centre.xyz, dn, probe) - probe.centre.xyz);
  return textureLod(u_probe_distances, vec4(dn, float(i)), 0.0).r > side * (1.0 + PROBE_BOX_SIDE_TOLERANCE);
}

// The specular lobe at the view read from probe i by filtered importance sampling (gi's
// probe_lobe_radiance, probe_cube.cpp, the same samples and weights): u_probe_lobe_samples half
// vectors from GGX's visible normals at v (Hammersley points), each reflected direction
// corrected for parallax and read at the level prefiltered for the sample's share of the lobe
// (its solid angle 1 / (count pdf), narrowed across the reflection's plane by v.h); weighted by F G2 / G1 and
// normalized per channel (the caller multiplies by the directional albedo, as with the split sum).
vec3 probe_lobe(Surface s, ReflectionProbeBox probe, int i, int count) {
  float alpha = s.brdf.alpha, a2 = alpha * alpha;
  vec3 n = s.normal, v = s.view;
  float nv = max(dot(n, v), 1e-4);
  vec3 t = v - nv * n;
  if (dot(t, t) < 1e-8) t = cross(abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0), n);
  t = normalize(t);
  vec3 b = cross(n, t);
  vec3 vh = normalize(vec3(alpha * dot(v, t), 0.0, nv));
  float g1 = 2.0 * nv / (nv + sqrt(a2 + (1.0 - a2) * nv * nv));
  float top_level = float(max(u_probe_levels - 1, 0));
  float fn = float(count);
  float dielectric = (1.0 - s.brdf.metallic) * s.brdf.specular_weight;
  vec3 sum = vec3(0.0), weight = vec3(0.0);
  for (int k = 0; k < PROBE_MAX_LOBE_SAMPLES; ++k) {
    if (k >= count) break;
    float phi = 2.0 * GLTF_PI * (float(k) + 0.5) / fn;
    float u = float(bitfieldReverse(uint(k))) * 2.3283064365386963e-10 + 0.5 / fn;
    float z = (1.0 - u) * (1.0 + vh.z) - vh.z;
    float sin_t = sqrt(clamp(1.0 - z * z, 0.0, 1.0));
    vec3 c = vec3(sin_t * cos(phi), sin_t * sin(phi), z) + vh;
    vec3 hl = normalize(vec3(alpha * c.x, alpha * c.y, max(c.z, 0.0)));
    vec3 h = hl.x * t + hl.y * b + hl.z * n;
    float vdh = dot(v, h);
    vec3 l = 2.0 * vdh * h - v;
    float nl = dot(n, l);
    if (!(nl > 0.0) || !(vdh > 0.0)) continue;
    float pdf = g1 * gltf_ggx_distribution(clamp(hl.z, 0.0, 1.0), alpha) / (4.0 * nv);
    float lod = max(sqrt(sqrt(vdh / (fn * max(pdf, 1e-12) * 4.0 * GLTF_PI))) * top_level - PROBE_LOBE_LEVEL_BIAS, 0.0);
    float w = gltf_schlick_weight(vdh);
    vec3 f = dielectric * (s.brdf.dielectric_f0 + (vec3(1.0) - s.brdf.dielectric_f0) * w) +
             s.brdf.metallic * (s.brdf.base_color + (vec3(1.0) - s.brdf.base_color) * w);
    vec3 wi = f * (gltf_smith_visibility(nv, nl, alpha) * nl);
    vec3 d = probe_direction(s.position, l, probe, i);
    if (PROBE_OPENING_LEVEL_BIAS > 0.0 && u_probe_has_distances != 0 && probe_beyond_side(d, probe, i))
      lod = max(lod - PROBE_OPENING_LEVEL_BIAS, 0.0);
    sum += wi * textureLod(u_probe_cubes, vec4(d, float(i)), lod).rgb;
    weight += wi;
  }
  bvec3 some = greaterThan(weight, vec3(0.0));
  if (all(some)) return sum / weight;
  vec3 fallback = textureLod(u_probe_cubes, vec4(probe_direction(s.position, reflect(-v, n), probe, i), float(i)),
                             sqrt(alpha) * top_level)
                      .rgb;
  return mix(fallback, sum / max(weight, vec3(1e-30)), vec3(some));
}

// Whether this surface reads the probes: static ones that read the atlas (`atlas`) below the
// roughness limit, dynamic ones (`dynamic`) at any roughness.
bool reads_probes(Surface s, bool atlas, bool dynamic) {
  return u_probe_count > 0 && (dynamic || (atlas && s.brdf.alpha < u_probe_max_roughness * u_probe_max_roughness));
}

// Probe i's weight at p in the blend (gi's probe_blend_weight, probe_placement.cpp): 0 outside
// its box grown by the margin, else the product over the axes of clamp(depth / PROBE_FADE_M,
// 1e-3, 1), depth the distance from the box's nearer side; the sides every box holding p shares cancel in the
// normalization, and across two segments' overlap the weights fade linearly from one to the next.
float probe_weight(vec3 p, ReflectionProbeBox probe) {
  if (any(lessThan(p, probe.box_min.xyz - PROBE_BOX_MARGIN_M)) ||
      any(greaterThan(p, probe.box_max.xyz + PROBE_BOX_MARGIN_M)))
    return 0.0;
  vec3 depth = min(p - probe.box_min.xyz, probe.box_max.xyz - p);
  vec3 f = clamp(depth / PROBE_FADE_M, vec3(1e-3), vec3(1.0));
  return f.x * f.y * f.z;
}

// gi's probe_cube.h: kProbeHiddenWeight, kProbeSeesSlackM (a second viewpoint where the first is blocked).
const float PROBE_HIDDEN_WEIGHT = 1e-3;
const float PROBE_SEES_SLACK_M = 0.05;

// Whether probe i saw p (gi's probe_visibility_weight): 1 where its captured distance towards p is
// at least |p - centre| (1 - the box-side tolerance) - the slack, else PROBE_HIDDEN_WEIGHT. Where two
// probes share a box, a point one did not see takes the other's light.
float probe_visibility(vec3 p, ReflectionProbeBox probe, int i) {
  if (u_probe_has_distances == 0) return 1.0;
  vec3 x = p - probe.centre.xyz;
  float len = length(x);
  if (!(len > 0.0)) return 1.0;
  float seen = textureLod(u_probe_distances, vec4(x, float(i)), 0.0).r;
  return seen >= len * (1.0 - PROBE_BOX_SIDE_TOLERANCE) - PROBE_SEES_SLACK_M ? 1.0 : PROBE_HIDDEN_WEIGHT;
}

// The probes' specular at s, given the lobe's directional albedo; false where no box holds it.
bool probe_specular(Surface s, vec3 specular_albedo, out vec3 specular) {
  specular = vec3(0.0);
  vec3 r = reflect(-s.view, s.normal);
  float lod = sqrt(s.brdf.alpha) * float(max(u_probe_levels - 1, 0));
  int count = u_probe_lobe_samples > 0 ? probe_lobe_count(dot(s.normal, s.view)) : 0;
  vec3 sum = vec3(0.0);
  float weight = 0.0;
  for (int i = 0; i < u_probe_count; ++i) {
    ReflectionProbeBox probe = rp_probes[i];
    float w = probe_weight(s.position, probe);
    if (w <= 0.0) continue;
    w *= probe_visibility(s.position, probe, i);
    if (u_probe_lobe_samples > 0)
      sum += w * probe_lobe(s, probe, i, count);
    else
      sum += w * textureLod(u_probe_cubes, vec4(probe_direction(s.position, r, probe, i), float(i)), lod).rgb;
    weight += w;
  }
  if (weight <= 0.0) return false;
  specular = sum / weight * specular_albedo;
  return true;
}
