#include "brf/brf_runtime.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>

#include "brf/brf_lod.h"
#include "brf/brf_visibility.h"
#include "brf/spherical_harmonics.h"
#include "raytrace/embree_ray_caster.h"

namespace gi {

BrfWorldVertices brf_world_vertices(const BrfObject& object) {
  BrfWorldVertices v;
  const glm::mat4& m = object.object_to_world;
  const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(m)));
  const glm::mat3 rot = glm::mat3(m) / glm::length(glm::vec3(m[0]));  // uniform scale removed
  const std::size_t count = object.mesh->positions.size();
  v.positions.reserve(count);
  v.normals.reserve(count);
  for (std::size_t j = 0; j < count; ++j) {
    v.positions.push_back(glm::vec3(m * glm::vec4(object.mesh->positions[j], 1.0f)));
    v.normals.push_back(glm::normalize(nm * object.mesh->normals[j]));
    if (object.glossy != nullptr) v.frames.push_back(rot * brf_tangent_frame(object.mesh->normals[j]));
  }
  return v;
}

std::array<std::vector<float>, 3> brf_fit_rgb(const BrfBasis& basis, std::span<const glm::vec3> radiosity) {
  std::array<std::vector<float>, 3> w;
  const std::size_t nv = basis.vertex_count, nb = static_cast<std::size_t>(basis.basis_count);
  const std::size_t blocks = nv > 0 ? radiosity.size() / nv : 0;
  std::vector<float> channel(nv);
  for (int c = 0; c < 3; ++c) {
    std::vector<float>& out = w[static_cast<std::size_t>(c)];
    out.assign(blocks * nb, 0.0f);
    for (std::size_t k = 0; k < blocks; ++k) {
      for (std::size_t j = 0; j < nv; ++j) channel[j] = radiosity[k * nv + j][c];
      const std::vector<float> wk = basis.fit(channel);
      std::copy(wk.begin(), wk.end(), out.begin() + static_cast<std::ptrdiff_t>(k * nb));
    }
  }
  return w;
}

BrfBox brf_object_box(const BrfMesh& mesh) {
  BrfBox b{glm::vec3(std::numeric_limits<float>::max()), glm::vec3(-std::numeric_limits<float>::max())};
  for (const glm::vec3& v : mesh.positions) {
    b.lo = glm::min(b.lo, v);
    b.hi = glm::max(b.hi, v);
  }
  return b;
}

BrfHorizon brf_horizon(const BrfBox& box, const glm::vec3& p, const glm::vec3& n) {
  // Signed distances of the 8 corners above the plane: centre term +- the half extents.
  const glm::vec3 c = 0.5f * (box.lo + box.hi), h = 0.5f * (box.hi - box.lo);
  const float centre = glm::dot(n, c - p);
  const float spread = std::abs(n.x) * h.x + std::abs(n.y) * h.y + std::abs(n.z) * h.z;
  // A box touching the plane (a neighbour's face coplanar with the receiver's) counts as on
  // the side it lies: the tolerance keeps rounding from flipping the choice.
  const float tolerance = 1e-4f * (h.x + h.y + h.z);
  if (centre + spread <= tolerance) return BrfHorizon::Behind;
  if (centre - spread >= -tolerance) return BrfHorizon::InFront;
  return BrfHorizon::Straddling;
}

