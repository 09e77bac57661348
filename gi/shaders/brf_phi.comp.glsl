#version 450 core
// Basis irradiance (Iwasaki et al. §5, eq. 13) of a batch of jobs in one dispatch. A job is
// one source's field evaluated at a run of points: a receiver instance's vertices (u_kind 0,
// points from the model-vertex buffer in the receiver's object space) or static-world
// receivers (u_kind 1, world-space points picked through an index list). The point goes into
// the source's object space (to_source), its normal too (normal_to_source, then normalized),
// and for each receiver term k' (rows; 1 for diffuse receivers and static points) and source
// channel c (C = terms x N of the source, channel = k x N + i)
//   phi[phi_offset + (k rows + k') C4 + c] = sum over the 8 field samples of weight x (coefficients_c . lobe_k')
// with lobe_0 = 0 / the unclamped cosine / the clamped cosine as the source's box lies behind /
// in front of / across the tangent plane (brf_horizon), and for k' >= 1 (a glossy receiver)
// the receiver's g_k' cos lobe (lobe SH in the vertex's tangent frame) rotated into the
// source's space as ShRotation does (least squares over fixed directions), or 0 behind
// (C4: C padded to a multiple of 4, the pads written 0)
// the twin of brf_basis_irradiance (brf_runtime.cpp); static points' rows are scaled by their
// visibility of the source (binding 9). Built twice: without
// BRF_GLOSSY_RECEIVER for jobs of one row, with it for glossy receivers (the rotation's local
// arrays would slow the diffuse jobs on llvmpipe). Work groups map to (job, first point)
// through the group table, so a dispatch covers many jobs of different lengths.

#include "brf_common.glsl"

layout(local_size_x = 64) in;

struct PhiJob {
  mat4 to_source;         // point -> source object space
  mat4 normal_to_source;  // normal -> source object space (mat3 part; normalized after)
  uint source_model;
  uint point_offset;  // kind 0: first model vertex; kind 1: first entry of static_indices
  uint point_count;
  uint phi_offset;       // first float written
  mat4 frame_to_source;  // glossy receiver: rotation (mat3 part) of its object space into the source's
  uint rows;             // receiver terms K_r (1: diffuse receiver or static point)
  uint frame_offset;     // glossy receiver: first float of its vertex frames (t, b, n per vertex) in sh_data
  uint lobe_offset;      // glossy receiver: first float of its lobe SH (16 per glossy term) in sh_data
  uint lod_points;       // level of detail (brf_lod.h; diffuse receivers): 0, or kind 0: 1 + the receiver's
                         // first representative point in u_lod (point k is the vertex u_lod[lod_points - 1 + k].x,
                         // its row the field part only, at phi_offset + k C4); kind 2: 1 + its first vertex entry
  uint occluder_offset;  // first record in occluders (kind 0): boxes of objects in the pair's way
  uint occluder_count;
  uint lod_rows;    // kind 2: first vec4 of the representative points' rows (u_lod_rows)
  uint lod_shared;  // 1: shared visibility (BrfUpdateSettings::lod_shared_visibility): the points'
                    // rows carry their visibility, kind 2 interpolates whole rows (kind 2: frame_offset
                    // holds the vec4s per row)
};

// A dynamic object's box standing between a pair (brf_pair_occluders): to_occluder maps the
// source's object space into the box's.
struct BrfOccluderRecord {
  mat4 to_occluder;
  vec4 lo;
  vec4 hi;
};

