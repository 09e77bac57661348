#pragma once
// The on-disk cache of reference data. A reference is computed once per (scene content,
// provider kind and version, request key) and stored as one small binary file:
//   offset 0   8 bytes  magic "GIREFCH\0"
//          8   u32      format version (1)
//         12   u32      key length K
//         16   u64      payload length P
//         24   K bytes  the full cache key (checked on load: a hash collision is never used)
//       24+K   P bytes  payload: i32 width, i32 height, u32 has_mask, 3*w*h f32, [w*h u8 mask]
//     24+K+P   u64      XXH3-64 checksum of every byte before it
// little-endian. Writes are atomic (write_file_atomically). A missing file is a miss; a
// truncated, corrupt or mismatching file is reported with the reason and never used.
//   gi::ReferenceCache cache("out/cache");
//   auto got = gi::fetch_reference(cache, provider, scene, request, 0, progress);

#include <engine/result.h>
#include <gi/rgb_field.h>

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "sweep/sweep_method.h"

namespace gi {

/// "scene=<content hash>;provider=<kind>@<version>;request=<request key>".
std::string reference_cache_key(const SweepScene& scene, const ReferenceProvider& provider,
                                const ReferenceRequest& request);

/// The file bytes of a cache entry. Precondition: field.consistent().
std::string encode_reference(std::string_view key, const RgbField& field);
/// Decodes and checks a cache entry. Errors (file = `source`): too short, wrong magic or
/// version, sizes that disagree with the file length, bad checksum, a different key.
engine::Result<RgbField> decode_reference(std::string_view bytes, std::string_view expected_key,
                                          const std::string& source);

class ReferenceCache {
 public:
  /// `dir` is created on the first store. An empty dir disables the disk cache.
  explicit ReferenceCache(std::filesystem::path dir) : dir_(std::move(dir)) {}

  bool enabled() const { return !dir_.empty(); }
  /// "<dir>/<16 hex digits of the key's hash>.giref".
  std::filesystem::path file_for(std::string_view key) const;
  /// nullopt: no entry. Error: an entry exists but cannot be used (the reason).
  engine::Result<std::optional<RgbField>> load(std::string_view key) const;
  /// Stores an entry atomically. Errors: the directory or file cannot be written.
  engine::Status store(std::string_view key, const RgbField& field) const;

 private:
  std::filesystem::path dir_;
};

/// A reference and where it came from.
struct ReferenceFetch {
  RgbField field;
  std::string key;  ///< The full cache key.
  bool from_cache = false;
  std::string warning;  ///< Non-empty when a cache entry was discarded or could not be written.
};

/// Loads the reference from the cache or computes it with `provider` and stores it.
/// Errors: the provider failed or was cancelled, or returned an inconsistent field.
engine::Result<ReferenceFetch> fetch_reference(const ReferenceCache& cache, const ReferenceProvider& provider,
                                               const SweepScene& scene, const ReferenceRequest& request,
                                               unsigned threads, const ProgressFn& progress);

}  // namespace gi