// Long because it is the CPU twin of the GPU's brf_phi pass, kept in the shader's order
// (LOD points, then per vertex: horizon, visibility, lobe, glossy terms) so the two read side by side.
void brf_basis_irradiance(const BrfObject& source, std::span<const glm::vec3> positions,
                          std::span<const glm::vec3> normals, std::vector<float>& out,
                          const BrdfSeparation* receiver_glossy, std::span<const glm::mat3> frames,
                          std::span<const BrfOccluder> occluders, const BrfLodPoints* lod, bool lod_shared_visibility) {
  const BasisRadianceField& f = *source.field;
  const auto cc = static_cast<std::size_t>(f.coefficient_count());
  const auto channels = static_cast<std::size_t>(f.channel_count());
  const std::size_t kr = 1 + (receiver_glossy != nullptr ? static_cast<std::size_t>(receiver_glossy->terms) : 0);
  const glm::mat4 to_source = glm::inverse(source.object_to_world);
  // Rotation part (uniform scale removed for the frames; normals are renormalized).
  const glm::mat3 rot = glm::mat3(to_source);
  const glm::mat3 pure = rot / glm::length(rot[0]);
  std::vector<float> coeffs(channels * cc);
  out.assign(positions.size() * kr * channels, 0.0f);
  // The object lies inside its bounding box: where the tangent plane of the receiver has
  // the whole box behind it the answer is 0; where the whole box is in front, every
  // direction the light comes from has n . w > 0, so the unclamped cosine (band 1) gives
  // the exact irradiance of the stored radiance. Only a box straddling the plane needs the
  // clamped lobe, truncated to the stored bands (whose ringing would otherwise light
  // faces that see nothing, such as the tops of crates beside each other). A glossy
  // receiver's g_k cos lobes are projected on the hemisphere and rotated as they are.
  const BrfBox box = brf_object_box(*source.mesh);
  const auto targets = brf_visibility_targets(box);
  std::array<float, kMaxShCoefficients> rotated{};
  // With a level-of-detail table (diffuse receivers only): the field part of the rows (field
  // . lobe, no visibility) at the representative points first, interpolated below.
  const bool reduced = lod != nullptr && !lod->empty() && kr == 1 && lod->from.size() == positions.size();
  std::vector<float> point_rows;
  if (reduced) {
    point_rows.assign(lod->points.size() * channels, 0.0f);
    for (std::size_t i = 0; i < lod->points.size(); ++i) {
      const std::size_t j = lod->points[i];
      const glm::vec3 p = glm::vec3(to_source * glm::vec4(positions[j], 1.0f));
      const glm::vec3 n = glm::normalize(rot * normals[j]);
      const BrfHorizon side = brf_horizon(box, p, n);
      if (side == BrfHorizon::Behind) continue;
      // Shared visibility: the point's row as the full evaluation has it, visibility included.
      const float v =
          !lod_shared_visibility
              ? 1.0f
              : brf_contact_visibility(box, p, n) *
                    (occluders.empty() ? 1.0f
                                       : brf_weighted_visibility(
                                             p, n, targets, [&](std::size_t, const glm::vec3& a, const glm::vec3& b) {
                                               return brf_segment_clear(a, b, occluders);
                                             }));
      if (v == 0.0f) continue;
      f.sample(p, coeffs);
      const auto lobe = side == BrfHorizon::InFront ? sh_cosine(n) : sh_clamped_cosine(n, f.sh_bands);
      for (std::size_t c = 0; c < channels; ++c)
        point_rows[i * channels + c] = sh_dot(std::span<const float>(coeffs).subspan(c * cc), lobe, cc) * v;
    }
    if (lod_shared_visibility) {  // every vertex's row from the points' rows as they are
      for (std::size_t j = 0; j < positions.size(); ++j)
        brf_lod_interpolate(*lod, j, point_rows, channels, 1.0f, out.data() + j * channels);
      return;
    }
  }
  for (std::size_t j = 0; j < positions.size(); ++j) {
    const glm::vec3 p = glm::vec3(to_source * glm::vec4(positions[j], 1.0f));
    const glm::vec3 n = glm::normalize(rot * normals[j]);
    const BrfHorizon side = brf_horizon(box, p, n);
    if (side == BrfHorizon::Behind) continue;
    // What the point sees of the source past the other objects (the GPU's brf_phi twin).
    const float v = brf_contact_visibility(box, p, n) *
                    (occluders.empty() ? 1.0f
                                       : brf_weighted_visibility(
                                             p, n, targets, [&](std::size_t, const glm::vec3& a, const glm::vec3& b) {
                                               return brf_segment_clear(a, b, occluders);
                                             }));
    if (v == 0.0f) continue;
    if (reduced) {  // this vertex's own side and visibility, the field part interpolated
      brf_lod_interpolate(*lod, j, point_rows, channels, v, out.data() + j * channels);
      continue;
    }
    f.sample(p, coeffs);
    const auto lobe = side == BrfHorizon::InFront ? sh_cosine(n) : sh_clamped_cosine(n, f.sh_bands);
    float* row = out.data() + j * kr * channels;
    for (std::size_t c = 0; c < channels; ++c)
      row[c] = sh_dot(std::span<const float>(coeffs).subspan(c * cc), lobe, cc);
    if (kr > 1) {
      const ShRotation to_source_frame(pure * frames[j]);
      for (std::size_t k = 1; k < kr; ++k) {
        to_source_frame.apply(receiver_glossy->lobe_coefficients(static_cast<int>(k - 1)), rotated, f.sh_bands);
        for (std::size_t c = 0; c < channels; ++c)
          row[k * channels + c] = sh_dot(std::span<const float>(coeffs).subspan(c * cc), rotated, cc);
      }
    }
    if (v != 1.0f)
      for (std::size_t c = 0; c < kr * channels; ++c) row[c] *= v;
  }
}

