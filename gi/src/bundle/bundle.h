#pragma once
// A bake bundle ("scene.gibake/", DESIGN.md §5): manifest.json plus one or more files per
// method. This header gathers its pieces:
//   - bake/geometry_hash.h  scene_geometry_hash: what a bake depends on, to detect stale bundles;
//   - bake/blob_file.h      write_file_atomic, the checksummed binary container (write/read_blob);
//   - bake/manifest.h       manifest.json: format version, geometry hash, per-method entries.
// Every writer writes a temporary file and renames it; every reader checks what it reads
// and returns an engine::Error naming the file.
//   auto m = gi::read_manifest(dir);
//   if (m && m->geometry_hash != gi::scene_geometry_hash(asset)) std::cerr << "stale bundle\n";

#include <string_view>

#include "bundle/geometry_hash.h"
#include "bundle/manifest.h"
#include "io/blob_file.h"

namespace gi {

/// True for a plain file name a manifest may reference (no directories, not "." or ".."),
/// so a manifest can never make a loader read outside its bundle.
bool is_bundle_file_name(std::string_view name);

}  // namespace gi
