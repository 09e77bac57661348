// Reflection probes (engine/indirect_light.h, IndirectLightFrame::reflection_probe_*): the
// specular lobe's indirect light from prefiltered, parallax-corrected cube maps, blended per
// pixel (docs/reflection_probes.md). Include after lighting_common.glsl.
//
// Per pixel: the probes whose box holds the point (grown by PROBE_BOX_MARGIN_M, so the floor
// and walls the box was fitted to are inside it) each give their radiance along the
// reflection direction corrected for parallax, by the capture's own distances when the probes
// carry them (gi's distance_corrected_direction, probe_cube.h: a distance-impostor search
// along the ray), else by the box (box_projected_direction), read at
// mip roughness x (levels - 1); they are averaged with equal weights. The split sum multiplies
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

// gi's probe_cube.h: kProbeSearchSteps, kProbeSecantSteps, kProbeMinSearchScaleM.
const int PROBE_SEARCH_STEPS = 12;
const int PROBE_SECANT_STEPS = 3;
const float PROBE_MIN_SEARCH_SCALE_M = 0.05;

// The direction from the probe's centre to where the ray from p along r leaves the box.
vec3 probe_box_direction(vec3 p, vec3 r, ReflectionProbeBox probe) {
  vec3 q = clamp(p, probe.box_min.xyz, probe.box_max.xyz);
  vec3 far_side = mix(probe.box_min.xyz, probe.box_max.xyz, step(vec3(0.0), r));
  vec3 t = (far_side - q) / mix(vec3(1e-20), r, notEqual(r, vec3(0.0)));
  t = mix(t, vec3(1e30), equal(r, vec3(0.0)));
  vec3 d = q + min(t.x, min(t.y, t.z)) * r - probe.centre.xyz;
  return dot(d, d) > 1e-12 ? d : r;
}

// Behind (> 0) or in front of (< 0) the surface probe i saw in the direction of q (from its centre).
float probe_behind(vec3 q, int i) { return length(q) - textureLod(u_probe_distances, vec4(q, float(i)), 0.0).r; }

// The direction from the probe's centre to where the ray from p along r meets the surface the
// probe captured (distance_corrected_direction in gi's probe_cube.cpp, the same search).
vec3 probe_direction(vec3 p, vec3 r, ReflectionProbeBox probe, int i) {
  vec3 boxed = probe_box_direction(p, r, probe);
  if (u_probe_has_distances == 0) return boxed;
  vec3 x = p - probe.centre.xyz;
  float scale = max(length(x), PROBE_MIN_SEARCH_SCALE_M);
  float t_lo = 0.0, g_lo = 0.0;
  bool in_front = false;
  for (int k = 1; k <= PROBE_SEARCH_STEPS; ++k) {
    float a = float(k) / float(PROBE_SEARCH_STEPS + 1);
    float t = scale * a / (1.0 - a);
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

// Whether this surface reads the probes: static ones that read the atlas (`atlas`) below the
// roughness limit, dynamic ones (`dynamic`) at any roughness.
bool reads_probes(Surface s, bool atlas, bool dynamic) {
  return u_probe_count > 0 && (dynamic || (atlas && s.brdf.alpha < u_probe_max_roughness * u_probe_max_roughness));
}

// The probes' specular at s, given the lobe's directional albedo; false where no box holds it.
bool probe_specular(Surface s, vec3 specular_albedo, out vec3 specular) {
  specular = vec3(0.0);
  vec3 r = reflect(-s.view, s.normal);
  float lod = sqrt(s.brdf.alpha) * float(max(u_probe_levels - 1, 0));
  vec3 sum = vec3(0.0);
  float count = 0.0;
  for (int i = 0; i < u_probe_count; ++i) {
    ReflectionProbeBox probe = rp_probes[i];
    if (any(lessThan(s.position, probe.box_min.xyz - PROBE_BOX_MARGIN_M)) ||
        any(greaterThan(s.position, probe.box_max.xyz + PROBE_BOX_MARGIN_M)))
      continue;
    sum += textureLod(u_probe_cubes, vec4(probe_direction(s.position, r, probe, i), float(i)), lod).rgb;
    count += 1.0;
  }
  if (count == 0.0) return false;
  specular = sum / count * specular_albedo;
  return true;
}
