#include "bundle/bundle_reader.h"

#include <utility>

#include "bundle/atlas_layout_file.h"
#include "bundle/bundle.h"

namespace gi {

namespace fs = std::filesystem;
using nlohmann::json;

BakedAtlasLayout read_baked_atlas_layout(JsonFields& f, const std::string& key) {
  BakedAtlasLayout l;
  l.requested_texels_per_metre = f.get<float>(key + ".requested_texels_per_metre");
  l.texels_per_metre = f.get<float>(key + ".texels_per_metre");
  l.padding_texels = f.get<int>(key + ".padding_texels");
  l.width = f.get<int>(key + ".width");
  l.height = f.get<int>(key + ".height");
  return l;
}

json baked_atlas_layout_json(const AtlasLayout& layout) {
  return json{{"requested_texels_per_metre", layout.requested_texels_per_metre},
              {"texels_per_metre", layout.texels_per_metre},
              {"padding_texels", layout.padding_texels},
              {"width", layout.width},
              {"height", layout.height}};
}

engine::Result<json> write_bundle_atlas_layout(const fs::path& bundle_dir, const std::string& file_name,
                                               const AtlasLayout& layout, const std::string& geometry_hash) {
  const fs::path path = bundle_dir / file_name;
  if (engine::Status s = write_atlas_layout_file(path, layout, geometry_hash); !s) return s.error();
  auto sum = file_checksum(path);
  if (!sum) return sum.error();
  return json{{"file", file_name}, {"xxh3_64", *sum}};
}

BundleReader::BundleReader(fs::path dir, Manifest manifest, json entry, const std::string& method)
    : dir_(std::move(dir)),
      manifest_file_(dir_ / kManifestFileName),
      manifest_(std::move(manifest)),
      entry_(std::move(entry)),
      prefix_("methods." + method) {}

engine::Result<BundleReader> BundleReader::open(const fs::path& bundle_dir, const std::string& method,
                                                const BakeInput& input, const std::string& rebake) {
  auto manifest = read_current_manifest(bundle_dir, input, rebake);
  if (!manifest) return manifest.error();
  auto entry = manifest_method(bundle_dir, *manifest, method);
  if (!entry) return entry.error();
  return BundleReader(bundle_dir, std::move(manifest).value(), std::move(entry).value(), method);
}

engine::Result<BundleReader> BundleReader::open_any_geometry(const fs::path& bundle_dir, const std::string& method) {
  auto manifest = read_manifest(bundle_dir);
  if (!manifest) return manifest.error();
  auto entry = manifest_method(bundle_dir, *manifest, method);
  if (!entry) return entry.error();
  return BundleReader(bundle_dir, std::move(manifest).value(), std::move(entry).value(), method);
}

engine::Error BundleReader::entry_error(const std::string& key, std::string message) const {
  return engine::Error{manifest_file_.string(), key.empty() ? prefix_ : prefix_ + "." + key, std::move(message)};
}

bool BundleReader::has_file(const std::string& key) const {
  return entry_.is_object() && entry_.contains("files") && entry_["files"].is_object() && entry_["files"].contains(key);
}

engine::Result<fs::path> BundleReader::file(const std::string& key) const {
  JsonFields f = fields();
  const std::string name = f.get<std::string>("files." + key + ".file");
  const std::string checksum = f.get<std::string>("files." + key + ".xxh3_64");
  if (f.error()) return *f.error();
  if (!is_bundle_file_name(name))
    return entry_error("files." + key + ".file", "\"" + name + "\" is not a file name inside the bundle");
  const fs::path path = dir_ / name;
  if (engine::Status s = check_file_checksum(path, checksum); !s) return s.error();
  return path;
}

engine::Status BundleReader::check_geometry(const fs::path& file, const std::string& geometry_hash) const {
  if (geometry_hash == manifest_.geometry_hash) return {};
  return engine::Error{file.string(), "",
                       "belongs to geometry " + geometry_hash + ", the manifest to " + manifest_.geometry_hash};
}

engine::Status BundleReader::check_lights(const std::string& baked_lights_hash, const BakeInput& input,
                                          const std::string& what, const std::string& advice) const {
  const std::string lights = static_lights_hash(input);
  if (baked_lights_hash == lights) return {};
  return entry_error("lights_hash", "stale " + what + " in " + dir_.string() + ": baked under static lights " +
                                        baked_lights_hash + ", but the scene's static lights hash to " + lights + " (" +
                                        advice + ")");
}

namespace {

// "32x16, 8 texels/m (requested 8), padding 2": a layout as the errors show it.
std::string describe(int width, int height, float density, float requested, int padding) {
  return std::to_string(width) + "x" + std::to_string(height) + ", " + std::to_string(density) +
         " texels/m (requested " + std::to_string(requested) + "), padding " + std::to_string(padding);
}

// Empty when `layout` has one mesh per static instance of `input`, with its id and vertex
// count (what the renderer pairs UV1 with), else what differs.
std::string layout_scene_mismatch(const AtlasLayout& layout, const BakeInput& input) {
  std::size_t m = 0;
  for (const BakeInstance& inst : input.instances) {
    if (inst.mobility != BakeMobility::Static || inst.mesh >= input.meshes.size()) continue;
    if (m >= layout.meshes.size())
      return "it holds " + std::to_string(layout.meshes.size()) + " meshes, the scene has more static instances";
    const AtlasMeshUv& mesh = layout.meshes[m];
    std::size_t vertices = 0, indices = 0;
    for (const BakePrimitive& prim : input.meshes[inst.mesh].primitives) {
      vertices += prim.positions.size();
      indices += prim.indices.size();
    }
    if (mesh.id != inst.id || mesh.indices.size() != indices)
      return "mesh " + std::to_string(m) + " is not static instance " + std::to_string(inst.id) + "'s";
    for (std::uint32_t v : mesh.source_vertex)
      if (v >= vertices) return "mesh " + std::to_string(m) + " names a vertex beyond the instance's";
    ++m;
  }
  if (m != layout.meshes.size())
    return "it holds " + std::to_string(layout.meshes.size()) + " meshes for " + std::to_string(m) +
           " static instances";
  return {};
}

}  // namespace

engine::Result<AtlasLayout> BundleReader::atlas_layout(const BakeInput& input, const BakedAtlasLayout& baked,
                                                       const std::string& what, const std::string& key) const {
  if (!has_file(key))
    return entry_error("files." + key, "no " + what +
                                           " file: the bundle was baked before bakes wrote their layouts "
                                           "(re-bake)");
  auto path = file(key);
  if (!path) return path.error();
  auto read = read_atlas_layout_file(*path);
  if (!read) return read.error();
  if (engine::Status s = check_geometry(*path, read->geometry_hash); !s) return s.error();
  AtlasLayout& layout = read->layout;
  if (layout.width != baked.width || layout.height != baked.height ||
      layout.texels_per_metre != baked.texels_per_metre ||
      layout.requested_texels_per_metre != baked.requested_texels_per_metre ||
      layout.padding_texels != baked.padding_texels)
    return engine::Error{path->string(), "",
                         "the " + what + " (" +
                             describe(layout.width, layout.height, layout.texels_per_metre,
                                      layout.requested_texels_per_metre, layout.padding_texels) +
                             ") differs from the one the manifest describes (" +
                             describe(baked.width, baked.height, baked.texels_per_metre,
                                      baked.requested_texels_per_metre, baked.padding_texels) +
                             ") (re-bake)"};
  if (std::string problem = layout_scene_mismatch(layout, input); !problem.empty())
    return engine::Error{path->string(), "", "the " + what + " does not fit the scene: " + problem + " (re-bake)"};
  return std::move(read->layout);
}

}  // namespace gi
