#pragma once
// The atlas's texels as area emitters, for the final gather's emitter sampling
// (texel_gather.h step 3, docs/light_atlas.md "Emitter-sampled final gather"): after the
// kept-ray solve every texel j reflects a known radiosity B_j = rho_j (E_d + E)_j, so the
// bright ones (the sunlit floor of a courtyard) can be sampled like lights, and their light
// reaches a dim room through rays aimed at them instead of the few cosine rays that happen
// to hit them.
//   gi::TexelEmitters em(scene, layout, work, face, radiosity, 8.0f, pool);
//   const gi::TexelEmitters::Sample s = em.sample(em.group_of(i), u, v);  // then trace towards s.point
//
// Texels are grouped into clusters: a cubic grid cell and one of the six axis directions of
// the face normal. A cluster's power is the sum of its texels' B_j x area. Every cluster is
// also a receiver group: each group holds a distribution over the emitting clusters
// proportional to power x an unoccluded bound of the geometric term between the two
// clusters (light-tree style: distance, the two normal cones widened by the clusters'
// extents), so emitters behind a receiver or far away get few samples. Within a cluster a
// texel is picked in proportion to its power, then a uniform point of its atlas square on
// the plane of its triangle. area_pdf() gives the density of that whole choice at any point
// of an atlas texel, for multiple importance sampling with the cosine rays; the bound needs
// not be conservative (a cluster with probability 0 is left to the cosine rays).
// Everything is a pure function of the inputs: no random numbers, bit-identical for any
// thread count.

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

#include "core/thread_pool.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace gi {

class TexelEmitters {
 public:
  /// `work`: the valid texels (atlas indices, ascending); `face`: per atlas texel, the unit
  /// geometric normal on the shading side; `radiosity`: per atlas texel, W/m^2 leaving it
  /// (rho (E_d + E)). `texels_per_metre` sets the clusters' cell size (a few metres at most).
  TexelEmitters(const StaticBakeScene& scene, const AtlasLayout& layout, std::span<const std::uint32_t> work,
                std::span<const glm::vec3> face, std::span<const glm::vec3> radiosity, float texels_per_metre,
                ThreadPool& pool);

  /// A point drawn on an emitting texel: the atlas texel and the world point on the plane of
  /// its triangle; texel == kNone when nothing emits.
  struct Sample {
    static constexpr std::uint32_t kNone = 0xffffffffu;
    std::uint32_t texel = kNone;
    glm::vec3 point{0.0f};
  };

  /// The receiver group of a valid atlas texel.
  std::uint32_t group_of(std::uint32_t texel) const { return cluster_of_[texel]; }
  /// Draws a texel and a point on it for receiver group `group` from three uniforms in [0, 1)
  /// (u picks the texel, v and w the point in its square).
  Sample sample(std::uint32_t group, float u, float v, float w) const;
  /// sample() in two halves: pick() draws the member from u (kNoMember when none) and starts
  /// loading its record; place(member, v, w) is then sample(group, u, v, w). Picks made ahead
  /// of their rays overlap their cache misses.
  static constexpr std::uint32_t kNoMember = 0xffffffffu;
  std::uint32_t pick(std::uint32_t group, float u) const;
  Sample place(std::uint32_t member, float v, float w) const;
  /// Density (1/m^2) of sample(group, ...) at a point inside atlas texel `texel` (0 when it
  /// is not a valid texel or does not emit).
  float area_pdf(std::uint32_t group, std::uint32_t texel) const;
  /// Starts loading what area_pdf() reads of `texel` (a landing's pixel), so that a batch of
  /// landings' lookups overlap their cache misses.
  void prefetch_area_pdf(std::uint32_t texel) const {
    if (texel >= cluster_of_.size()) return;
    __builtin_prefetch(&cluster_of_[texel]);
    __builtin_prefetch(&density_[texel]);
  }
  /// Emitting clusters (for the tests and the docs).
  std::size_t cluster_count() const { return clusters_.size(); }

 private:
  struct Cluster {
    glm::vec3 centre{0.0f}, normal{0.0f};
    float radius = 0.0f, cone = 0.0f;  // bounding sphere radius (m), normal cone half-angle (rad)
    float thickness = 0.0f;            // largest distance of a texel from the plane through the centre (m)
    double power = 0.0;
    std::uint32_t first = 0, end = 0;  // its texels: members_[first, end)
  };
  void build_clusters(const std::vector<std::pair<std::uint64_t, std::uint32_t>>& keyed,
                      std::span<const glm::vec3> face, std::span<const glm::vec3> radiosity);
  void build_rows(ThreadPool& pool);
  static double bound(const Cluster& receiver, const Cluster& emitter);
  float row_probability(std::uint32_t group, std::uint32_t cluster) const;

  // What sample() reads of a cluster member, in one 64-byte record beside its neighbours: its
  // texel (kNone where its density is 0) and the map from its atlas square to the plane of its
  // triangle (square_map's). Drawing a texel otherwise missed the cache on its texel, its
  // density, its triangle and its mesh's UVs (a tenth of the Sponza gather's time).
  struct alignas(64) MemberPoint {
    glm::vec3 p0{0.0f}, e1{0.0f}, e2{0.0f};
    glm::vec2 a0{0.0f};
    glm::mat2 inverse{1.0f};
    std::uint32_t texel = Sample::kNone;
  };
  std::uint32_t member_of(const Cluster& c, float u) const;
  const StaticBakeScene* scene_;
  const AtlasLayout* layout_;
  int width_ = 0, height_ = 0;
  std::vector<std::uint32_t> cluster_of_;  // per atlas texel (kNone when invalid)
  std::vector<float> density_;             // per atlas texel: P(texel | its cluster) / square area (1/m^2)
  std::vector<Cluster> clusters_;
  std::vector<std::uint32_t> members_;   // texels of every cluster, grouped
  std::vector<float> member_cdf_;        // inclusive CDF within each cluster, parallel to members_
  std::vector<float> row_cdf_;           // per group g: clusters_.size() inclusive CDF values
  std::vector<std::uint8_t> row_empty_;  // per group: nothing to sample

  // Parallel to members_.
  std::vector<MemberPoint> member_points_;
  // Parallel to members_: in a cluster of n members, guide entry k holds the first member m
  // whose CDF exceeds k / n (a cutpoint table: the draw starts its search there, not at the
  // front) and the CDF at m - 1, m and m + 1 (-inf before the cluster, +inf past it), so that
  // most draws end without reading member_cdf_.
  struct Guide {
    std::uint32_t member = 0;
    float cdf_before = 0.0f, cdf_at = 0.0f, cdf_next = 0.0f;
  };
  std::vector<Guide> member_guide_;
};

}  // namespace gi