// Read-only per-dispatch data through buffer textures too (texel gathers, not lane loops):
// unit 1 the model table (6 uvec4 per BrfModel), 2 the model vertices (position, normal per
// vertex), 3 the jobs (15 uvec4 per PhiJob), 4 the occluder records (6 uvec4 each).
layout(binding = 1) uniform usamplerBuffer u_models;
layout(binding = 2) uniform samplerBuffer u_model_vertices;
layout(binding = 3) uniform usamplerBuffer u_jobs;
layout(binding = 4) uniform usamplerBuffer u_occluders;
// Unit 5: the level-of-detail tables (brf_gpu_pass.cpp ModelData::lod_table): representative
// vertices (uvec4(vertex, 0, 0, 0)), per vertex uvec4(points a, b, c, 0), uvec4(weight bits, 0).
// Unit 6: Phi as vec4s, for kind 2's reads of the representative rows (written by kind 0).
layout(binding = 5) uniform usamplerBuffer u_lod;
layout(binding = 6) uniform samplerBuffer u_lod_rows;
layout(std430, binding = 2) readonly buffer StaticPoints { vec4 static_points[]; };  // position, normal per receiver
layout(std430, binding = 3) readonly buffer StaticIndices { uint static_indices[]; };
layout(std430, binding = 5) readonly buffer Groups { uvec2 groups[]; };  // (job, first point)
// The field: each channel's SH coefficients padded to vec4s (3 for 3 bands, 4 for 4;
// brf_gpu_pass.cpp's gpu_field), read through a GL_RGBA32F buffer texture on unit 0:
// llvmpipe (Mesa 22) runs each SSBO load as a scalar loop over the SIMD lanes, a texel fetch
// as one vector gather.
layout(binding = 0) uniform samplerBuffer u_field;
vec4 field_at(uint i) { return texelFetch(u_field, int(i)); }
layout(std430, binding = 7) writeonly buffer Phi { float phi[]; };
layout(std430, binding = 7) writeonly buffer Phi4 { vec4 phi4[]; };  // the same buffer, rows are C4 floats
// sh_rotation_tables(): 26 directions (vec4 each, 104 floats), the pinv of bands 1..3
// (3, 5, 7 rows x 26, row-major), then the glossy models' lobe SH and vertex frames.
layout(std430, binding = 8) readonly buffer ShData { float sh_data[]; };
// u_kind 1: per static_indices entry, the fraction of the source that receiver sees past the
// static world (brf_static_visibility); the row is scaled by it.
layout(std430, binding = 9) readonly buffer StaticVisibility { float static_visibility[]; };

vec4 texel_f(usamplerBuffer t, uint i) { return uintBitsToFloat(texelFetch(t, int(i))); }
mat4 texel_mat4(usamplerBuffer t, uint i) {
  return mat4(texel_f(t, i), texel_f(t, i + 1u), texel_f(t, i + 2u), texel_f(t, i + 3u));
}

BrfModel load_model(uint index) {  // BrfModel in brf_common.glsl, std430
  const uint at = 6u * index;
  BrfModel m;
  m.centre_inner = texel_f(u_models, at);
  const uvec4 a = texelFetch(u_models, int(at + 1u)), b = texelFetch(u_models, int(at + 2u)),
              c = texelFetch(u_models, int(at + 3u));
  m.outer_radius = uintBitsToFloat(a.x);
  m.spheres = a.y;
  m.face_resolution = a.z;
  m.sh_bands = a.w;
  m.basis_count = b.x;
  m.vertex_offset = b.y;
  m.vertex_count = b.z;
  m.psi_offset = b.w;
  m.ainv_offset = c.x;
  m.field_offset = c.y;
  m.field_buffer = c.z;
  m.terms = c.w;
  m.box_lo = texel_f(u_models, at + 4u);
  m.box_hi = texel_f(u_models, at + 5u);
  return m;
}

PhiJob load_job(uint index) {  // PhiJob above, std430
  const uint at = 15u * index;
  PhiJob j;
  j.to_source = texel_mat4(u_jobs, at);
  j.normal_to_source = texel_mat4(u_jobs, at + 4u);
  const uvec4 a = texelFetch(u_jobs, int(at + 8u)), b = texelFetch(u_jobs, int(at + 13u)),
              c = texelFetch(u_jobs, int(at + 14u));
  j.source_model = a.x;
  j.point_offset = a.y;
  j.point_count = a.z;
  j.phi_offset = a.w;
  j.frame_to_source = texel_mat4(u_jobs, at + 9u);
  j.rows = b.x;
  j.frame_offset = b.y;
  j.lobe_offset = b.z;
  j.lod_points = b.w;
  j.occluder_offset = c.x;
  j.occluder_count = c.y;
  j.lod_rows = c.z;
  j.lod_shared = c.w;
  return j;
}

