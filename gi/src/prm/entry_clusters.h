#pragma once
// Clustering of PRM entry points (Szécsi et al. 2006, §5.1): entry points that are close and
// face the same way get similar direct light, so their panes are summed and they share one
// weight (the mean of theirs). A median-split kd-tree over (position, normal x scale) gives
// exactly the requested number of clusters; optional k-means (Lloyd) steps refine it.
//   std::vector<std::uint32_t> c = gi::cluster_entry_points(positions, normals, 64, false);

#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

namespace gi {

/// Cluster index in [0, min(clusters, n)) of every point. The normal enters the distance
/// scaled by `normal_scale_m` (metres per unit of normal difference). Deterministic: the
/// leaf with most members is split next (ties: lowest index), along its widest dimension,
/// at the median (ties by index). Preconditions: positions.size() == normals.size(), clusters >= 1.
std::vector<std::uint32_t> cluster_entry_points(std::span<const glm::vec3> positions,
                                                std::span<const glm::vec3> normals, int clusters, float normal_scale_m,
                                                int kmeans_iterations = 0);

}  // namespace gi