glm::vec3 brf_outgoing_radiance(const BrfObject& object, const BrfWorldVertices& vertices,
                                std::span<const glm::vec3> light, std::size_t j, const glm::vec3& w_out) {
  const std::size_t nv = vertices.positions.size();
  glm::vec3 radiance = object.albedo * light[j] / std::numbers::pi_v<float>;
  if (object.glossy == nullptr) return radiance;
  const glm::vec3 local = glm::transpose(vertices.frames[j]) * w_out;
  if (local.z <= 0.0f) return radiance;
  for (int k = 1; k <= object.glossy->terms; ++k)
    radiance += object.specular * object.glossy->h_at(k - 1, local) * light[static_cast<std::size_t>(k) * nv + j];
  return radiance;
}

std::vector<std::uint8_t> brf_pair_influence(std::span<const BrfObject> objects, float influence_scale,
                                             std::size_t* candidates) {
  const std::size_t n = objects.size();
  std::vector<std::uint8_t> outside(n * n, 1);
  std::size_t inside = 0;
  if (!(influence_scale > 0.0f) || !std::isfinite(influence_scale)) {
    for (std::size_t s = 0; s < n; ++s)
      for (std::size_t r = 0; r < n; ++r) outside[s * n + r] = s == r ? 1 : 0;
    if (candidates) *candidates = n * (n - std::min<std::size_t>(n, 1));
    return outside;
  }
  // Receivers: bounding spheres; sources: the outermost field sphere in world space (the
  // field's object-space sphere under the object's uniform scale) x influence_scale.
  std::vector<BrfSphere> receiver(n), reach(n);
  float cell = 0.0f, largest_radius = 0.0f;
  for (std::size_t o = 0; o < n; ++o) {
    const BrfObject& obj = objects[o];
    receiver[o] = brf_bounding_sphere(brf_object_box(*obj.mesh), obj.object_to_world);
    const float scale = glm::length(glm::vec3(obj.object_to_world[0]));
    reach[o] = {glm::vec3(obj.object_to_world * glm::vec4(obj.field->centre, 1.0f)),
                obj.field->outer_radius * scale * influence_scale};
    largest_radius = std::max(largest_radius, receiver[o].radius);
  }
  for (std::size_t o = 0; o < n; ++o) cell = std::max(cell, reach[o].radius + largest_radius);
  cell = std::max(cell, 1e-6f);
  // The receivers' centres sorted by grid cell; a source looks at the 27 cells around its
  // centre (the cell is at least its reach plus any receiver's radius).
  auto key_of = [&](const glm::vec3& p) {
    const glm::vec3 c = glm::floor(p / cell);
    auto k = [](float v) { return static_cast<std::int64_t>(std::clamp(v, -1e6f, 1e6f)) + (std::int64_t{1} << 20); };
    return (k(c.x) << 42) | (k(c.y) << 21) | k(c.z);
  };
  std::vector<std::pair<std::int64_t, std::uint32_t>> sorted(n);
  for (std::size_t o = 0; o < n; ++o) sorted[o] = {key_of(receiver[o].centre), static_cast<std::uint32_t>(o)};
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t s = 0; s < n; ++s) {
    const glm::vec3 c = glm::floor(reach[s].centre / cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::int64_t key = key_of((c + glm::vec3(dx, dy, dz) + 0.5f) * cell);
          auto it = std::lower_bound(sorted.begin(), sorted.end(), std::pair{key, std::uint32_t{0}});
          for (; it != sorted.end() && it->first == key; ++it) {
            const std::size_t r = it->second;
            if (r == s) continue;
            if (glm::length(receiver[r].centre - reach[s].centre) < reach[s].radius + receiver[r].radius) {
              outside[s * n + r] = 0;
              ++inside;
            }
          }
        }
  }
  if (candidates) *candidates = inside;
  return outside;
}