uniform uint u_first_group;
uniform uint u_group_count;
// 1: the table has one entry (job, point) per invocation (kind 0's packed level-of-detail
// points, BrfGpuPassOptions::pack_lod_points) and u_group_count counts invocations.
uniform uint u_packed;
// 0: instance vertices, 1: static receivers, 2 (the BRF_LOD_ROWS variant): instance vertices of
// a far pair, their rows interpolated from the representative points' (level of detail, brf_lod.h)
uniform uint u_kind;

const uint kDirections = 26u;
const uint kPinvOffset[4] = uint[4](0u, 104u, 182u, 312u);
const uint kMaxRows = 16u;  // 1 + kMaxGlossyTerms

// Target i of brf_visibility_targets (brf_visibility.h): the source box's centre c (i = 0)
// or a corner pulled to 0.7 (c +- h).
vec3 visibility_target(vec3 c, vec3 h, int i) {
  return i == 0 ? c
                : c + vec3((((i - 1) & 1) != 0) ? h.x : -h.x, (((i - 1) & 2) != 0) ? h.y : -h.y,
                           (((i - 1) & 4) != 0) ? h.z : -h.z);
}

// One axis of a ray-box slab test: narrows [t0, t1] to where p + t d lies within [lo, hi]
// along it (inv = 1 / d, |d| >= 1e-12); the order of the two crossings as the CPU twin swaps them.
void clip_to_slab(float lo, float hi, float p, float inv, inout float t0, inout float t1) {
  const float ta = (lo - p) * inv, tb = (hi - p) * inv;
  t0 = max(t0, min(ta, tb));
  t1 = min(t1, max(ta, tb));
}

// brf_weighted_visibility over brf_visibility_targets (brf_visibility.h): the cosine-weighted
// fraction of the source's 9 target points (box centre, corners pulled to 0.7) that p sees,
// a segment p -> target seen when it misses every box of the job's occluders (brf_segment_clear,
// brf_visibility.cpp). Occluders outer, targets inner: each occluder record is read and p
// mapped into its box once (not once per target; on llvmpipe the texel reads were the cost),
// the segment tests and the sums are the per-target ones bit for bit.
float occluded_visibility(BrfModel m, vec3 p, vec3 n, uint first, uint count) {
  const vec3 c = 0.5 * (m.box_lo.xyz + m.box_hi.xyz), h = 0.7 * 0.5 * (m.box_hi.xyz - m.box_lo.xyz);
  uint wanted = 0u;  // targets in front of p
  for (int i = 0; i < 9; ++i) {
    const vec3 d = visibility_target(c, h, i) - p;
    const float len = length(d);
    if (len > 0.0 && !(dot(n, d) / len <= 0.0)) wanted |= 1u << uint(i);
  }
  uint blocked = 0u;
  for (uint o = first; o < first + count; ++o) {
    const mat4 to_occluder = texel_mat4(u_occluders, 6u * o);
    const vec3 lo = texel_f(u_occluders, 6u * o + 4u).xyz, hi = texel_f(u_occluders, 6u * o + 5u).xyz;
    const vec3 po = (to_occluder * vec4(p, 1.0)).xyz;
    for (int i = 0; i < 9; ++i) {
      if ((wanted & ~blocked & (1u << uint(i))) == 0u) continue;
      const vec3 d = (to_occluder * vec4(visibility_target(c, h, i), 1.0)).xyz - po;
      float t0 = 0.0, t1 = 1.0;
      bool miss = false;
      for (int k = 0; k < 3 && !miss; ++k) {
        if (abs(d[k]) < 1e-12) {
          miss = po[k] < lo[k] || po[k] > hi[k];
          continue;
        }
        clip_to_slab(lo[k], hi[k], po[k], 1.0 / d[k], t0, t1);
        miss = t0 > t1;
      }
      if (!miss) blocked |= 1u << uint(i);
    }
  }
  float all = 0.0, seen = 0.0;
  for (int i = 0; i < 9; ++i) {
    if ((wanted & (1u << uint(i))) == 0u) continue;
    const vec3 d = visibility_target(c, h, i) - p;
    const float cs = dot(n, d) / length(d);
    all += cs;
    if ((blocked & (1u << uint(i))) == 0u) seen += cs;
  }
  return all > 0.0 ? seen / all : 0.0;
}

