// Shared by the basis-radiance-field compute passes (brf_gpu_pass.cpp mirrors these structs
// with static_asserts on their sizes). GLSL twins of gi/src/brf/spherical_harmonics.cpp and
// BasisRadianceField::sample (gi/src/brf/radiance_field.cpp): same cube-face mapping, same
// corner weights, same radius interpolation, so the GPU and CPU runtimes agree to float
// rounding.

// One uploaded model: its field's geometry and where its data lives.
struct BrfModel {
  vec4 centre_inner;   // xyz: field centre (object space), w: innermost sphere radius
  float outer_radius;  // outermost sphere radius
  uint spheres;
  uint face_resolution;
  uint sh_bands;       // 3 or 4
  uint basis_count;    // N
  uint vertex_offset;  // first vertex in the model-vertex buffer
  uint vertex_count;
  uint psi_offset;    // first float of Psi (N x vertex_count, basis-major) in the psi buffer
  uint ainv_offset;   // first float of A^-1 (N x N, row-major)
  uint field_offset;  // first float of the field in its field buffer (a multiple of 4)
  uint field_buffer;  // which field buffer (one dispatch per buffer)
  uint terms;         // K: 1 + glossy terms; the field has K x N channels (k x N + i)
  vec4 box_lo;        // xyz: the object's bounding box (object space), brf_object_box
  vec4 box_hi;
};

// One placed instance this frame.
struct BrfInstance {
  vec4 albedo;        // rgb diffuse albedo
  vec3 specular;      // rgb glossy colour (glossy models)
  uint gather_first;  // brf_gather.comp.glsl: its first invocation (4 vertices each)
  uint model;
  uint vertex_offset;  // first vertex of the instance (the gather's invocation index)
  uint vertex_count;   // V
  uint weight_offset;  // first vec4 of its weights: one rgb vec4 per channel (k x N + i), K x N padded to 4
  uint live_first;     // its live sources in the live-source list
  uint live_count;
  uint value_offset;  // first of its K x V per-vertex values ([k x V + j]) in the value buffers
  uint terms;         // K
};

// Channels padded to a multiple of 4: Phi rows and weight runs are read as vec4s.
uint brf_padded(uint count) { return (count + 3u) & ~3u; }

// Y_lm(w) for l < 4 (w unit, z up), "l, m" order: index l (l + 1) + m.
void brf_sh_basis(vec3 w, out float c[16]) {
  const float x = w.x, y = w.y, z = w.z;
  c[0] = 0.282094792;
  c[1] = 0.488602512 * y;
  c[2] = 0.488602512 * z;
  c[3] = 0.488602512 * x;
  c[4] = 1.092548431 * x * y;
  c[5] = 1.092548431 * y * z;
  c[6] = 0.315391565 * (3.0 * z * z - 1.0);
  c[7] = 1.092548431 * x * z;
  c[8] = 0.546274215 * (x * x - y * y);
  c[9] = 0.590043589 * y * (3.0 * x * x - y * y);
  c[10] = 2.890611442 * x * y * z;
  c[11] = 0.457045799 * y * (5.0 * z * z - 1.0);
  c[12] = 0.373176333 * z * (5.0 * z * z - 3.0);
  c[13] = 0.457045799 * x * (5.0 * z * z - 1.0);
  c[14] = 1.445305721 * z * (x * x - y * y);
  c[15] = 0.590043589 * x * (x * x - 3.0 * y * y);
}

// Where the object's box lies relative to the tangent plane of (p, n), object space: the
// twin of brf_horizon (brf_runtime.cpp). 0: behind, 1: wholly in front, 2: straddling.
uint brf_horizon(BrfModel m, vec3 p, vec3 n) {
  const vec3 c = 0.5 * (m.box_lo.xyz + m.box_hi.xyz), h = 0.5 * (m.box_hi.xyz - m.box_lo.xyz);
  const float centre = dot(n, c - p);
  const float spread = abs(n.x) * h.x + abs(n.y) * h.y + abs(n.z) * h.z;
  const float tolerance = 1e-4 * (h.x + h.y + h.z);
  if (centre + spread <= tolerance) return 0u;
  if (centre - spread >= -tolerance) return 1u;
  return 2u;
}

