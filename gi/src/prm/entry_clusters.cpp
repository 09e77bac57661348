#include "prm/entry_clusters.h"

#include <algorithm>
#include <array>
#include <limits>
#include <numeric>

namespace gi {
namespace {

using Point6 = std::array<float, 6>;

float distance2(const Point6& a, const Point6& b) {
  float d = 0.0f;
  for (int i = 0; i < 6; ++i)
    d += (a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)]) *
         (a[static_cast<std::size_t>(i)] - b[static_cast<std::size_t>(i)]);
  return d;
}

// Median-split kd-tree: leaves are index lists; split the largest until there are enough.
std::vector<std::vector<std::uint32_t>> kd_leaves(const std::vector<Point6>& pts, int clusters) {
  std::vector<std::vector<std::uint32_t>> leaves(1);
  leaves[0].resize(pts.size());
  std::iota(leaves[0].begin(), leaves[0].end(), 0u);
  const auto target = static_cast<std::size_t>(std::max(1, clusters));
  while (leaves.size() < std::min(target, pts.size())) {
    std::size_t big = 0;
    for (std::size_t l = 1; l < leaves.size(); ++l)
      if (leaves[l].size() > leaves[big].size()) big = l;
    std::vector<std::uint32_t>& leaf = leaves[big];
    if (leaf.size() < 2) break;
    int axis = 0;
    float widest = -1.0f;
    for (int a = 0; a < 6; ++a) {
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      for (std::uint32_t i : leaf)
        lo = std::min(lo, pts[i][static_cast<std::size_t>(a)]), hi = std::max(hi, pts[i][static_cast<std::size_t>(a)]);
      if (hi - lo > widest) widest = hi - lo, axis = a;
    }
    const auto ax = static_cast<std::size_t>(axis);
    const auto mid = leaf.begin() + static_cast<std::ptrdiff_t>(leaf.size() / 2);
    std::nth_element(leaf.begin(), mid, leaf.end(), [&](std::uint32_t a, std::uint32_t b) {
      return pts[a][ax] < pts[b][ax] || (pts[a][ax] == pts[b][ax] && a < b);
    });
    std::vector<std::uint32_t> upper(mid, leaf.end());
    leaf.erase(mid, leaf.end());
    std::sort(leaf.begin(), leaf.end());
    std::sort(upper.begin(), upper.end());
    leaves.push_back(std::move(upper));
  }
  return leaves;
}

// Optional Lloyd steps from the kd-tree's centroids (empty clusters keep their centroid).
void lloyd_steps(const std::vector<Point6>& pts, std::size_t cluster_count, int kmeans_iterations,
                 std::vector<std::uint32_t>& out) {
  const std::size_t n = pts.size();
  for (int it = 0; it < kmeans_iterations; ++it) {
    std::vector<Point6> centre(cluster_count, Point6{});
    std::vector<std::size_t> count(cluster_count, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t a = 0; a < 6; ++a) centre[out[i]][a] += pts[i][a];
      ++count[out[i]];
    }
    for (std::size_t c = 0; c < centre.size(); ++c)
      if (count[c] > 0)
        for (float& v : centre[c]) v /= static_cast<float>(count[c]);
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      std::uint32_t best = out[i];
      float best_d = distance2(pts[i], centre[best]);
      for (std::uint32_t c = 0; c < centre.size(); ++c) {
        if (count[c] == 0) continue;
        const float d = distance2(pts[i], centre[c]);
        if (d < best_d) best_d = d, best = c;
      }
      changed = changed || best != out[i];
      out[i] = best;
    }
    if (!changed) break;
  }
}

}  // namespace

std::vector<std::uint32_t> cluster_entry_points(std::span<const glm::vec3> positions,
                                                std::span<const glm::vec3> normals, int clusters, float normal_scale_m,
                                                int kmeans_iterations) {
  const std::size_t n = positions.size();
  std::vector<Point6> pts(n);
  for (std::size_t i = 0; i < n; ++i)
    pts[i] = {positions[i].x,
              positions[i].y,
              positions[i].z,
              normals[i].x * normal_scale_m,
              normals[i].y * normal_scale_m,
              normals[i].z * normal_scale_m};

  const std::vector<std::vector<std::uint32_t>> leaves = kd_leaves(pts, clusters);
  std::vector<std::uint32_t> out(n, 0);
  for (std::size_t l = 0; l < leaves.size(); ++l)
    for (std::uint32_t i : leaves[l]) out[i] = static_cast<std::uint32_t>(l);

  lloyd_steps(pts, leaves.size(), kmeans_iterations, out);
  return out;
}

}  // namespace gi
