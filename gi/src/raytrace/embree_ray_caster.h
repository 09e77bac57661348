#pragma once
// The Embree 3 implementation of RayCaster. Static instances are flattened into world-space
// triangle geometries of the top-level scene (fastest traversal); dynamic instances are
// Embree instances of a per-geometry scene, so moving one only rebuilds the top level.
//   auto rc = gi::make_embree_ray_caster(data);
//   if (!rc) report(rc.error());

#include <memory>

#include <engine/result.h>

#include "raytrace/ray_caster.h"
#include "raytrace/rt_scene_data.h"

namespace gi {

/// Builds the Embree scenes. Errors (invalid indices, non-finite positions, Embree device
/// failures) are returned, not thrown. The caller's data is copied.
engine::Result<std::unique_ptr<RayCaster>> make_embree_ray_caster(const RtSceneData& data);

/// Raw access for the benchmark that compares the wrapper with direct Embree calls: the
/// RTCScene handle (as void*) of an Embree ray caster.
void* embree_scene_handle(const RayCaster& caster);

}  // namespace gi
