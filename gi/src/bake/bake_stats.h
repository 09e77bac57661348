#pragma once
// bake_stats.json (docs/bake-bundle.md): per method, when and where it was baked, with how
// many threads and how long each stage took. Everything that differs between two bakes of
// the same scene, settings and seed lives here and nowhere else, so the manifest and the
// method files are byte-identical across runs and thread counts. No loader reads it.
//   nlohmann::json baked = {{"prm", {{"seconds", 12.5}, {"stages", {{"walk_seconds", 8.1}}}}}};
//   if (auto ok = gi::update_bake_stats(staging_dir, baked, options.threads); !ok) return ok.error();

#include <engine/result.h>

#include <cstdint>
#include <filesystem>
#include <string>
#include <nlohmann/json.hpp>

namespace gi {

/// Sets the entries of `baked` (manifest method name -> {"seconds", "stages"}) in
/// DIR/bake_stats.json, each stamped with the threads used (`threads_requested`, 0: all),
/// the hardware's threads, the host and the UTC time. Entries of methods baked earlier are
/// kept while DIR/manifest.json still lists them. Written atomically.
engine::Status update_bake_stats(const std::filesystem::path& dir, const nlohmann::json& baked,
                                 unsigned threads_requested);

/// Sum of the sizes of the files DIR/manifest.json lists for `method` (entry.files.<k>.file);
/// 0 when the manifest or the entry is missing.
std::uint64_t method_bytes(const std::filesystem::path& dir, const std::string& method);

}  // namespace gi
