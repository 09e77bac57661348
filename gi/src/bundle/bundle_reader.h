#pragma once
// The one reader path of a bake bundle: what every method's loader does before its payload.
// A BundleReader opens a method's entry in manifest.json (the manifest read, the bundle's
// geometry checked against the scene, the entry present), hands out the files the entry
// names once their names stay inside the bundle and their checksums match, checks a
// payload's geometry hash and static-lights hash, and reads the atlas layout the bake wrote
// (files.layout, bundle/atlas_layout_file.h). Its errors name the file and the problem, so the loaders' errors read
// alike.
//   auto bundle = gi::BundleReader::open(dir, gi::kDlmMethod, input, "re-bake the directional light maps");
//   if (!bundle) return bundle.error();
//   auto path = bundle->file("maps");  // files.maps.{file,xxh3_64}

#include <engine/result.h>
#include <gi/bake_input.h>

#include <filesystem>
#include <string>
#include <nlohmann/json.hpp>

#include "bundle/manifest.h"
#include "io/json_fields.h"
#include "uv/atlas_layout.h"

namespace gi {

/// The atlas layout a method's entry records ("layout": requested and achieved density,
/// padding, size): what the layout file (files.layout) must agree with.
struct BakedAtlasLayout {
  float requested_texels_per_metre = 0.0f;
  float texels_per_metre = 0.0f;
  int padding_texels = 0;
  int width = 0;
  int height = 0;
};

/// Reads the entry's "layout" fields (or `key`'s) into `f`'s error state (check f.error() afterwards).
BakedAtlasLayout read_baked_atlas_layout(JsonFields& f, const std::string& key = "layout");

/// The "layout" object a writer stores for `layout` (read back by read_baked_atlas_layout).
nlohmann::json baked_atlas_layout_json(const AtlasLayout& layout);

/// Writes DIR/<file_name> (write_atlas_layout_file) and returns its manifest entry
/// {"file", "xxh3_64"}, which a writer stores as "files.layout".
engine::Result<nlohmann::json> write_bundle_atlas_layout(const std::filesystem::path& bundle_dir,
                                                         const std::string& file_name, const AtlasLayout& layout,
                                                         const std::string& geometry_hash);

class BundleReader {
 public:
  /// Opens `method`'s entry of the bundle in `bundle_dir` baked from the geometry of `input`.
  /// Errors name manifest.json: missing or unreadable, baked from other geometry (the
  /// message ends in what to do, `rebake`), or without an entry for `method`.
  static engine::Result<BundleReader> open(const std::filesystem::path& bundle_dir, const std::string& method,
                                           const BakeInput& input, const std::string& rebake);
  /// As open, without the geometry check: for a method whose files carry their own hashes
  /// (the BRF's meshes).
  static engine::Result<BundleReader> open_any_geometry(const std::filesystem::path& bundle_dir,
                                                        const std::string& method);

  const std::filesystem::path& dir() const { return dir_; }
  /// DIR/manifest.json, the file the entry's errors name.
  const std::filesystem::path& manifest_file() const { return manifest_file_; }
  const Manifest& manifest() const { return manifest_; }
  /// The method's entry ("methods.<method>").
  const nlohmann::json& entry() const { return entry_; }
  /// "methods.<method>": the entry's location in manifest.json.
  const std::string& prefix() const { return prefix_; }
  /// Typed reads of the entry's fields, errors located in manifest.json under prefix().
  JsonFields fields() const { return JsonFields(entry_, manifest_file_.string(), prefix_); }
  /// An error in manifest.json at prefix() + "." + key (prefix() alone when key is empty).
  engine::Error entry_error(const std::string& key, std::string message) const;

  /// True when the entry lists "files.<key>".
  bool has_file(const std::string& key) const;
  /// DIR/<name> of the entry's "files.<key>" {"file", "xxh3_64"}: errors when a field is
  /// missing, the name would leave the bundle, or the file's checksum differs.
  engine::Result<std::filesystem::path> file(const std::string& key) const;

  /// Error naming `file` unless `geometry_hash` (the one its payload starts with) is the manifest's.
  engine::Status check_geometry(const std::filesystem::path& file, const std::string& geometry_hash) const;
  /// Error naming manifest.json unless `baked_lights_hash` (the entry's "lights_hash") is
  /// the static lights hash of `input`: "stale <what> in DIR: ... (<advice>)".
  engine::Status check_lights(const std::string& baked_lights_hash, const BakeInput& input, const std::string& what,
                              const std::string& advice) const;
  /// The atlas layout the bake wrote (the entry's files.layout), checked: its checksum, its
  /// geometry hash, its size and densities against `baked`, and one mesh per static instance
  /// of `input` with that instance's id and vertex count. Nothing is rebuilt from geometry.
  /// `what` names the atlas in errors ("PRM atlas layout"); `key`: the files entry
  /// (files.<key>) when an entry stores more than one layout.
  engine::Result<AtlasLayout> atlas_layout(const BakeInput& input, const BakedAtlasLayout& baked,
                                           const std::string& what, const std::string& key = "layout") const;

 private:
  BundleReader(std::filesystem::path dir, Manifest manifest, nlohmann::json entry, const std::string& method);

  std::filesystem::path dir_;
  std::filesystem::path manifest_file_;
  Manifest manifest_;
  nlohmann::json entry_;
  std::string prefix_;
};

}  // namespace gi
