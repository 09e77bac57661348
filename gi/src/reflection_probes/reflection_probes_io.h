#pragma once
// Saving baked reflection probes into a bundle directory and loading them back for a scene.
//   gi::save_reflection_probes("level.gibake", probes, input);
//   auto probes = gi::load_reflection_probes("level.gibake", input);   // stale / truncated: an error naming the file
//
// Files (DESIGN.md §5):
//   reflection_probes.bin  blob "GIRPROBE" v2 (io/blob_file.h): the geometry hash, the
//                          settings, per probe its centre and box (9 float32), then per probe
//                          per level 6 x s x s RGB float32 (probe_cube.h's order) and its
//                          level 0's 6 x s x s distances (float32, ProbeCube::distance).
//                          Version 1 (no distances) is refused: re-bake.
//   manifest.json          methods.reflection_probes = {
//     "files": { "probes": {"file": "reflection_probes.bin", "xxh3_64": "<hex>"} },
//     "lights_hash", "settings", "probes", "resolution", "levels", "stats", "memory" }

#include <engine/result.h>
#include <gi/bake_input.h>

#include <filesystem>
#include <string>

#include "io/blob_file.h"
#include "reflection_probes/reflection_probes.h"

namespace gi {

inline constexpr const char* kReflectionProbesFile = "reflection_probes.bin";
inline constexpr BlobMagic kReflectionProbesMagic{"GIRPROBE"};
inline constexpr std::uint32_t kReflectionProbesVersion = 3;  // 3: the distances' face size

/// The file's content: the probes and the geometry hash they were baked for.
struct ReflectionProbesFile {
  std::string geometry_hash;
  ReflectionProbeSet set;
};

/// Writes the file alone (atomically). Error when the set's arrays do not fit together.
engine::Status write_reflection_probes_file(const std::filesystem::path& path, const ReflectionProbeSet& set,
                                            const std::string& geometry_hash);
/// Reads the file alone: every error (truncated, corrupt, values out of range) names it.
engine::Result<ReflectionProbesFile> read_reflection_probes_file(const std::filesystem::path& path);

/// Writes the file and the manifest's entry (other methods' entries are kept).
engine::Status save_reflection_probes(const std::filesystem::path& bundle_dir, const ReflectionProbeSet& set,
                                      const BakeInput& input);

/// Loads the probes of `bundle_dir` for `input` through the one reader path: the manifest,
/// the geometry hash, the static lights' hash, the file's checksum, then its payload.
engine::Result<ReflectionProbeSet> load_reflection_probes(const std::filesystem::path& bundle_dir,
                                                          const BakeInput& input);

}  // namespace gi
