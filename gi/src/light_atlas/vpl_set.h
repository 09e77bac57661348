#pragma once
// VPLs spread uniformly over the static surfaces (Schärfig et al. 2016, §3.1): every chart
// of near-coplanar triangles is covered by a jittered grid of sample points; VPLs are picked
// on a coarser jittered grid of the same chart, each sample point belongs to its nearest VPL
// (a Voronoi patch), and the VPL moves to its patch's centroid (one Lloyd step, which keeps
// VPLs away from corners and chart borders). A patch's area is the sum of the areas its
// sample points stand for: eq. 1 (A_j = m_j C) with C computed per chart so every chart's
// area is kept exactly.
//   gi::VplSet vpls = gi::distribute_vpls(scene, index, {.vpl_count = 1000}).value();

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>

#include "raytrace/reference_scene.h"

namespace gi {

struct VplDistributionSettings {
  int vpl_count = 1000;      ///< Target over all static surfaces (the result is close, not exact).
  int samples_per_vpl = 10;  ///< Target sample points per VPL.
  std::uint64_t seed = 1;
};

/// Structure of arrays; sample points of VPL j are [sample_first[j], sample_first[j + 1]).
struct VplSet {
  std::vector<glm::vec3> position;       ///< On the surface, metres.
  std::vector<glm::vec3> normal;         ///< Unit, front side of the patch.
  std::vector<glm::vec3> albedo;         ///< Hemispherical reflectance of the patch's material (RGB).
  std::vector<float> area_m2;            ///< Patch area A_j.
  std::vector<std::uint32_t> sample_first;  ///< size() + 1 entries.
  std::vector<glm::vec3> sample_position;   ///< Sample points S_jk, metres.
  std::vector<glm::vec3> sample_normal;     ///< Unit geometric normal at S_jk.
  std::vector<float> sample_area_m2;        ///< Area each sample point stands for.

  std::size_t size() const { return position.size(); }
  std::uint32_t sample_count(std::size_t j) const { return sample_first[j + 1] - sample_first[j]; }
};

/// Directional-hemispherical reflectance of a material's BRDF averaged over cosine-weighted
/// incidence (the energy a diffuse patch of it reflects), estimated with `samples`
/// stratified BRDF samples from a fixed seed. A Lambertian material returns its albedo.
glm::vec3 hemispherical_albedo(const ReferenceMaterial& material, int samples = 4096);

/// VPLs over the triangles of the instances of `scene` whose `dynamic` flag is false.
/// Triangles are charted per instance (uv/chart_builder.h). Errors: no static surface area,
/// settings out of range.
engine::Result<VplSet> distribute_vpls(const ReferenceScene& scene, const ReferenceSceneIndex& index,
                                       const VplDistributionSettings& settings);

}  // namespace gi
