#pragma once
// Final shooting into the light atlas (Schärfig et al. 2016, §4.1, eq. 9): every texel
// receives the irradiance sum_i F'_i(texel) E_i of the VPLs it sees. On the CPU the paper's
// projection of a VPL's view into the atlas becomes one shadow ray per (texel, VPL); in place
// of the paper's percentage-closer soft shadows (§4.3) each (texel, VPL) pair connects to
// one of the VPL's sample points, chosen by a hash of (seed, texel, VPL), so a VPL acts as
// the area light its patch is and shadow edges are soft rather than banded. The choice is a
// pure function of (seed, texel, VPL): re-shooting a VPL's power difference (§6.2) hits
// exactly the same points.
//   std::vector<glm::vec3> e = gi::shoot_into_atlas(vpls, shooters, powers, texels, texel_area, caster, pool, {});

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <engine/result.h>
#include <gi/progress.h>

#include "core/thread_pool.h"
#include "raytrace/ray_caster.h"
#include "transport/point_emitters.h"
#include "transport/vpl_set.h"
#include "uv/atlas_rasterizer.h"

namespace gi {

struct FinalShootingSettings {
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

struct FinalShootingResult {
  std::vector<glm::vec3> irradiance;  ///< Per texel (width x height); 0 on invalid texels.
  std::uint64_t rays = 0;
};

/// Irradiance at every valid texel from the VPLs `shooters` (indices into vpls) with powers
/// `power[k]` (W, RGB, may be negative for differences). `texel_area_m2` is the area one texel
/// stands for (the receiver area of the regularized kernel). Errors: cancelled.
engine::Result<FinalShootingResult> shoot_into_atlas(const VplSet& vpls, const std::vector<std::uint32_t>& shooters,
                                                     const std::vector<glm::vec3>& power, const AtlasTexels& texels,
                                                     float texel_area_m2, const RayCaster& caster, ThreadPool& pool,
                                                     const FinalShootingSettings& settings);

/// Direct irradiance of the point emitters at every valid texel (the optional direct term).
std::vector<glm::vec3> direct_into_atlas(const std::vector<PointEmitter>& emitters, const AtlasTexels& texels,
                                         float texel_area_m2, const RayCaster& caster, ThreadPool& pool,
                                         std::uint64_t* rays = nullptr);

}  // namespace gi