std::vector<std::uint8_t> brf_pair_culling(std::span<const BrfObject> objects,
                                           std::span<const std::array<std::vector<float>, 3>> weights, float threshold,
                                           float influence_scale) {
  const std::size_t n = objects.size();
  std::vector<std::uint8_t> outside = brf_pair_influence(objects, influence_scale);
  if (threshold <= 0.0f) return outside;
  std::vector<float> bound(n * n, 0.0f);
  float largest = 0.0f;
  std::vector<float> coeffs;
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t r = 0; r < n; ++r) {
      if (outside[s * n + r] != 0) continue;
      const BasisRadianceField& f = *objects[s].field;
      const glm::mat4 to_source = glm::inverse(objects[s].object_to_world);
      const glm::vec3 centre_r = glm::vec3(objects[r].object_to_world * glm::vec4(objects[r].basis->centre, 1.0f));
      const glm::vec3 p = glm::vec3(to_source * glm::vec4(centre_r, 1.0f));
      coeffs.assign(static_cast<std::size_t>(f.channel_count() * f.coefficient_count()), 0.0f);
      f.sample(p, coeffs);
      // Irradiance on the plane facing the source (the receiver's best case), largest channel.
      // Bounded per basis function, sum_i |w_i| |I_c,i| (§5.4 tests each S_i): the signed sum
      // can cancel to about 0 where the fitted light is dark on the side facing the receiver's
      // centre (a source lit from behind), which culled pairs that light the receiver's other
      // vertices and carry every later bounce (two boxes at N = 20: no interreflection at all).
      const glm::vec3 to_centre = f.centre - p;
      const glm::vec3 facing = glm::length(to_centre) > 0.0f ? glm::normalize(to_centre) : glm::vec3(0, 1, 0);
      const auto lobe = sh_clamped_cosine(facing, f.sh_bands);
      float b = 0.0f;
      for (std::size_t c = 0; c < 3; ++c) {
        float e = 0.0f;
        for (int i = 0; i < f.channel_count(); ++i)
          e += std::fabs(
              weights[s][c][static_cast<std::size_t>(i)] *
              sh_dot(std::span<const float>(coeffs).subspan(static_cast<std::size_t>(i * f.coefficient_count())), lobe,
                     static_cast<std::size_t>(f.coefficient_count())));
        b = std::max(b, e);
      }
      bound[s * n + r] = b;
      largest = std::max(largest, b);
    }
  std::vector<std::uint8_t> culled(n * n, 1);
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t r = 0; r < n; ++r)
      if (outside[s * n + r] == 0 && bound[s * n + r] > threshold * largest) culled[s * n + r] = 0;
  return culled;
}

std::vector<std::vector<glm::vec3>> brf_direct_light(std::span<const BrfObject> objects,
                                                     std::span<const PointEmitter> lights, const RayCaster* world) {
  const std::size_t n = objects.size();
  std::vector<std::vector<glm::vec3>> direct(n);
  if (n == 0) return direct;
  RtSceneData data;
  for (std::size_t o = 0; o < n; ++o) {
    data.geometries.push_back({objects[o].mesh->positions, objects[o].mesh->indices});
    data.instances.push_back({static_cast<std::uint32_t>(o), objects[o].object_to_world, true, o});
  }
  auto caster = make_embree_ray_caster(data);
  for (std::size_t o = 0; o < n; ++o) {
    const BrfWorldVertices v = brf_world_vertices(objects[o]);
    const std::size_t nv = v.positions.size();
    const BrdfSeparation* glossy = objects[o].glossy;
    direct[o].assign(nv * static_cast<std::size_t>(objects[o].terms()), glm::vec3(0.0f));
    for (std::size_t j = 0; j < nv; ++j)
      for (const PointEmitter& l : lights) {
        const glm::vec3 e = emitter_irradiance(l, v.positions[j], v.normals[j], 0.0f);
        if (e == glm::vec3(0.0f)) continue;
        if (caster && !emitter_visible(**caster, l, v.positions[j], v.normals[j])) continue;
        if (world != nullptr && !emitter_visible(*world, l, v.positions[j], v.normals[j])) continue;
        direct[o][j] += e;
        if (glossy == nullptr) continue;
        // E_k = g_k(w_light) E (eq. 8 for a point light), w_light in the vertex's frame.
        const glm::vec3 w = glm::transpose(v.frames[j]) * glm::normalize(l.position - v.positions[j]);
        for (int k = 1; k <= glossy->terms; ++k)
          direct[o][static_cast<std::size_t>(k) * nv + j] += glossy->g_at(k - 1, w) * e;
      }
  }
  return direct;
}