// The unclamped cosine n . w: band 1 only, (4 pi / 3) Y_1m(n) (sh_cosine).
void brf_cosine(vec3 n, out float lobe[16]) {
  brf_sh_basis(n, lobe);
  for (uint i = 0u; i < 16u; ++i) lobe[i] = (i >= 1u && i <= 3u) ? 4.18879020 * lobe[i] : 0.0;
}

// The clamped cosine max(0, n . w) around unit n, `bands` bands (band 3 is zero).
void brf_clamped_cosine(vec3 n, uint bands, out float lobe[16]) {
  const float kPi = 3.14159265358979;
  brf_sh_basis(n, lobe);
  const float band[4] = float[4](kPi, 2.0 * kPi / 3.0, kPi / 4.0, 0.0);
  for (uint l = 0u; l < 4u; ++l)
    for (uint i = l * l; i < (l + 1u) * (l + 1u); ++i) lobe[i] = l < bands ? band[l] * lobe[i] : 0.0;
}

// Cube face f and (u, v) in [-1, 1]^2 of direction d (radiance_field.cpp's cube_face).
void brf_cube_face(vec3 d, out uint f, out float u, out float v) {
  const vec3 a = abs(d);
  if (a.x >= a.y && a.x >= a.z) {
    f = d.x > 0.0 ? 0u : 1u;
    u = d.x > 0.0 ? -d.z / a.x : d.z / a.x;
    v = d.y / a.x;
  } else if (a.y >= a.z) {
    f = d.y > 0.0 ? 2u : 3u;
    u = d.x / a.y;
    v = d.y > 0.0 ? -d.z / a.y : d.z / a.y;
  } else {
    f = d.z > 0.0 ? 4u : 5u;
    u = d.z > 0.0 ? d.x / a.z : -d.x / a.z;
    v = d.y / a.z;
  }
}

// Cube face f's point (u, v) in [-1, 1]^2 as a direction (radiance_field.cpp's cube_direction).
vec3 brf_cube_direction(uint f, float u, float v) {
  if (f == 0u) return vec3(1.0, v, -u);
  if (f == 1u) return vec3(-1.0, v, u);
  if (f == 2u) return vec3(u, 1.0, -v);
  if (f == 3u) return vec3(u, -1.0, v);
  if (f == 4u) return vec3(u, v, 1.0);
  return vec3(-u, v, -1.0);
}

// Cell (iu, iv) of face f, one cell beyond the face allowed: the neighbouring face's cell
// holding the direction of its centre (radiance_field.cpp's seam_cell).
void brf_seam_cell(uint res, inout uint f, inout int iu, inout int iv) {
  const int r = int(res);
  if (iu >= 0 && iu < r && iv >= 0 && iv < r) return;
  const float n = float(res);
  const float cu = (float(iu) + 0.5) / n * 2.0 - 1.0;
  const float cv = (float(iv) + 0.5) / n * 2.0 - 1.0;
  float u, v;
  brf_cube_face(brf_cube_direction(f, cu, cv), f, u, v);
  iu = clamp(int(floor((u + 1.0) * 0.5 * n)), 0, r - 1);
  iv = clamp(int(floor((v + 1.0) * 0.5 * n)), 0, r - 1);
}

float brf_sphere_radius(BrfModel m, uint s) {
  if (m.spheres <= 1u) return m.centre_inner.w;
  return m.centre_inner.w * pow(m.outer_radius / m.centre_inner.w, float(s) / float(m.spheres - 1u));
}

