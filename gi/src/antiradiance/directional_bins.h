#pragma once
// The directional discretization of antiradiance (Dachsbacher et al. 2007, §3.1): the sphere
// of directions split into m bins Omega_j with main directions omega_j. We use an
// octahedral map of n x n cells (m = n^2; n = 8: 64 bins, the paper uses 128): a direction
// finds its bin in O(1) and every bin is a connected patch of the sphere. The cells are not
// of exactly equal solid angle (max/min ~ 2.5 for n = 8), so each bin carries its own solid
// angle omega_bin(j), measured by sub-sampling at construction, instead of the paper's
// uniform 4 pi / m (eq. 16-17 use the bin's own value; documented in docs/antiradiance.md).
//   gi::DirectionalBins bins(8);
//   int j = bins.bin_of(glm::normalize(d));  float w = bins.solid_angle(j);

#include <vector>

#include <glm/glm.hpp>

namespace gi {

class DirectionalBins {
 public:
  /// n x n octahedral cells, n in [1, 64].
  explicit DirectionalBins(int cells_per_side);

  int count() const { return n_ * n_; }
  int cells_per_side() const { return n_; }
  /// The bin holding unit direction d.
  int bin_of(const glm::vec3& d) const;
  /// Main direction omega_j of bin j (unit): the mean direction over the cell.
  const glm::vec3& direction(int j) const { return directions_[static_cast<std::size_t>(j)]; }
  /// Solid angle of bin j (sr); the bins sum to 4 pi.
  float solid_angle(int j) const { return solid_angles_[static_cast<std::size_t>(j)]; }
  /// Smallest bin solid angle (the oracle's threshold).
  float min_solid_angle() const { return min_solid_angle_; }
  /// Octahedral cell centre (u, v in [0,1]^2) mapped to the sphere.
  static glm::vec3 octahedral_direction(glm::vec2 uv);
  static glm::vec2 octahedral_uv(const glm::vec3& d);

 private:
  int n_ = 1;
  std::vector<glm::vec3> directions_;
  std::vector<float> solid_angles_;
  float min_solid_angle_ = 0.0f;
};

}  // namespace gi