// E_k'(x_j) += sum_c w_c Phi_(k',c)(x_j) per RGB channel, out laid out [k' x V + j]; the
// irradiance (k' = 0) is clamped at 0 (SH ringing must not make light negative), the
// glossy terms are signed like g_k.
void brf_gather(std::span<const float> phi, std::size_t channels, std::size_t receiver_terms,
                const std::array<std::vector<float>, 3>& w, std::span<glm::vec3> out) {
  // The hot loop of the bounces: it streams Phi once, three dot products per row, four
  // partial sums per colour in SSE registers (GCC/Clang vector extensions; -O2 leaves the
  // scalar loop scalar), so Phi is read near memory speed (brf_bench's BM_BrfGatherCpu
  // against a memcpy of the same bytes). The order of the additions is fixed: the result
  // depends on the data only.
  using v4 = float __attribute__((vector_size(16)));
  constexpr std::size_t kMaxVectors = 16;  // up to 64 channels vectorised; the rest scalar
  const std::size_t nv = out.size() / receiver_terms;
  const std::size_t vectors = std::min(channels / 4, kMaxVectors);
  v4 w4[3][kMaxVectors];
  for (std::size_t rgb = 0; rgb < 3; ++rgb)
    for (std::size_t q = 0; q < vectors; ++q) std::memcpy(&w4[rgb][q], w[rgb].data() + 4 * q, sizeof(v4));
  const float* w0 = w[0].data();
  const float* w1 = w[1].data();
  const float* w2 = w[2].data();
  for (std::size_t j = 0; j < nv; ++j)
    for (std::size_t k = 0; k < receiver_terms; ++k) {
      const float* row = phi.data() + (j * receiver_terms + k) * channels;
      v4 a0 = {0, 0, 0, 0}, a1 = a0, a2 = a0;
      for (std::size_t q = 0; q < vectors; ++q) {
        v4 r;
        std::memcpy(&r, row + 4 * q, sizeof(v4));
        a0 += w4[0][q] * r;
        a1 += w4[1][q] * r;
        a2 += w4[2][q] * r;
      }
      glm::vec3 e((a0[0] + a0[1]) + (a0[2] + a0[3]), (a1[0] + a1[1]) + (a1[2] + a1[3]),
                  (a2[0] + a2[1]) + (a2[2] + a2[3]));
      for (std::size_t c = 4 * vectors; c < channels; ++c) e += glm::vec3(w0[c], w1[c], w2[c]) * row[c];
      out[k * nv + j] += k == 0 ? glm::max(e, glm::vec3(0.0f)) : e;
    }
}

