#include "bundle/manifest.h"

#include <engine/json_depth.h>

#include <cstdint>
#include <string_view>

#include "bundle/geometry_hash.h"
#include "io/blob_file.h"

namespace gi {

namespace {

std::filesystem::path manifest_path(const std::filesystem::path& dir) { return dir / kManifestFileName; }

engine::Error manifest_error(const std::filesystem::path& dir, std::string location, std::string message) {
  return engine::Error{manifest_path(dir).string(), std::move(location), std::move(message)};
}

}  // namespace

engine::Result<Manifest> read_manifest(const std::filesystem::path& bundle_dir) {
  const std::filesystem::path path = manifest_path(bundle_dir);
  auto bytes = read_file_bytes(path);
  if (!bytes) {
    engine::Error e = bytes.error();
    e.message += " (not a bake bundle, or not baked yet)";
    return e;
  }
  const auto* text = reinterpret_cast<const char*>(bytes->data());
  nlohmann::json doc = nlohmann::json::parse(text, text + bytes->size(), nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) return manifest_error(bundle_dir, "", "malformed JSON");
  if (!doc.is_object()) return manifest_error(bundle_dir, "", "the top level is not a JSON object");
  // Manifests nest a few levels; copying or walking a crafted deep one would exhaust the stack.
  constexpr std::size_t kMaxManifestDepth = 64;
  if (engine::json_depth(doc, kMaxManifestDepth) > kMaxManifestDepth)
    return manifest_error(bundle_dir, "", "nested deeper than " + std::to_string(kMaxManifestDepth) + " levels");

  const auto field = [&](const char* name, bool (nlohmann::json::*is_type)() const noexcept,
                         const char* type) -> engine::Result<const nlohmann::json*> {
    auto it = doc.find(name);
    if (it == doc.end()) return manifest_error(bundle_dir, name, "missing field");
    if (!((*it).*is_type)()) return manifest_error(bundle_dir, name, std::string("must be ") + type);
    return &*it;
  };
  auto version = field("format_version", &nlohmann::json::is_number_integer, "an integer");
  if (!version) return version.error();
  Manifest m;
  // Compared as read (64 bits): 2^32 + 1 must not narrow to a supported version.
  const std::int64_t read_version = (*version)->get<std::int64_t>();
  m.format_version = kManifestFormatVersion;
  if (read_version != kManifestFormatVersion) {
    return manifest_error(bundle_dir, "format_version",
                          "unsupported format_version " + std::to_string(read_version) + ", this build reads " +
                              std::to_string(kManifestFormatVersion) + " (re-bake)");
  }
  auto hash = field("geometry_hash", &nlohmann::json::is_string, "a string");
  if (!hash) return hash.error();
  m.geometry_hash = (*hash)->get<std::string>();
  auto scene = field("scene", &nlohmann::json::is_string, "a string");
  if (!scene) return scene.error();
  m.scene = (*scene)->get<std::string>();
  auto methods = field("methods", &nlohmann::json::is_object, "an object");
  if (!methods) return methods.error();
  m.methods = **methods;
  if (auto it = doc.find("plan"); it != doc.end()) {
    if (!it->is_object()) return manifest_error(bundle_dir, "plan", "must be an object");
    m.plan = *it;
  }
  return m;
}

engine::Status write_manifest(const std::filesystem::path& bundle_dir, const Manifest& manifest) {
  nlohmann::json doc = nlohmann::json::object();
  doc["format_version"] = manifest.format_version;
  doc["geometry_hash"] = manifest.geometry_hash;
  doc["scene"] = manifest.scene;
  doc["methods"] = manifest.methods.is_object() ? manifest.methods : nlohmann::json::object();
  if (manifest.plan.is_object()) doc["plan"] = manifest.plan;
  const std::string text = doc.dump(2) + "\n";
  return write_file_atomic(manifest_path(bundle_dir),
                           std::span<const std::byte>(reinterpret_cast<const std::byte*>(text.data()), text.size()));
}

engine::Status update_manifest_method(const std::filesystem::path& bundle_dir, const std::string& geometry_hash,
                                      const std::string& scene, const std::string& method,
                                      const nlohmann::json& entry) {
  Manifest m;
  if (auto existing = read_manifest(bundle_dir); existing && existing->geometry_hash == geometry_hash) {
    m = std::move(existing).value();
  }
  m.geometry_hash = geometry_hash;
  m.scene = scene;
  m.methods[method] = entry;
  return write_manifest(bundle_dir, m);
}

engine::Status update_manifest_plan(const std::filesystem::path& bundle_dir, const std::string& geometry_hash,
                                    const std::string& scene, const nlohmann::json& plan) {
  Manifest m;
  if (auto existing = read_manifest(bundle_dir); existing && existing->geometry_hash == geometry_hash) {
    m = std::move(existing).value();
  }
  m.geometry_hash = geometry_hash;
  m.scene = scene;
  m.plan = plan;
  return write_manifest(bundle_dir, m);
}

engine::Result<nlohmann::json> manifest_method(const std::filesystem::path& bundle_dir, const Manifest& manifest,
                                               const std::string& method) {
  auto it = manifest.methods.find(method);
  if (it == manifest.methods.end()) {
    return manifest_error(bundle_dir, "methods",
                          "no \"" + method + "\" entry: the bundle was not baked with " + method);
  }
  if (!it->is_object()) return manifest_error(bundle_dir, "methods." + method, "must be an object");
  return *it;
}

engine::Result<Manifest> read_current_manifest(const std::filesystem::path& bundle_dir, const BakeInput& input,
                                               const std::string& rebake) {
  auto manifest = read_manifest(bundle_dir);
  if (!manifest) return manifest.error();
  const std::string scene_hash = scene_geometry_hash(input);
  if (manifest->geometry_hash != scene_hash) {
    const std::string scene = input.name.empty() ? std::string("the scene") : input.name;
    return engine::Error{(bundle_dir / kManifestFileName).string(), "geometry_hash",
                         "stale bundle " + bundle_dir.string() + ": baked from geometry " + manifest->geometry_hash +
                             ", but " + scene + " hashes to " + scene_hash + " (" + rebake + ")"};
  }
  return manifest;
}

}  // namespace gi
