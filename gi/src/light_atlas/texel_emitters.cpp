#include "light_atlas/texel_emitters.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace gi {
namespace {

constexpr std::uint32_t kNone = TexelEmitters::Sample::kNone;
// At most this many clusters: the receiver groups' distributions take clusters^2 floats
// (16 MiB here); the cell doubles until the level fits.
constexpr std::size_t kMaxClusters = 2048;
// A cluster whose normals spread less than this (radians) is flat enough for the plane test.
constexpr float kFlatCone = 0.05f;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

float luminance(const glm::vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

// One of six axis directions: the largest component of the face normal and its sign.
std::uint64_t axis_of(const glm::vec3& n) {
  const glm::vec3 a = glm::abs(n);
  const int k = a.x >= a.y && a.x >= a.z ? 0 : a.y >= a.z ? 1 : 2;
  return static_cast<std::uint64_t>(2 * k + (n[k] < 0.0f ? 1 : 0));
}

std::uint64_t cluster_key(const glm::vec3& p, const glm::vec3& face, float cell_m) {
  const glm::ivec3 c = glm::ivec3(glm::floor(p / cell_m));
  const auto field = [](int v) { return static_cast<std::uint64_t>(std::clamp(v + (1 << 19), 0, (1 << 20) - 1)); };
  return (field(c.z) << 43u) | (field(c.y) << 23u) | (field(c.x) << 3u) | axis_of(face);
}

// cos of the angle between a direction and a cone's axis made smaller by `spread` radians
// (0 when even the nearest direction of the cone is at or past 90 degrees).
float widened_cos(float cos_angle, float spread) {
  const float angle = std::acos(std::clamp(cos_angle, -1.0f, 1.0f)) - spread;
  if (angle <= 0.0f) return 1.0f;
  return angle >= 0.5f * std::numbers::pi_v<float> ? 0.0f : std::cos(angle);
}

// The world point at atlas UV `uv` on the plane of texel `texel`'s triangle, and the world
// area of one atlas texel there (0 when the triangle's UVs are degenerate).
struct SquareMap {
  glm::vec3 p0{0.0f}, e1{0.0f}, e2{0.0f};
  glm::vec2 a0{0.0f};
  glm::mat2 inverse{1.0f};
  float texel_area = 0.0f;
};

SquareMap square_map(const StaticBakeScene& b, const AtlasLayout& layout, std::uint32_t texel) {
  const AtlasTexels& tx = b.texels;
  const auto mesh = static_cast<std::uint32_t>(tx.mesh[texel]);
  const auto tri = static_cast<std::uint32_t>(tx.triangle[texel]);
  const ShadingTriangle& st = b.index.triangles[b.index.instance_first[b.static_instance[mesh]] + tri];
  const AtlasMeshUv& mu = layout.meshes[mesh];
  const std::uint32_t* idx = &mu.indices[3u * tri];
  SquareMap m;
  m.p0 = st.p0, m.e1 = st.e1, m.e2 = st.e2;
  m.a0 = mu.uv1[idx[0]];
  const glm::mat2 uv(mu.uv1[idx[1]] - m.a0, mu.uv1[idx[2]] - m.a0);  // columns
  const float det = glm::determinant(uv);
  if (!(std::fabs(det) > 1e-20f)) return m;
  m.inverse = glm::inverse(uv);
  m.texel_area = glm::length(glm::cross(st.e1, st.e2)) / std::fabs(det) /
                 (static_cast<float>(tx.width) * static_cast<float>(tx.height));
  return m;
}

}  // namespace

TexelEmitters::TexelEmitters(const StaticBakeScene& b, const AtlasLayout& layout, std::span<const std::uint32_t> work,
                             std::span<const glm::vec3> face, std::span<const glm::vec3> radiosity,
                             float texels_per_metre, ThreadPool& pool)
    : scene_(&b), layout_(&layout), width_(b.texels.width), height_(b.texels.height) {
  const AtlasTexels& tx = b.texels;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(work.size());
  float cell_m = 8.0f / std::max(texels_per_metre, 1e-3f);
  for (;;) {
    for (std::size_t w = 0; w < work.size(); ++w)
      keyed[w] = {cluster_key(tx.position[work[w]], face[work[w]], cell_m), work[w]};
    std::sort(keyed.begin(), keyed.end());
    std::size_t count = keyed.empty() ? 0 : 1;
    for (std::size_t k = 1; k < keyed.size(); ++k) count += keyed[k].first != keyed[k - 1].first;
    if (count <= kMaxClusters) break;
    cell_m *= 2.0f;
  }
  build_clusters(keyed, face, radiosity);
  build_rows(pool);
}

void TexelEmitters::build_clusters(const std::vector<std::pair<std::uint64_t, std::uint32_t>>& keyed,
                                   std::span<const glm::vec3> face, std::span<const glm::vec3> radiosity) {
  const AtlasTexels& tx = scene_->texels;
  cluster_of_.assign(tx.valid.size(), kNone);
  density_.assign(tx.valid.size(), 0.0f);
  std::vector<float> area(tx.valid.size(), 0.0f);
  members_.reserve(keyed.size());
  member_cdf_.reserve(keyed.size());
  member_points_.reserve(keyed.size());
  member_guide_.reserve(keyed.size());
  for (std::size_t k = 0; k < keyed.size();) {
    std::size_t end = k;
    while (end < keyed.size() && keyed[end].first == keyed[k].first) ++end;
    Cluster c;
    c.first = static_cast<std::uint32_t>(members_.size());
    glm::dvec3 centre(0.0), normal(0.0);
    std::vector<double> power;
    for (std::size_t m = k; m < end; ++m) {
      const std::uint32_t j = keyed[m].second;
      cluster_of_[j] = static_cast<std::uint32_t>(clusters_.size());
      members_.push_back(j);
      centre += glm::dvec3(tx.position[j]);
      normal += glm::dvec3(face[j]);
      const SquareMap sq = square_map(*scene_, *layout_, j);
      area[j] = sq.texel_area;
      member_points_.push_back({.p0 = sq.p0, .e1 = sq.e1, .e2 = sq.e2, .a0 = sq.a0, .inverse = sq.inverse});
      power.push_back(area[j] > 0.0f ? static_cast<double>(std::max(luminance(radiosity[j]), 0.0f) * area[j]) : 0.0);
      c.power += power.back();
    }
    c.end = static_cast<std::uint32_t>(members_.size());
    c.centre = glm::vec3(centre / static_cast<double>(end - k));
    c.normal = glm::length(normal) > 0.0 ? glm::vec3(glm::normalize(normal)) : face[keyed[k].second];
    double running = 0.0;
    for (std::size_t m = k; m < end; ++m) {
      const std::uint32_t j = keyed[m].second;
      c.radius = std::max(c.radius, glm::length(tx.position[j] - c.centre));
      c.cone = std::max(c.cone, std::acos(std::clamp(glm::dot(face[j], c.normal), -1.0f, 1.0f)));
      c.thickness = std::max(c.thickness, std::fabs(glm::dot(tx.position[j] - c.centre, c.normal)));
      running += power[m - k];
      member_cdf_.push_back(c.power > 0.0 ? static_cast<float>(running / c.power) : 0.0f);
      if (c.power > 0.0 && area[j] > 0.0f) density_[j] = static_cast<float>(power[m - k] / c.power) / area[j];
      if (density_[j] > 0.0f) member_points_[c.first + (m - k)].texel = j;
    }
    if (c.power > 0.0) member_cdf_.back() = 1.0f;
    // The cutpoint table: entry g is the first member whose CDF exceeds g / n.
    const auto n = static_cast<float>(end - k);
    const auto cdf_of = [&](std::uint32_t m) { return m >= c.end ? kInfinity : member_cdf_[m]; };
    std::uint32_t first_above = c.first;
    for (std::size_t g = 0; g < end - k; ++g) {
      const float threshold = static_cast<float>(g) / n;
      while (first_above < c.end && !(threshold < member_cdf_[first_above])) ++first_above;
      const float before = first_above > c.first ? member_cdf_[first_above - 1] : -kInfinity;
      member_guide_.push_back({first_above, before, cdf_of(first_above), cdf_of(first_above + 1)});
    }
    clusters_.push_back(c);
    k = end;
  }
}

// The unoccluded bound of receiver cluster g's irradiance from emitter cluster c, up to the
// factor 1/pi: power x the two widened cosines / the squared nearest distance.
double TexelEmitters::bound(const Cluster& g, const Cluster& c) {
  if (!(c.power > 0.0)) return 0.0;
  const glm::vec3 v = c.centre - g.centre;
  // Flat clusters: an emitter wholly behind or in the receiver's plane, or a receiver wholly
  // behind the emitter's, sends nothing (a floor to the rest of the same floor).
  if (g.cone < kFlatCone && glm::dot(v, g.normal) + c.radius + g.thickness <= 0.0f) return 0.0;
  if (c.cone < kFlatCone && glm::dot(-v, c.normal) + g.radius + c.thickness <= 0.0f) return 0.0;
  const float r = g.radius + c.radius, d = glm::length(v);
  const double r2 = static_cast<double>(r) * static_cast<double>(r);
  if (d <= r) return c.power / std::max(r2, 1e-12);
  const glm::vec3 dir = v / d;
  const float spread = std::asin(std::min(1.0f, r / d));
  const float cos_g = widened_cos(glm::dot(g.normal, dir), g.cone + spread);
  const float cos_c = widened_cos(glm::dot(c.normal, -dir), c.cone + spread);
  const double gap = static_cast<double>(d - r);
  const double near = std::max(gap * gap, r2);
  return c.power * static_cast<double>(cos_g * cos_c) / std::max(near, 1e-12);
}

void TexelEmitters::build_rows(ThreadPool& pool) {
  const std::size_t k = clusters_.size();
  row_cdf_.assign(k * k, 0.0f);
  row_empty_.assign(k, 1);
  pool.parallel_for(
      k,
      [&](std::size_t g) {
        float* row = &row_cdf_[g * k];
        std::vector<double> w(k);
        double total = 0.0;
        for (std::size_t c = 0; c < k; ++c) total += w[c] = bound(clusters_[g], clusters_[c]);
        if (!(total > 0.0)) return;
        double running = 0.0;
        for (std::size_t c = 0; c < k; ++c) row[c] = static_cast<float>((running += w[c]) / total);
        row[k - 1] = 1.0f;
        row_empty_[g] = 0;
      },
      16);
}

float TexelEmitters::row_probability(std::uint32_t group, std::uint32_t cluster) const {
  const float* row = &row_cdf_[static_cast<std::size_t>(group) * clusters_.size()];
  return row[cluster] - (cluster > 0 ? row[cluster - 1] : 0.0f);
}

TexelEmitters::Sample TexelEmitters::sample(std::uint32_t group, float u, float v, float w) const {
  return place(pick(group, u), v, w);
}

std::uint32_t TexelEmitters::pick(std::uint32_t group, float u) const {
  if (row_empty_[group]) return kNoMember;
  const std::size_t k = clusters_.size();
  const float* row = &row_cdf_[static_cast<std::size_t>(group) * k];
  const auto c = static_cast<std::uint32_t>(std::upper_bound(row, row + k, u) - row);
  if (c >= k) return kNoMember;
  const float lo = c > 0 ? row[c - 1] : 0.0f;
  const float u2 = std::clamp((u - lo) / (row[c] - lo), 0.0f, 0x1.fffffep-1f);
  const Cluster& cl = clusters_[c];
  const std::uint32_t m = member_of(cl, u2);
  if (m >= cl.end) return kNoMember;
  __builtin_prefetch(&member_points_[m]);
  return m;
}

TexelEmitters::Sample TexelEmitters::place(std::uint32_t member, float v, float w) const {
  if (member == kNoMember) return {};
  const MemberPoint& sq = member_points_[member];
  const std::uint32_t j = sq.texel;
  if (j == kNone) return {};
  const int x = static_cast<int>(j % static_cast<std::uint32_t>(width_));
  const int y = static_cast<int>(j / static_cast<std::uint32_t>(width_));
  const glm::vec2 uv((static_cast<float>(x) + v) / static_cast<float>(width_),
                     (static_cast<float>(y) + w) / static_cast<float>(height_));
  const glm::vec2 bary = sq.inverse * (uv - sq.a0);
  return {j, sq.p0 + bary.x * sq.e1 + bary.y * sq.e2};
}

// std::upper_bound(cdf + first, cdf + end, u) over the cluster's members, started at the
// cutpoint table's entry for u (stepped back should rounding have put it past the answer).
std::uint32_t TexelEmitters::member_of(const Cluster& c, float u) const {
  const std::uint32_t n = c.end - c.first;
  if (n == 0) return c.end;
  const auto g = std::min(n - 1, static_cast<std::uint32_t>(u * static_cast<float>(n)));
  const Guide& guide = member_guide_[c.first + g];
  std::uint32_t m = guide.member;
  if (!(u < guide.cdf_before)) {  // the answer is m or after it
    if (u < guide.cdf_at) return m;
    if (u < guide.cdf_next) return m + 1;
  }
  const float* cdf = member_cdf_.data();
  while (m > c.first && u < cdf[m - 1]) --m;
  while (m < c.end && !(u < cdf[m])) ++m;
  return m;
}

float TexelEmitters::area_pdf(std::uint32_t group, std::uint32_t texel) const {
  if (texel >= cluster_of_.size() || cluster_of_[texel] == kNone || row_empty_[group]) return 0.0f;
  return row_probability(group, cluster_of_[texel]) * density_[texel];
}

}  // namespace gi