// brf_contact_visibility (brf_visibility.cpp): t / gap where the normal runs into the source's
// box within gap = 0.25 x its mean half extent, 0 inside it, 1 otherwise.
float contact_visibility(BrfModel m, vec3 p, vec3 n) {
  const vec3 half_extent = 0.5 * (m.box_hi.xyz - m.box_lo.xyz);
  const float gap = 0.25 * (half_extent.x + half_extent.y + half_extent.z) / 3.0;
  const float inf = uintBitsToFloat(0x7f800000u);
  float t0 = -inf, t1 = inf;
  for (int k = 0; k < 3; ++k) {
    if (abs(n[k]) < 1e-12) {
      if (p[k] < m.box_lo[k] || p[k] > m.box_hi[k]) return 1.0;
      continue;
    }
    clip_to_slab(m.box_lo[k], m.box_hi[k], p[k], 1.0 / n[k], t0, t1);
  }
  if (t0 > t1 || t1 < 0.0) return 1.0;
  if (t0 <= 0.0) return 0.0;
  return t0 >= gap ? 1.0 : t0 / gap;
}

#ifdef BRF_LOD_ROWS
// Kind 2 (level of detail, brf_lod.h), its own program variant so that it reads only what it
// needs (llvmpipe pays per texel fetch and invocation): a far pair's row of vertex k is
// brf_lod_interpolate of its representative points' rows (written by a kind-0 job into the
// slot's scratch), scaled by the vertex's own horizon and visibility (brf_basis_irradiance's),
// or, with shared visibility (lod_shared != 0), as it is.
void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  if (group >= u_group_count) return;
  const uvec2 g = groups[u_first_group + group];
  const uint at = 15u * g.x;                         // PhiJob
  const uvec4 a = texelFetch(u_jobs, int(at + 8u));  // source_model, point_offset, point_count, phi_offset
  const uint k = g.y + gl_LocalInvocationIndex;
  if (k >= a.z) return;
  // rows, frame_offset (here: vec4s per row), lobe_offset, lod_points
  const uvec4 b = texelFetch(u_jobs, int(at + 13u));
  const uvec4 c = texelFetch(u_jobs, int(at + 14u));  // occluder_offset, occluder_count, lod_rows, lod_shared
  const uint q4 = b.y, e = b.w - 1u + 2u * k, out0 = a.w / 4u + k * q4;
  float vis = 1.0;
  if (c.w == 0u) {
    const mat4 to_source = texel_mat4(u_jobs, at);
    const mat3 normal_to_source = mat3(texel_mat4(u_jobs, at + 4u));
    const uint v = a.y + k;
    const vec3 p = (to_source * vec4(texelFetch(u_model_vertices, int(2u * v)).xyz, 1.0)).xyz;
    const vec3 n = normalize(normal_to_source * texelFetch(u_model_vertices, int(2u * v + 1u)).xyz);
    BrfModel m;
    m.box_lo = texel_f(u_models, 6u * a.x + 4u);
    m.box_hi = texel_f(u_models, 6u * a.x + 5u);
    vis = brf_horizon(m, p, n) == 0u
              ? 0.0
              : contact_visibility(m, p, n) * (c.y == 0u ? 1.0 : occluded_visibility(m, p, n, c.x, c.y));
  }
  if (vis == 0.0) {
    for (uint q = 0u; q < q4; ++q) phi4[out0 + q] = vec4(0.0);
    return;
  }
  const uvec4 from = texelFetch(u_lod, int(e));
  const vec3 w = uintBitsToFloat(texelFetch(u_lod, int(e + 1u)).xyz);
  for (uint q = 0u; q < q4; ++q) {
    const vec4 ra = texelFetch(u_lod_rows, int(c.z + from.x * q4 + q));
    const vec4 rb = texelFetch(u_lod_rows, int(c.z + from.y * q4 + q));
    const vec4 rc = texelFetch(u_lod_rows, int(c.z + from.z * q4 + q));
    phi4[out0 + q] = ((w.x * ra + w.y * rb) + w.z * rc) * vis;
  }
}
#else
void main() {
  const uint group = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
  uint job_index, point;  // the job and its point (vertex, static entry or representative point)
  if (u_packed != 0u) {
    const uint entry = group * gl_WorkGroupSize.x + gl_LocalInvocationIndex;
    if (entry >= u_group_count) return;
    const uvec2 e = groups[u_first_group + entry];
    job_index = e.x;
    point = e.y;
  } else {
    if (group >= u_group_count) return;
    const uvec2 g = groups[u_first_group + group];
    job_index = g.x;
    point = g.y + gl_LocalInvocationIndex;
    // Lanes past the job's last point leave before loading the rest of the job.
    if (point >= texelFetch(u_jobs, int(15u * g.x + 8u)).z) return;
  }
  const PhiJob job = load_job(job_index);
  // The receiver vertex (kind 0) or static entry: with the level of detail, a representative
  // vertex (its row is written where the vertex's is; brf_lod_expand.comp.glsl fills the others).
  // Representative points (level of detail): the field part only, or with shared visibility the whole row.
  const bool points = u_kind == 0u && job.lod_points != 0u;
  const uint k = points ? texelFetch(u_lod, int(job.lod_points - 1u + point)).x : point;

  vec3 p_in, n_in;
  if (u_kind == 0u) {
    const uint v = job.point_offset + k;
    p_in = texelFetch(u_model_vertices, int(2u * v)).xyz;
    n_in = texelFetch(u_model_vertices, int(2u * v + 1u)).xyz;
  } else {
    const uint t = static_indices[job.point_offset + k];
    p_in = static_points[2u * t].xyz;
    n_in = static_points[2u * t + 1u].xyz;
  }
  const vec3 p = (job.to_source * vec4(p_in, 1.0)).xyz;
  const vec3 n = normalize(mat3(job.normal_to_source) * n_in);

  const BrfModel m = load_model(job.source_model);
  const uint nc = m.basis_count * m.terms, c4 = brf_padded(nc);
  const uint rows = job.rows;
  const uint row0 = job.phi_offset + point * rows * c4;
  const uint side = brf_horizon(m, p, n);
  if (side == 0u) {  // the source is behind the tangent plane: no light
    for (uint i = 0u; i < rows * c4; i += 4u) phi4[(row0 + i) / 4u] = vec4(0.0);
    return;
  }
  // What the point sees of the source past the objects in the pair's way (1 without any).
  // (Representative points: none; the vertices they are interpolated to apply their own.)
  const float vis =
      (points && job.lod_shared == 0u)
          ? 1.0
          : contact_visibility(m, p, n) * (job.occluder_count == 0u
                                               ? 1.0
                                               : occluded_visibility(m, p, n, job.occluder_offset, job.occluder_count));
  if (vis == 0.0) {
    for (uint i = 0u; i < rows * c4; i += 4u) phi4[(row0 + i) / 4u] = vec4(0.0);
    return;
  }
  float lobe[16];
  if (side == 1u)
    brf_cosine(n, lobe);
  else
    brf_clamped_cosine(n, m.sh_bands, lobe);
  uint base[8];
  float weight[8];
  const uint taps = brf_field_corners(m, p, base, weight);
  const uint cc = m.sh_bands * m.sh_bands, cq = brf_padded(cc) / 4u;  // vec4s per channel

#ifndef BRF_GLOSSY_RECEIVER
  {  // a diffuse receiver or static point: the irradiance row only
    const float scale = (u_kind == 1u ? static_visibility[job.point_offset + k] : 1.0) * vis;
    // The unclamped cosine in front is band 1 only: the first vec4 (its coefficient 0 is 0,
    // the others are 0, so skipping them changes no sum). Loops with per-invocation bounds
    // rather than `continue`: llvmpipe leaves a loop once every lane of the SIMD group is
    // done, where a skipped iteration would still run masked. The mesh's vertices come face
    // by face, so a group's lanes mostly share the side and the tap count. Phi is written four
    // channels at a time (the row's pads get 0).
    const uint q1 = side == 1u ? 1u : cq;
    const vec4 l0 = vec4(lobe[0], lobe[1], lobe[2], lobe[3]), l1 = vec4(lobe[4], lobe[5], lobe[6], lobe[7]),
               l2 = vec4(lobe[8], lobe[9], lobe[10], lobe[11]), l3 = vec4(lobe[12], lobe[13], lobe[14], lobe[15]);
    for (uint i4 = 0u; i4 < c4; i4 += 4u) {
      vec4 out4 = vec4(0.0);
      for (uint j = 0u; j < 4u; ++j) {
        const uint i = i4 + j;
        float sum = 0.0;
        for (uint c = 0u; c < (i < nc ? taps : 0u); ++c) {
          const uint at = (m.field_offset + base[c]) / 4u + i * cq;
          float d = 0.0;
          for (uint q = 0u; q < q1; ++q) d += dot(field_at(at + q), q == 0u ? l0 : q == 1u ? l1 : q == 2u ? l2 : l3);
          sum += weight[c] * d;
        }
        out4[j] = sum * scale;
      }
      phi4[(row0 + i4) / 4u] = out4;
    }
    return;
  }
#else
  // A glossy receiver (kind 0 only). ShRotation of R = frame_to_source x tangent frame:
  // block_l = pinv_l Y_l(R^T D), then out_l = block_l in_l for the source's bands.
  const uint vertex = k;  // receiver vertex index within its model
  const uint fo = job.frame_offset + 9u * vertex;
  const mat3 local = mat3(sh_data[fo], sh_data[fo + 1u], sh_data[fo + 2u], sh_data[fo + 3u], sh_data[fo + 4u],
                          sh_data[fo + 5u], sh_data[fo + 6u], sh_data[fo + 7u], sh_data[fo + 8u]);
  const mat3 rt = transpose(mat3(job.frame_to_source) * local);
  float block[84];  // bands 1..3 at 0, 9, 34 (row-major (2l + 1)^2 each)
  for (uint i = 0u; i < 84u; ++i) block[i] = 0.0;
  const uint bo[4] = uint[4](0u, 0u, 9u, 34u);
  for (uint d = 0u; d < kDirections; ++d) {
    float y[16];
    brf_sh_basis(rt * vec3(sh_data[4u * d], sh_data[4u * d + 1u], sh_data[4u * d + 2u]), y);
    for (uint l = 1u; l < m.sh_bands; ++l) {
      const uint count = 2u * l + 1u;
      for (uint a = 0u; a < count; ++a) {
        const float pa = sh_data[kPinvOffset[l] + a * kDirections + d];
        for (uint c = 0u; c < count; ++c) block[bo[l] + a * count + c] += pa * y[l * l + c];
      }
    }
  }
  float lobes[kMaxRows * 16u];
  for (uint q = 0u; q < 16u; ++q) lobes[q] = lobe[q];
  for (uint r = 1u; r < rows; ++r) {
    const uint in0 = job.lobe_offset + (r - 1u) * 16u;
    lobes[r * 16u] = sh_data[in0];
    for (uint l = 1u; l < m.sh_bands; ++l) {
      const uint count = 2u * l + 1u;
      for (uint a = 0u; a < count; ++a) {
        float s = 0.0;
        for (uint c = 0u; c < count; ++c) s += block[bo[l] + a * count + c] * sh_data[in0 + l * l + c];
        lobes[r * 16u + l * l + a] = s;
      }
    }
  }
  for (uint r = 0u; r < rows; ++r)
    for (uint i = nc; i < c4; ++i) phi[row0 + r * c4 + i] = 0.0;
  // Per channel, the sample interpolated as BasisRadianceField::sample does, dotted with every row's lobe.
  for (uint i = 0u; i < nc; ++i) {
    vec4 coeffs4[4] = vec4[4](vec4(0.0), vec4(0.0), vec4(0.0), vec4(0.0));
    for (uint c = 0u; c < taps; ++c) {
      const uint at = (m.field_offset + base[c]) / 4u + i * cq;
      for (uint q = 0u; q < cq; ++q) coeffs4[q] += weight[c] * field_at(at + q);
    }
    float coeffs[16];
    for (uint q = 0u; q < 16u; ++q) coeffs[q] = coeffs4[q / 4u][q % 4u];
    for (uint r = 0u; r < rows; ++r) {
      float d = 0.0;
      for (uint q = 0u; q < cc; ++q) d += coeffs[q] * lobes[r * 16u + q];
      phi[row0 + r * c4 + i] = d * vis;
    }
  }
#endif
}
#endif  // BRF_LOD_ROWS
