#pragma once
// manifest.json of a bake bundle (a directory "scene.gibake/"): the format version, the
// geometry hash the bundle was baked from, the scene's file name and one entry per method
// (its files, settings, statistics and timings, as the method chooses).
//   auto m = gi::read_manifest("level.gibake");
//   if (m && m->geometry_hash != gi::scene_geometry_hash(asset)) { /* stale */ }
//
//   { "format_version": 3, "geometry_hash": "0123456789abcdef", "scene": "level.gltf",
//     "methods": { "light_atlas": { "files": {...}, "settings": {...}, ... } } }

#include <engine/result.h>
#include <gi/bake_input.h>

#include <filesystem>
#include <string>
#include <nlohmann/json.hpp>

namespace gi {

// 3: the atlas methods' layouts are bundle files (files.layout), read at load, not rebuilt;
// 2: XXH3-64 checksums and hashes ("xxh3_64"); 1 (FNV-1a). Older versions are refused with "re-bake".
inline constexpr int kManifestFormatVersion = 3;
inline constexpr const char* kManifestFileName = "manifest.json";

struct Manifest {
  int format_version = kManifestFormatVersion;
  std::string geometry_hash;                          ///< gi::scene_geometry_hash of the baked scene.
  std::string scene;                                  ///< File name of the baked scene (informative only).
  nlohmann::json methods = nlohmann::json::object();  ///< Method name -> its entry (any JSON).
  /// The effect plan the bundle was baked under (gi/src/plan/plan_json.h); null when absent.
  nlohmann::json plan;
};

/// Reads DIR/manifest.json. Errors (naming the file): missing, malformed JSON, a
/// format_version this build does not read, missing or mistyped fields.
engine::Result<Manifest> read_manifest(const std::filesystem::path& bundle_dir);

/// read_manifest, then the check every loader makes first: the bundle was baked from the
/// geometry of `input`. Error otherwise, naming manifest.json, both hashes and what to do
/// (`rebake`, e.g. "re-bake the PRM").
engine::Result<Manifest> read_current_manifest(const std::filesystem::path& bundle_dir, const BakeInput& input,
                                               const std::string& rebake);

/// Writes DIR/manifest.json atomically (pretty-printed, keys sorted). DIR must exist.
engine::Status write_manifest(const std::filesystem::path& bundle_dir, const Manifest& manifest);

/// Sets methods[method] = entry in DIR/manifest.json, keeping the other methods' entries
/// when the existing manifest was baked from the same geometry_hash. A missing manifest,
/// one that does not read (see read_manifest) or one of other geometry is replaced: its
/// entries would describe files of another bake. DIR must exist.
engine::Status update_manifest_method(const std::filesystem::path& bundle_dir, const std::string& geometry_hash,
                                      const std::string& scene, const std::string& method, const nlohmann::json& entry);

/// Sets the manifest's "plan" section, keeping the methods' entries when the existing
/// manifest was baked from the same geometry_hash (as update_manifest_method). DIR must exist.
engine::Status update_manifest_plan(const std::filesystem::path& bundle_dir, const std::string& geometry_hash,
                                    const std::string& scene, const nlohmann::json& plan);

/// The entry of `method`; error (naming the manifest) when the bundle has none.
engine::Result<nlohmann::json> manifest_method(const std::filesystem::path& bundle_dir, const Manifest& manifest,
                                               const std::string& method);

}  // namespace gi
