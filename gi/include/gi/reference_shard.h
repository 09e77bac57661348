#pragma once
// Distributed path-traced references (docs/distributed-bake.md "Path-traced references"):
// a reference job — a camera image, a light atlas's ground truth, or both — split into N
// shards by blocks of 64 pixels / valid texels (block b to shard b mod N), each shard
// computed by its own process into a checksummed shard file, and the merge that checks every
// shard is there once, of this scene and these settings, and puts the values in place. The
// merged result is bit-identical to render_reference_job (each pixel or texel draws from its
// own random stream, as for any thread count).
//   gi::ReferenceJob job{.atlas = gi::ReferenceAtlasJob{.texels_per_metre = 32.0f},
//                        .settings = {.samples_per_pixel = 256}};
//   gi::reference_shard(input, job, 3, 8, "out/cbox_atlas.shards");   // one process per shard
//   auto all = gi::merge_reference_shards(input, job, "out/cbox_atlas.shards");  // == render_reference_job

#include <engine/image.h>
#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/reference.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace gi {

struct ReferenceImageJob {
  ReferenceCamera camera;
  int width = 256;
  int height = 256;
};

struct ReferenceAtlasJob {
  float texels_per_metre = 0.0f;
  TexelPlacement placement = TexelPlacement::VisibleSurface;
};

/// What a reference run computes. settings.threads and settings.progress (used for each
/// part in turn) do not change the result; every other field does, and enters the shard
/// files' settings hash.
struct ReferenceJob {
  std::optional<ReferenceImageJob> image;
  std::optional<ReferenceAtlasJob> atlas;
  ReferenceSettings settings;
};

struct ReferenceOutputs {
  std::optional<engine::ImageRgbaF> image;  ///< render_reference_image's.
  std::optional<AtlasReference> atlas;      ///< reference_atlas's.
};

/// The whole job in this process: render_reference_image and reference_atlas.
engine::Result<ReferenceOutputs> render_reference_job(const BakeInput& input, const ReferenceJob& job);

/// "shard-0003-of-0007.girefshard" for shard 3 of 7.
std::string reference_shard_file_name(std::uint32_t index, std::uint32_t count);

/// Computes shard `index` of `count` of `job` and writes it atomically to
/// shard_dir / reference_shard_file_name(index, count) (the directory is created). Returns
/// that path. Errors: index >= count, no part in the job, the reference's own errors.
engine::Result<std::filesystem::path> reference_shard(const BakeInput& input, const ReferenceJob& job,
                                                      std::uint32_t index, std::uint32_t count,
                                                      const std::filesystem::path& shard_dir);

/// Reads every *.girefshard in `shard_dir` and assembles the job's outputs. `count` 0: N
/// from the first file in name order. Errors name the shard file: missing, duplicated (two
/// files of the same I), damaged (checksum, truncated, magic, version), foreign (other N,
/// scene, settings, seed or parts), texels or pixels that are not that shard's blocks.
/// Nothing is written.
engine::Result<ReferenceOutputs> merge_reference_shards(const BakeInput& input, const ReferenceJob& job,
                                                        const std::filesystem::path& shard_dir,
                                                        std::uint32_t count = 0);

}  // namespace gi
