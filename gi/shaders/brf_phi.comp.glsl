#version 450 core
// Basis irradiance (Iwasaki et al. §5, eq. 13) of a batch of jobs in one dispatch. A job is
// one source's field evaluated at a run of points: a receiver instance's vertices (u_kind 0,
// points from the model-vertex buffer in the receiver's object space) or static-world
// receivers (u_kind 1, world-space points picked through an index list). The point goes into
// the source's object space (to_source), its normal too (normal_to_source, then normalized),
// and
//   phi[phi_offset + k N4 + i] = sum over the 8 field samples of weight x (coefficients_i . lobe(n))
// with lobe = 0 / the unclamped cosine / the clamped cosine as the source's box lies behind /
// in front of / across the tangent plane (brf_horizon)
// (N4: N padded to a multiple of 4, the pads written 0)
// the twin of brf_basis_irradiance (brf_runtime.cpp). Work groups map to (job, first point)
// through the group table, so a dispatch covers many jobs of different lengths.

#include "brf_common.glsl"

layout(local_size_x = 64) in;

struct PhiJob {
  mat4 to_source;         // point -> source object space
  mat4 normal_to_source;  // normal -> source object space (mat3 part; normalized after)
  uint source_model;
  uint point_offset;      // kind 0: first model vertex; kind 1: first entry of static_indices
  uint point_count;
  uint phi_offset;        // first float written
};

layout(std430, binding = 0) readonly buffer Models { BrfModel models[]; };
layout(std430, binding = 1) readonly buffer ModelVertices { vec4 model_vertices[]; };  // position, normal per vertex
layout(std430, binding = 2) readonly buffer StaticPoints { vec4 static_points[]; };    // position, normal per receiver
layout(std430, binding = 3) readonly buffer StaticIndices { uint static_indices[]; };
layout(std430, binding = 4) readonly buffer Jobs { PhiJob jobs[]; };
layout(std430, binding = 5) readonly buffer Groups { uvec2 groups[]; };  // (job, first point)
layout(std430, binding = 6) readonly buffer Field { float field[]; };
layout(std430, binding = 7) writeonly buffer Phi { float phi[]; };

uniform uint u_first_group;
uniform uint u_group_count;
uniform uint u_kind;  // 0: instance vertices, 1: static receivers

void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (group >= u_group_count) return;
  const uvec2 g = groups[u_first_group + group];
  const uint k = g.y + gl_LocalInvocationIndex;
  if (k >= jobs[g.x].point_count) return;
  const PhiJob job = jobs[g.x];

  vec3 p_in, n_in;
  if (u_kind == 0u) {
    const uint v = job.point_offset + k;
    p_in = model_vertices[2u * v].xyz;
    n_in = model_vertices[2u * v + 1u].xyz;
  } else {
    const uint t = static_indices[job.point_offset + k];
    p_in = static_points[2u * t].xyz;
    n_in = static_points[2u * t + 1u].xyz;
  }
  const vec3 p = (job.to_source * vec4(p_in, 1.0)).xyz;
  const vec3 n = normalize(mat3(job.normal_to_source) * n_in);

  const BrfModel m = models[job.source_model];
  const uint nb = m.basis_count, n4 = brf_padded(nb);
  const uint side = brf_horizon(m, p, n);
  if (side == 0u) {  // the source is behind the tangent plane: no light
    for (uint i = 0u; i < n4; ++i) phi[job.phi_offset + k * n4 + i] = 0.0;
    return;
  }
  float lobe[16];
  if (side == 1u)
    brf_cosine(n, lobe);
  else
    brf_clamped_cosine(n, m.sh_bands, lobe);
  uint base[8];
  float weight[8];
  const bool inside = brf_field_corners(m, p, base, weight);
  const uint cc = m.sh_bands * m.sh_bands;
  for (uint i = nb; i < n4; ++i) phi[job.phi_offset + k * n4 + i] = 0.0;
  for (uint i = 0u; i < nb; ++i) {
    float sum = 0.0;
    if (inside)
      for (int c = 0; c < 8; ++c) {
        if (weight[c] == 0.0) continue;
        const uint at = m.field_offset + base[c] + i * cc;
        float d = 0.0;
        for (uint q = 0u; q < cc; ++q) d += field[at + q] * lobe[q];
        sum += weight[c] * d;
      }
    phi[job.phi_offset + k * n4 + i] = sum;
  }
}