namespace {

// The light an object sends on from per-vertex incoming values: albedo x E for the diffuse
// term, specular x E_k for the glossy ones.
void reflect(const BrfObject& object, std::span<const glm::vec3> in, std::span<glm::vec3> out) {
  const std::size_t nv = object.mesh->positions.size();
  for (std::size_t i = 0; i < in.size(); ++i) out[i] = (i < nv ? object.albedo : object.specular) * in[i];
}

/// Level of detail (brf_lod.h): one table per distinct diffuse receiver mesh, the sources'
/// innermost field spheres in world space.
struct PairLod {
  std::vector<std::pair<const BrfMesh*, BrfLodPoints>> tables;
  std::vector<const BrfLodPoints*> of;  ///< Per object: its table, or nullptr (none, glossy, off).
  std::vector<BrfSphere> inner;         ///< Per object: its innermost field sphere (world space).
};

PairLod pair_lod(std::span<const BrfObject> objects, const BrfUpdateSettings& settings) {
  const std::size_t n = objects.size();
  PairLod lod;
  lod.of.assign(n, nullptr);
  lod.inner.resize(n);
  const bool lod_on = settings.lod_distance > 0.0f && std::isfinite(settings.lod_distance);
  if (!lod_on) return lod;
  lod.tables.reserve(n);  // `of` points into it
  for (std::size_t o = 0; o < n; ++o) {
    const BrfObject& obj = objects[o];
    lod.inner[o] = {glm::vec3(obj.object_to_world * glm::vec4(obj.field->centre, 1.0f)),
                    obj.field->inner_radius * glm::length(glm::vec3(obj.object_to_world[0]))};
    if (obj.glossy != nullptr) continue;
    auto it = std::find_if(lod.tables.begin(), lod.tables.end(), [&](const auto& t) { return t.first == obj.mesh; });
    if (it == lod.tables.end()) {
      lod.tables.emplace_back(obj.mesh, brf_lod_points(*obj.mesh));
      it = lod.tables.end() - 1;
    }
    if (!it->second.empty()) lod.of[o] = &it->second;
  }
  return lod;
}

/// Basis irradiance of every live pair ([s * n + r]), once per frame, seen past the objects
/// in between; counts the pairs into `out`.
std::vector<std::vector<float>> pair_phi(std::span<const BrfObject> objects, std::span<const BrfWorldVertices> wv,
                                         std::span<const std::uint8_t> culled, const BrfUpdateSettings& settings,
                                         BrfResult& out) {
  const std::size_t n = objects.size();
  std::vector<BrfBox> boxes(n);
  std::vector<BrfSphere> spheres(n);
  for (std::size_t o = 0; o < n; ++o) {
    boxes[o] = brf_object_box(*objects[o].mesh);
    spheres[o] = brf_bounding_sphere(boxes[o], objects[o].object_to_world);
  }
  std::vector<std::vector<float>> phi(n * n);
  std::vector<BrfOccluder> occluders;
  const PairLod lod = pair_lod(objects, settings);
  for (std::size_t s = 0; s < n; ++s)
    for (std::size_t r = 0; r < n; ++r) {
      if (s == r) continue;
      if (culled[s * n + r] != 0) {
        ++out.pairs_culled;
        continue;
      }
      ++out.pairs_evaluated;
      occluders.clear();
      if (settings.occlusion)
        for (std::uint32_t o : brf_pair_occluders(spheres, s, r))
          occluders.push_back({boxes[o], glm::inverse(objects[o].object_to_world) * objects[s].object_to_world});
      const BrfLodPoints* pair_lod =
          lod.of[r] != nullptr && brf_pair_far(spheres[r], lod.inner[s], settings.lod_distance) ? lod.of[r] : nullptr;
      if (pair_lod != nullptr) ++out.pairs_lod;
      brf_basis_irradiance(objects[s], wv[r].positions, wv[r].normals, phi[s * n + r], objects[r].glossy, wv[r].frames,
                           occluders, pair_lod, settings.lod_shared_visibility);
    }
  return phi;
}

/// Step 2d: the static receivers get every object's total radiosity inside its field.
void receive_static(std::span<const BrfObject> objects, std::span<const std::vector<glm::vec3>> total,
                    const BrfStaticReceivers& receivers, BrfResult& out) {
  std::vector<glm::vec3> pos, nrm;
  std::vector<std::size_t> index;
  std::vector<float> phi_static;
  std::vector<glm::vec3> e;
  std::vector<float> visibility;
  for (std::size_t s = 0; s < objects.size(); ++s) {
    const BasisRadianceField& f = *objects[s].field;
    const glm::vec3 centre = glm::vec3(objects[s].object_to_world * glm::vec4(f.centre, 1.0f));
    const float scale = glm::length(glm::vec3(objects[s].object_to_world[0]));
    const float reach = f.outer_radius * scale;
    pos.clear();
    nrm.clear();
    index.clear();
    for (std::size_t t = 0; t < receivers.positions.size(); ++t)
      if (glm::length(receivers.positions[t] - centre) <= reach) {
        pos.push_back(receivers.positions[t]);
        nrm.push_back(receivers.normals[t]);
        index.push_back(t);
      }
    if (index.empty()) continue;
    visibility.assign(index.size(), 1.0f);
    if (receivers.world != nullptr) {
      std::array<glm::vec3, kBrfVisibilityTargets> targets = brf_visibility_targets(brf_object_box(*objects[s].mesh));
      for (glm::vec3& t : targets) t = glm::vec3(objects[s].object_to_world * glm::vec4(t, 1.0f));
      brf_static_visibility(*receivers.world, targets, pos, nrm, visibility);
    }
    brf_basis_irradiance(objects[s], pos, nrm, phi_static);
    const auto wt = brf_fit_rgb(*objects[s].basis, total[s]);
    e.assign(index.size(), glm::vec3(0.0f));
    brf_gather(phi_static, static_cast<std::size_t>(f.channel_count()), 1, wt, e);
    const BrfBox box = brf_object_box(*objects[s].mesh);
    for (std::size_t k = 0; k < index.size(); ++k)
      if (visibility[k] > 0.0f) {
        out.static_irradiance[index[k]] += visibility[k] * e[k];
        out.static_occlusion[index[k]] +=
            visibility[k] * brf_box_form_factor(box, objects[s].object_to_world, pos[k], nrm[k]);
      }
  }
}

}  // namespace

