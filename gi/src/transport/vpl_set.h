#pragma once
// VPLs spread uniformly over the static surfaces (Schärfig et al. 2016, §3.1): every chart
// of near-coplanar triangles is covered by a jittered grid of sample points; VPLs are picked
// on a coarser jittered grid of the same chart, each sample point belongs to its nearest VPL
// (a Voronoi patch), and the VPL moves to its patch's centroid (one Lloyd step, which keeps
// VPLs away from corners and chart borders). A patch's area is the sum of the areas its
// sample points stand for: eq. 1 (A_j = m_j C) with C computed per chart so every chart's
// area is kept exactly. With one sample per VPL every sample is a VPL (PRM's entry points).
//   gi::VplSet vpls = gi::distribute_vpls(scene, index, {.vpl_count = 1000}).value();

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>

#include "raytrace/reference_scene.h"
#include "transport/point_emitters.h"

namespace gi {

struct VplDistributionSettings {
  int vpl_count = 1000;      ///< Target over all static surfaces (the result is close, not exact).
  int samples_per_vpl = 10;  ///< Target sample points per VPL.
  std::uint64_t seed = 1;
};

/// Structure of arrays; sample points of VPL j are [sample_first[j], sample_first[j + 1]).
struct VplSet {
  std::vector<glm::vec3> position;          ///< On the surface, metres.
  std::vector<glm::vec3> normal;            ///< Unit, front side of the patch.
  std::vector<glm::vec3> albedo;            ///< Hemispherical reflectance of the patch's material (RGB).
  std::vector<float> area_m2;               ///< Patch area A_j.
  std::vector<std::uint32_t> sample_first;  ///< size() + 1 entries.
  std::vector<glm::vec3> sample_position;   ///< Sample points S_jk, metres.
  std::vector<glm::vec3> sample_normal;     ///< Unit geometric normal at S_jk.
  std::vector<float> sample_area_m2;        ///< Area each sample point stands for.

  std::size_t size() const { return position.size(); }
  std::uint32_t sample_count(std::size_t j) const { return sample_first[j + 1] - sample_first[j]; }
};

/// Irradiance per watt of VPL i's reflected power at point p (unit normal n) standing for
/// `receiver_area_m2`: the patch as the Lambertian emitters of its sample points, each
/// carrying its share a_l / A_i (the patch-to-point form factor; no visibility). Evaluating
/// every sample point instead of the VPL centre keeps the near-field regularization at the
/// scale of one sample's area rather than the whole patch's.
inline float patch_kernel(const VplSet& vpls, std::size_t i, const glm::vec3& p, const glm::vec3& n,
                          float receiver_area_m2) {
  float sum = 0.0f;
  for (std::uint32_t l = vpls.sample_first[i]; l < vpls.sample_first[i + 1]; ++l)
    sum += vpls.sample_area_m2[l] * lambertian_kernel(vpls.sample_position[l], vpls.sample_normal[l],
                                                      vpls.sample_area_m2[l], false, p, n, receiver_area_m2);
  return sum / vpls.area_m2[i];
}

/// One sample point of VPL i chosen by a hash of `key` (and `seed`): the end of a
/// visibility ray, so a VPL's shadow is that of its patch, not of one point.
inline std::uint32_t pick_sample(const VplSet& vpls, std::size_t i, std::uint64_t key, std::uint64_t seed = 0) {
  std::uint64_t h = key + 0x9e3779b97f4a7c15ULL * (seed + 1);
  h = (h ^ (h >> 30)) * 0xbf58476d1ce4e5b9ULL;
  h = (h ^ (h >> 27)) * 0x94d049bb133111ebULL;
  h ^= h >> 31;
  return vpls.sample_first[i] + static_cast<std::uint32_t>(h % vpls.sample_count(i));
}

/// VPLs over the triangles of the instances of `scene` whose `dynamic` flag is false.
/// Triangles are charted per instance (uv/chart_builder.h). Errors: no static surface area,
/// settings out of range.
engine::Result<VplSet> distribute_vpls(const ReferenceScene& scene, const ReferenceSceneIndex& index,
                                       const VplDistributionSettings& settings);

}  // namespace gi
