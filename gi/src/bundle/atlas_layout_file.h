#pragma once
// <method>_layout.bin: the atlas layout a method was baked on (per static instance its UV1,
// vertex split and triangle charts; the charts' texel rectangles), written by the bake so a
// load reads it instead of re-charting the geometry. The checksummed container of
// io/blob_file.h with magic "GIATLAYT", version 1.
//   gi::write_atlas_layout_file(dir / "prm_layout.bin", layout, gi::scene_geometry_hash(input));
//   auto file = gi::read_atlas_layout_file(dir / "prm_layout.bin");
//
// Payload (little-endian; "array" = uint64 count then the elements):
//   string  geometry_hash       (uint64 length + chars) the scene the layout belongs to
//   int32 width, int32 height, float32 texels_per_metre, float32 requested_texels_per_metre,
//   int32 padding_texels
//   uint64  body_bytes          size of the body once decompressed
//   array<uint8> body           one zstd frame (io/zstd_stream.h) of:
//     uint64 chart count, then per chart: uint32 mesh, int32 origin x, y, int32 size x, y,
//       vec3 normal, uint32 triangle_count, float64 area_m2
//     uint64 mesh count, then per mesh: int64 id, array<uint32> indices,
//       array<uint32> source_vertex, array<vec2> uv1, array<uint32> triangle_chart
// Nothing follows (trailing bytes are an error). The reader checks what the runtime relies
// on: charts inside the atlas, indices inside the mesh's vertices, triangle charts inside
// the chart list, uv1 finite in [0, 1].

#include <engine/result.h>

#include <cstdint>
#include <filesystem>
#include <string>

#include "io/blob_file.h"
#include "uv/atlas_layout.h"

namespace gi {

inline constexpr BlobMagic kAtlasLayoutMagic{"GIATLAYT"};
inline constexpr std::uint32_t kAtlasLayoutVersion = 1;

/// What an atlas layout file holds.
struct AtlasLayoutFile {
  std::string geometry_hash;  ///< gi::scene_geometry_hash of the scene the layout was built from.
  AtlasLayout layout;
};

/// Writes `layout` atomically (body compressed). Error naming `path` when the layout is not
/// self-consistent (the checks the reader makes) or the write fails.
engine::Status write_atlas_layout_file(const std::filesystem::path& path, const AtlasLayout& layout,
                                       const std::string& geometry_hash);

/// XXH3-64 of everything the layout file holds but the geometry hash: what a file computed
/// over a layout (antiradiance's texel blends) records to recognise it at load.
std::uint64_t atlas_layout_fingerprint(const AtlasLayout& layout);

/// Reads and checks an atlas layout file. Errors name the file and what is wrong: the
/// container's checks (missing, truncated, wrong magic or version, checksum mismatch), a
/// truncated or corrupt body, or a layout that breaks the invariants above.
engine::Result<AtlasLayoutFile> read_atlas_layout_file(const std::filesystem::path& path);

}  // namespace gi
