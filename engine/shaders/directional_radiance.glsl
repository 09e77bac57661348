// Specular reflection of incoming light stored per direction bin: the GLSL twin of
// engine/include/engine/directional_radiance.h (the header explains the model; a test keeps
// the two equal). Include after gltf_brdf.glsl.
//
// Data (engine/indirect_light.h, IndirectLightFrame::directional_*):
//   DirectionalDirections  vec4 per bin: xyz the unit direction psi_k, w the bin's layer scale;
//                          with tangent-frame bins (IndirectLightFrame::directional_tangent_frame)
//                          psi_k is in the frame directional_tangent_frame(n_bins) of the surface's
//                          vertex normal, so a lobe sample l reads the bin nearest (l.t, l.b, l.n_bins)
//   DirectionalRadiance    uvec2 per (bin, element), bin-major: packHalf2x16(r, g),
//                          packHalf2x16(b, 0); radiance = unpacked x the bin's scale (W/(m^2 sr))

#ifndef DIRECTIONAL_RADIANCE_BINDING
#define DIRECTIONAL_RADIANCE_BINDING 2
#endif
#ifndef DIRECTIONAL_DIRECTION_BINDING
#define DIRECTIONAL_DIRECTION_BINDING 3
#endif

// Element layouts: engine/indirect_light.h's DirectionalRadiance and DirectionalBin (std430, asserted there).
struct DirectionalRadianceElement {
  uint red_green;  // packHalf2x16(r, g)
  uint blue;       // packHalf2x16(b, 0)
};
struct DirectionalBin {
  vec3 direction;
  float scale;
};
layout(std430, binding = DIRECTIONAL_RADIANCE_BINDING) readonly buffer DirectionalRadiance {
  DirectionalRadianceElement dr_values[];
};
layout(std430, binding = DIRECTIONAL_DIRECTION_BINDING) readonly buffer DirectionalDirections {
  DirectionalBin dr_directions[];
};

vec3 directional_bin_radiance(int bin, int element, int element_count) {
  DirectionalRadianceElement p = dr_values[bin * element_count + element];
  return vec3(unpackHalf2x16(p.red_green), unpackHalf2x16(p.blue).x) * dr_directions[bin].scale;
}

// A point's bilinear footprint over the maps' texels: up to four stored elements (-1: none)
// and their weights (summing to 1 over the elements that exist). The lookup is linear in the
// bins' radiance, so reading the bins blended is the blend of the four texels' lookups: no
// texel blocks, as the light atlas's bilinear irradiance.
struct DirectionalTexels {
  ivec4 element;
  vec4 weight;
};

vec3 directional_bin_radiance(int bin, DirectionalTexels t, int element_count) {
  vec3 sum = vec3(0.0);
  for (int i = 0; i < 4; ++i)
    if (t.weight[i] > 0.0) sum += t.weight[i] * directional_bin_radiance(bin, t.element[i], element_count);
  return sum;
}

const int DIRECTIONAL_LOBE_SAMPLES = 32;  // engine::kDirectionalLobeSamples

vec2 directional_lobe_sample_point(int j) {
  uint bits = uint(j);
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return vec2((float(j) + 0.5) / float(DIRECTIONAL_LOBE_SAMPLES), float(bits) * 2.3283064365386963e-10);
}

// engine::directional_tangent_frame: t = the x axis (y when |n.x| > 0.9) made orthogonal to n, b = n x t.
void directional_tangent_frame(vec3 n, out vec3 t, out vec3 b) {
  t = abs(n.x) > 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
  t = normalize(t - n * dot(n, t));
  b = cross(n, t);
}

// engine::directional_bin_of: the nearest direction (lowest index among equals), the directions
// sorted by non-increasing z; from where l.z would lie among uniform z, outwards on both sides
// until the z gap alone bounds l.psi below the best found (l.psi <= l.z psi.z + |l.xy| |psi.xy|).
// The same scan as the C++ (directional_radiance.cpp's scan_side), so the same bin.
void directional_scan_side(vec3 l, float l_xy, float l_len, int start, int step, int bin_count, inout int best,
                           inout float best_dot) {
  for (int k = start + step; k >= 0 && k < bin_count; k += step) {
    vec3 p = dr_directions[k].direction;
    bool beyond = step > 0 ? p.z * l_len < l.z : p.z * l_len > l.z;
    if (beyond && l.z * p.z + l_xy * sqrt(p.x * p.x + p.y * p.y) < best_dot - 1e-4) break;
    float d = dot(l, p);
    if (d > best_dot || (d == best_dot && k < best)) {
      best_dot = d;
      best = k;
    }
  }
}

int directional_bin_of(vec3 l, int bin_count) {
  if (bin_count <= 0) return -1;
  float l_len = sqrt(dot(l, l));
  float z_first = dr_directions[0].direction.z, z_last = dr_directions[bin_count - 1].direction.z;
  float at = z_first > z_last ? (z_first - l.z / l_len) / (z_first - z_last) * float(bin_count - 1) : 0.0;
  int start = at >= 0.0 ? (at < float(bin_count - 1) ? int(at + 0.5) : bin_count - 1) : 0;
  int best = -1;
  float best_dot = -2.0;
  float d = dot(l, dr_directions[start].direction);
  if (d > best_dot) {
    best_dot = d;
    best = start;
  }
  float l_xy = sqrt(l.x * l.x + l.y * l.y);
  directional_scan_side(l, l_xy, l_len, start, 1, bin_count, best, best_dot);
  directional_scan_side(l, l_xy, l_len, start, -1, bin_count, best, best_dot);
  return best;
}

