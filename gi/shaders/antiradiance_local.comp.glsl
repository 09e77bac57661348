#version 450 core
// Local pass (Dachsbacher et al. 2007 §3.1 eq. 18-19, diffuse BRDF), one invocation per leaf:
// (L = L_in at the leaf's node after push: all the light arriving at the leaf)
//   E        = sum_b <n|-w_b>+ omega_b L[b]                      (gathered indirect irradiance)
//   I_L[b]   = a <n|w_b>+ albedo/pi (E + E_direct)               when u_radiance   (operator K)
//   I_A[b]   = a <n|-w_b>+ L[b]                                  when u_antiradiance (operator J)
//   I_ex[b]  = I_L[b] - I_A[b] at the leaf's node
// and the leaf's residual terms sum_b |I_ex new - I_ex old| and sum_b |I_ex new| (float,
// bins then channels; the host sums the leaves in double). The twin of
// CpuAntiradiancePasses::local.

#include "antiradiance_common.glsl"

struct Leaf {
  vec4 normal_area;  // unit normal, area m^2
  vec4 albedo;       // rgb, 0
  vec4 direct;       // direct irradiance W/m^2
};

layout(std430, binding = 0) readonly buffer LeafData { Leaf leaf_data[]; };
layout(std430, binding = 1) readonly buffer LeafNodes { int leaves[]; };
layout(std430, binding = 2) readonly buffer Bins { vec4 bins[]; };  // direction, solid angle
layout(std430, binding = 3) readonly buffer Incident { float l_in[]; };
layout(std430, binding = 4) buffer Reflected { float i_l[]; };
layout(std430, binding = 5) buffer Anti { float i_a[]; };
layout(std430, binding = 6) buffer Exitant { float i_ex[]; };
layout(std430, binding = 7) buffer Irradiance { vec4 irradiance[]; };
layout(std430, binding = 8) writeonly buffer Residual { vec2 residual[]; };

uniform uint u_radiance;
uniform uint u_antiradiance;

const float kInvPi = 0.318309886183790671538;

void main() {
  const uint l = item_index();
  if (l >= u_items) return;
  const Leaf d = leaf_data[l];
  const vec3 n = d.normal_area.xyz;
  const float area = d.normal_area.w;
  const uint leaf_row = l * u_bins * 3u;
  const uint node_row = uint(leaves[l]) * u_bins * 3u;
  vec3 e = vec3(0.0);
  for (uint b = 0u; b < u_bins; ++b) {
    const float cos_minus = max(0.0, -dot(n, bins[b].xyz));
    const uint j = node_row + b * 3u;
    e += (cos_minus * bins[b].w) * vec3(l_in[j], l_in[j + 1u], l_in[j + 2u]);
  }
  const vec3 reflected = d.albedo.rgb * kInvPi * (e + d.direct.rgb);
  if (u_radiance != 0u) irradiance[l] = vec4(e, 1.0);
  float change = 0.0;
  float magnitude = 0.0;
  for (uint b = 0u; b < u_bins; ++b) {
    const float c = dot(n, bins[b].xyz);
    const uint k = leaf_row + b * 3u;
    vec3 il = vec3(i_l[k], i_l[k + 1u], i_l[k + 2u]);
    vec3 ia = vec3(i_a[k], i_a[k + 1u], i_a[k + 2u]);
    if (u_radiance != 0u) {
      il = (area * max(0.0, c)) * reflected;
      i_l[k] = il.x;
      i_l[k + 1u] = il.y;
      i_l[k + 2u] = il.z;
    }
    if (u_antiradiance != 0u) {
      const uint j = node_row + b * 3u;
      ia = (area * max(0.0, -c)) * vec3(l_in[j], l_in[j + 1u], l_in[j + 2u]);
      i_a[k] = ia.x;
      i_a[k + 1u] = ia.y;
      i_a[k + 2u] = ia.z;
    }
    const vec3 ex = il - ia;
    const uint j = node_row + b * 3u;
    const vec3 diff = abs(ex - vec3(i_ex[j], i_ex[j + 1u], i_ex[j + 2u]));
    const vec3 mag = abs(ex);
    change += diff.x + diff.y + diff.z;
    magnitude += mag.x + mag.y + mag.z;
    i_ex[j] = ex.x;
    i_ex[j + 1u] = ex.y;
    i_ex[j + 2u] = ex.z;
  }
  residual[l] = vec2(change, magnitude);
}