// The 8 samples around object-space point p, as in BasisRadianceField::sample: first float
// of each sample's [term][basis][coefficient] block (relative to the field; on the GPU each
// channel's coefficients are padded to a multiple of 4, brf_padded) and its weight
// (trilinear weight x falloff x (r_s / r)^2 between spheres). Returns how many of them carry
// weight: 8 between two spheres, 4 inside the innermost or beyond the outermost sphere (one
// shell: samples 4-7 have weight 0, so callers loop over the first `taps` only, which lets
// llvmpipe leave the loop for the whole SIMD group), 0 at the centre or for non-finite
// points (the sample is zero there).
uint brf_field_corners(BrfModel m, vec3 p, out uint base[8], out float weight[8]) {
  for (int k = 0; k < 8; ++k) {
    base[k] = 0u;
    weight[k] = 0.0;
  }
  const vec3 d = p - m.centre_inner.xyz;
  const float r = length(d);
  if (!(r > 0.0) || isinf(r) || isnan(r)) return 0u;
  const float inner = m.centre_inner.w, outer = m.outer_radius;
  float falloff = 1.0;
  float sr = 0.0;
  if (r <= inner || m.spheres == 1u) {
    sr = 0.0;
  } else if (r >= outer) {
    sr = float(m.spheres - 1u);
    falloff = (outer / r) * (outer / r);
  } else {
    sr = log(r / inner) / log(outer / inner) * float(m.spheres - 1u);
  }
  const uint s0 = min(uint(sr), m.spheres - 1u), s1 = min(s0 + 1u, m.spheres - 1u);
  const float ts = sr - float(s0);
  uint f;
  float u, v;
  brf_cube_face(d, f, u, v);
  const float n = float(m.face_resolution);
  // Across a face's edge the outer neighbours lie on the next face (brf_seam_cell).
  const float fu = clamp((u + 1.0) * 0.5 * n - 0.5, -0.5, n - 0.5);
  const float fv = clamp((v + 1.0) * 0.5 * n - 0.5, -0.5, n - 0.5);
  const int u0 = int(floor(fu)), v0 = int(floor(fv));
  const int u1 = u0 + 1, v1 = v0 + 1;
  const float tu = fu - float(u0), tv = fv - float(v0);
  const uint per_point = m.terms * m.basis_count * brf_padded(m.sh_bands * m.sh_bands);
  const bool between = r > inner && r < outer && m.spheres > 1u;
  const uint cs[8] = uint[8](s0, s0, s0, s0, s1, s1, s1, s1);
  const int cu[8] = int[8](u0, u1, u0, u1, u0, u1, u0, u1);
  const int cv[8] = int[8](v0, v0, v1, v1, v0, v0, v1, v1);
  const float cw[8] = float[8]((1.0 - ts) * (1.0 - tu) * (1.0 - tv), (1.0 - ts) * tu * (1.0 - tv),
                               (1.0 - ts) * (1.0 - tu) * tv, (1.0 - ts) * tu * tv, ts * (1.0 - tu) * (1.0 - tv),
                               ts * tu * (1.0 - tv), ts * (1.0 - tu) * tv, ts * tu * tv);
  // The two shells' (r_s / r)^2 (brf_sphere_radius per shell, not per sample: the same values).
  const float rs0 = brf_sphere_radius(m, s0), rs1 = brf_sphere_radius(m, s1);
  const float shell[2] = float[2](between ? (rs0 / r) * (rs0 / r) : 1.0, between ? (rs1 / r) * (rs1 / r) : 1.0);
  const uint taps = between ? 8u : 4u;
  for (uint k = 0u; k < taps; ++k) {
    uint ff = f;
    int iu = cu[k], iv = cv[k];
    brf_seam_cell(m.face_resolution, ff, iu, iv);
    const uint idx = ((cs[k] * 6u + ff) * m.face_resolution + uint(iv)) * m.face_resolution + uint(iu);
    base[k] = idx * per_point;
    weight[k] = cw[k] * falloff * shell[k / 4u];
  }
  return taps;
}
