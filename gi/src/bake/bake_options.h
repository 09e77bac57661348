#pragma once
// gi::BakeOptions mapped onto each method's settings: the preset first, then every option
// the caller set (a zero option keeps the preset's value), the threads, the seed and the
// stage's progress. The one place a new option reaches a baker.
//   auto settings = gi::atlas_settings(options, stage);
//   if (!settings) return settings.error();  // an unknown preset

#include <engine/result.h>
#include <gi/bake.h>

#include <string>

#include "antiradiance/antiradiance_settings.h"
#include "bake/bake_stage.h"
#include "brf/brf_bake.h"
#include "dlm/dlm.h"
#include "light_atlas/light_atlas.h"
#include "prm/prm.h"

namespace gi {

/// The light atlas's settings (preset, vpls, bounces, texels_per_metre, samples_per_vpl, include_direct).
engine::Result<LightAtlasSettings> atlas_settings(const BakeOptions& o, const BakeStage& stage);
/// The PRM's settings (preset, texels_per_metre).
engine::Result<PrmSettings> prm_settings(const BakeOptions& o, const BakeStage& stage);
/// The directional light maps' settings (preset, texels_per_metre, dlm_directions, dlm_photons).
engine::Result<DlmSettings> dlm_settings(const BakeOptions& o, const BakeStage& stage);
/// The basis radiance fields' settings (preset, brf_basis, brf_spheres); progress is per mesh.
engine::Result<BrfSettings> brf_settings(const BakeOptions& o);
/// Antiradiance (docs/antiradiance.md): antiradiance_preset(preset) (0.8 m leaves, split leaf links,
/// 64 / 144 / 324 bins at preview / medium / high).
AntiradianceSettings antiradiance_settings(const BakeOptions& o);

/// The hash of every option that changes a bake's files (not threads, not the shard fields):
/// what a merge checks its shards against (docs/distributed-bake.md).
std::string bake_settings_hash(const BakeOptions& o);

}  // namespace gi