BrfResult brf_interreflect(std::span<const BrfObject> objects, std::span<const std::vector<glm::vec3>> incoming,
                           const BrfUpdateSettings& settings, const BrfStaticReceivers& receivers) {
  BrfResult out;
  const std::size_t n = objects.size();
  out.indirect.resize(n);
  out.static_irradiance.assign(receivers.positions.size(), glm::vec3(0.0f));
  out.static_occlusion.assign(receivers.positions.size(), 0.0f);
  if (n == 0) return out;

  std::vector<BrfWorldVertices> wv(n);
  std::vector<std::size_t> terms(n);
  std::vector<std::vector<glm::vec3>> light(n);  // light leaving each vertex this bounce, per term
  std::vector<std::vector<glm::vec3>> total(n);  // all light leaving each vertex, per term
  for (std::size_t o = 0; o < n; ++o) {
    wv[o] = brf_world_vertices(objects[o]);
    terms[o] = static_cast<std::size_t>(objects[o].terms());
    const std::size_t size = wv[o].positions.size() * terms[o];
    out.indirect[o].assign(size, glm::vec3(0.0f));
    light[o].resize(size);
    reflect(objects[o], incoming[o], light[o]);
    total[o] = light[o];
  }
  std::vector<std::array<std::vector<float>, 3>> w(n);
  for (std::size_t s = 0; s < n; ++s) w[s] = brf_fit_rgb(*objects[s].basis, light[s]);
  const std::vector<std::uint8_t> culled =
      brf_pair_culling(objects, w, settings.cull_threshold, settings.influence_scale);
  const std::vector<std::vector<float>> phi = pair_phi(objects, wv, culled, settings, out);

  for (int bounce = 0; bounce < settings.bounces; ++bounce) {
    if (bounce > 0)
      for (std::size_t s = 0; s < n; ++s) w[s] = brf_fit_rgb(*objects[s].basis, light[s]);
    std::vector<std::vector<glm::vec3>> gathered(n);
    for (std::size_t r = 0; r < n; ++r) gathered[r].assign(light[r].size(), glm::vec3(0.0f));
    for (std::size_t s = 0; s < n; ++s)
      for (std::size_t r = 0; r < n; ++r)
        if (s != r && culled[s * n + r] == 0)
          brf_gather(phi[s * n + r], static_cast<std::size_t>(objects[s].field->channel_count()), terms[r], w[s],
                     gathered[r]);
    for (std::size_t r = 0; r < n; ++r) {
      reflect(objects[r], gathered[r], light[r]);
      for (std::size_t j = 0; j < gathered[r].size(); ++j) {
        out.indirect[r][j] += gathered[r][j];
        total[r][j] += light[r][j];
      }
    }
  }

  if (!receivers.positions.empty()) receive_static(objects, total, receivers, out);
  for (float& o : out.static_occlusion) o = std::min(o, 1.0f);
  return out;
}

BrfResult update_brf(std::span<const BrfObject> objects, std::span<const PointEmitter> lights,
                     const BrfUpdateSettings& settings) {
  std::vector<std::vector<glm::vec3>> direct = brf_direct_light(objects, lights, nullptr);
  BrfResult out = brf_interreflect(objects, direct, settings);
  out.direct = std::move(direct);
  return out;
}

}  // namespace gi
