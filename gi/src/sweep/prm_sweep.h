#pragma once
// PRM in the sweep harness: knobs entry points x clusters x active clusters K x pane
// density x splitting factor x light pose, judged against the reference path tracer's
// per-texel indirect irradiance with the moving light at the same pose
// (docs/sweeps/README.md). Poses: "authored" (as in the scene file), "corner" (low in a
// corner of the static bounds, facing the centre), "wall" (1 cm from the +x wall of the
// static bounds, shining down along it), "along" (the authored position moved by 30% of
// the static bounds' x extent along +x), "wall20" (the authored position moved horizontally
// to 20 cm from the nearest static surface along +-x or +-z).

#include <engine/scene_asset.h>

#include <cstdint>
#include <string>

#include <glm/vec3.hpp>

#include "sweep/sweep_registry.h"
#include "uv/atlas_rasterizer.h"

namespace gi {

/// Keeps `count` of `texels`' valid texels, a fixed random choice (the same for the same
/// atlas), and marks the others invalid: the subset a reference path-traces when the whole
/// atlas would take too long. Every valid texel stays when `count` is not below their number.
void keep_random_texels(AtlasTexels& texels, std::uint64_t count);

/// Where the poses "along" and "wall20" put a light authored at `authored` in `asset`'s
/// static world (see above). Errors: another pose; "wall20" with no static surface more than
/// 20 cm away along +-x and +-z.
engine::Result<glm::vec3> moved_light_position(const engine::SceneAsset& asset, const glm::vec3& authored,
                                               const std::string& pose);

/// Adds the "prm" method and its "atlas_indirect_irradiance_posed" reference provider.
void register_prm_sweep(SweepRegistry& registry);

}  // namespace gi