// L_spec of engine::directional_specular for the bins blended over the footprint `texels`;
// `tangent_bins`: the bins are in the tangent frame of `bin_normal` (unit, the vertex normal).
vec3 directional_specular(GltfBrdf m, vec3 n, vec3 v, DirectionalTexels texels, int bin_count, int element_count,
                          bool tangent_bins, vec3 bin_normal) {
  float a = m.alpha;
  float n_dot_v = max(dot(n, v), 1e-4);
  vec3 t, b;
  directional_tangent_frame(n, t, b);
  vec3 bin_t = vec3(1.0, 0.0, 0.0), bin_b = vec3(0.0, 1.0, 0.0), bin_n = vec3(0.0, 0.0, 1.0);
  if (tangent_bins) {
    bin_n = bin_normal;
    directional_tangent_frame(bin_n, bin_t, bin_b);
  }
  vec3 ve = vec3(dot(v, t), dot(v, b), n_dot_v);
  vec3 vh = normalize(vec3(a * ve.x, a * ve.y, ve.z));
  float lensq = vh.x * vh.x + vh.y * vh.y;
  vec3 t1 = lensq > 1e-7 ? vec3(-vh.y, vh.x, 0.0) * inversesqrt(lensq) : vec3(1.0, 0.0, 0.0);
  vec3 t2 = cross(vh, t1);
  float g1 = 2.0 * n_dot_v / (n_dot_v + sqrt(a * a + (1.0 - a * a) * n_dot_v * n_dot_v));
  vec3 sum_w = vec3(0.0);
  vec3 sum = vec3(0.0);
  for (int j = 0; j < DIRECTIONAL_LOBE_SAMPLES; ++j) {
    vec2 u = directional_lobe_sample_point(j);
    float r = sqrt(u.x);
    float phi = 6.28318530718 * u.y;
    float p1 = r * cos(phi);
    float s = 0.5 * (1.0 + vh.z);
    float p2 = (1.0 - s) * sqrt(max(0.0, 1.0 - p1 * p1)) + s * r * sin(phi);
    vec3 nh = p1 * t1 + p2 * t2 + sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2)) * vh;
    vec3 ne = normalize(vec3(a * nh.x, a * nh.y, max(0.0, nh.z)));
    vec3 h = ne.x * t + ne.y * b + ne.z * n;
    vec3 l = 2.0 * dot(v, h) * h - v;
    float n_dot_l = dot(n, l);
    if (!(n_dot_l > 0.0)) continue;
    vec3 l_bins = tangent_bins ? vec3(dot(l, bin_t), dot(l, bin_b), dot(l, bin_n)) : l;
    int k = directional_bin_of(l_bins, bin_count);
    if (k < 0) continue;
    float fresnel_w = gltf_schlick_weight(dot(v, h));
    vec3 fresnel =
        (1.0 - m.metallic) * m.specular_weight * (m.dielectric_f0 + (vec3(1.0) - m.dielectric_f0) * fresnel_w) +
        m.metallic * (m.base_color + (vec3(1.0) - m.base_color) * fresnel_w);
    vec3 w = fresnel * (4.0 * n_dot_l * n_dot_v * gltf_smith_visibility(n_dot_v, n_dot_l, a) / g1);
    sum_w += w;
    sum += w * directional_bin_radiance(k, texels, element_count);
  }
  vec3 albedo = gltf_directional_albedo(m, dot(n, v)).specular;
  return mix(vec3(0.0), albedo * sum / max(sum_w, vec3(1e-30)), greaterThan(sum_w, vec3(0.0)));
}

// L_spec for stored element `element` alone.
vec3 directional_specular(GltfBrdf m, vec3 n, vec3 v, int element, int bin_count, int element_count, bool tangent_bins,
                          vec3 bin_normal) {
  return directional_specular(m, n, v, DirectionalTexels(ivec4(element, -1, -1, -1), vec4(1.0, 0.0, 0.0, 0.0)),
                              bin_count, element_count, tangent_bins, bin_normal);
}

// The footprint of uv1 point `uv` over the index texture (texel centres at (i + 0.5) / size):
// the four nearest texels with bilinear weights, those without maps dropped and the rest
// renormalized. `nearest` is the element of the texel holding uv (-1: no maps there).
DirectionalTexels directional_footprint(isampler2D index, vec2 uv, out int nearest) {
  ivec2 size = textureSize(index, 0);
  nearest = texelFetch(index, clamp(ivec2(floor(uv * vec2(size))), ivec2(0), size - 1), 0).r;
  vec2 f = uv * vec2(size) - 0.5;
  ivec2 base = ivec2(floor(f));
  vec2 w = f - floor(f);
  DirectionalTexels t;
  float total = 0.0;
  for (int i = 0; i < 4; ++i) {
    ivec2 o = ivec2(i & 1, i >> 1);
    t.element[i] = texelFetch(index, clamp(base + o, ivec2(0), size - 1), 0).r;
    t.weight[i] = t.element[i] >= 0 ? (o.x == 1 ? w.x : 1.0 - w.x) * (o.y == 1 ? w.y : 1.0 - w.y) : 0.0;
    total += t.weight[i];
  }
  t.weight = total > 0.0 ? t.weight / total : vec4(1.0, 0.0, 0.0, 0.0);
  if (!(total > 0.0)) t.element = ivec4(nearest, -1, -1, -1);
  return t;
}
