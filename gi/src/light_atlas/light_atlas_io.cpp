#include "light_atlas/light_atlas_io.h"

#include <engine/image.h>

#include <cmath>
#include <system_error>
#include <nlohmann/json.hpp>

#include "bundle/bundle.h"
#include "io/json_fields.h"
#include "light_atlas/light_atlas_vpl_file.h"
#include "uv/atlas_input.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json settings_json(const LightAtlasSettings& s) {
  return json{{"texels_per_metre", s.texels_per_metre}, {"vpl_count", s.vpl_count},
              {"samples_per_vpl", s.samples_per_vpl},   {"bounces", s.bounces},
              {"unshot_threshold", s.unshot_threshold}, {"area_light_samples", s.area_light_samples},
              {"include_direct", s.include_direct},     {"seed", s.seed}};
}

// What direct light the atlas holds (light_atlas.h, LightAtlasBake::irradiance): "unlit" the
// sky's and that of emitters no light stands for; "all" every static source's.
std::string direct_light_name(const LightAtlasSettings& s) { return s.include_direct ? "all" : "unlit"; }

json stats_json(const LightAtlasStats& s) {
  return json{{"vpls", s.vpls},   {"sample_points", s.sample_points}, {"light_points", s.light_points},
              {"shots", s.shots}, {"valid_texels", s.valid_texels},   {"rays", s.rays}};
}

LightAtlasStats read_stats(JsonFields& f) {
  LightAtlasStats s;
  s.vpls = f.get<std::size_t>("stats.vpls");
  s.sample_points = f.get<std::size_t>("stats.sample_points");
  s.light_points = f.get<std::size_t>("stats.light_points");
  s.shots = f.get<std::size_t>("stats.shots");
  s.valid_texels = f.get<std::size_t>("stats.valid_texels");
  s.rays = f.get<std::uint64_t>("stats.rays");
  return s;
}

// What the manifest entry says about the files and the layout.
struct EntryInfo {
  std::string exr_file, exr_checksum, vpls_file, vpls_checksum, lights_hash, direct_light;
  float requested_texels_per_metre = 0.0f;
  float texels_per_metre = 0.0f;
  int padding_texels = 0;
  int width = 0;
  int height = 0;
  LightAtlasStats stats;
};

engine::Result<EntryInfo> read_entry(const fs::path& manifest_file, const json& entry) {
  JsonFields f(entry, manifest_file.string(), std::string("methods.") + kLightAtlasMethod);
  EntryInfo e;
  e.exr_file = f.get<std::string>("files.irradiance.file");
  e.exr_checksum = f.get<std::string>("files.irradiance.xxh3_64");
  e.vpls_file = f.get<std::string>("files.vpls.file");
  e.vpls_checksum = f.get<std::string>("files.vpls.xxh3_64");
  e.lights_hash = f.get<std::string>("lights_hash");
  // Absent in bundles baked before the atlas held the sky (load_light_atlas says so).
  if (entry.is_object() && entry.contains("direct_light")) e.direct_light = f.get<std::string>("direct_light");
  e.requested_texels_per_metre = f.get<float>("layout.requested_texels_per_metre");
  e.texels_per_metre = f.get<float>("layout.texels_per_metre");
  e.padding_texels = f.get<int>("layout.padding_texels");
  e.width = f.get<int>("layout.width");
  e.height = f.get<int>("layout.height");
  e.stats = read_stats(f);
  if (f.error()) return *f.error();
  for (const std::string* name : {&e.exr_file, &e.vpls_file})
    if (!is_bundle_file_name(*name))
      return engine::Error{manifest_file.string(), "methods.light_atlas.files",
                           "\"" + *name + "\" is not a file name inside the bundle"};
  return e;
}

// Fills irradiance and valid from the EXR, checking its size and values.
engine::Status read_atlas_exr(const fs::path& path, LightAtlasBake& bake) {
  auto image = engine::load_exr(path);
  if (!image) return image.error();
  if (image->width != bake.width || image->height != bake.height)
    return engine::Error{path.string(), "",
                         "size mismatch: the image is " + std::to_string(image->width) + "x" +
                             std::to_string(image->height) + ", the atlas layout is " + std::to_string(bake.width) +
                             "x" + std::to_string(bake.height)};
  const std::size_t texels = static_cast<std::size_t>(bake.width) * static_cast<std::size_t>(bake.height);
  bake.irradiance.resize(texels);
  bake.valid.resize(texels);
  for (std::size_t i = 0; i < texels; ++i) {
    const float* p = &image->pixels[4 * i];
    const auto where = [&] {
      return "texel (" + std::to_string(i % static_cast<std::size_t>(bake.width)) + ", " +
             std::to_string(i / static_cast<std::size_t>(bake.width)) + ")";
    };
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(p[c])) return engine::Error{path.string(), where(), "irradiance is NaN or infinite"};
      if (p[c] < 0.0f) return engine::Error{path.string(), where(), "irradiance is negative"};
    }
    if (p[3] != 0.0f && p[3] != 1.0f)
      return engine::Error{path.string(), where(), "alpha (texel valid) must be 0 or 1, not " + std::to_string(p[3])};
    bake.irradiance[i] = glm::vec3(p[0], p[1], p[2]);
    bake.valid[i] = p[3] == 1.0f ? 1 : 0;
  }
  return {};
}

}  // namespace

engine::Status save_light_atlas(const fs::path& bundle_dir, const LightAtlasBake& bake, const BakeInput& input) {
  const std::string geometry_hash = scene_geometry_hash(input);
  const std::string scene_name = fs::path(input.name).filename().string();
  const std::size_t texels =
      static_cast<std::size_t>(std::max(bake.width, 0)) * static_cast<std::size_t>(std::max(bake.height, 0));
  if (bake.width <= 0 || bake.height <= 0 || bake.width != bake.layout.width || bake.height != bake.layout.height ||
      bake.irradiance.size() != texels || bake.valid.size() != texels)
    return engine::Error{bundle_dir.string(), "",
                         "cannot save the light atlas: its size (" + std::to_string(bake.width) + "x" +
                             std::to_string(bake.height) + ") does not match its layout or arrays"};
  std::error_code ec;
  fs::create_directories(bundle_dir, ec);
  if (ec) return engine::Error{bundle_dir.string(), "", "cannot create the bundle directory: " + ec.message()};

  engine::ImageRgbaF image{bake.width, bake.height, std::vector<float>(texels * 4)};
  for (std::size_t i = 0; i < texels; ++i) {
    image.pixels[4 * i + 0] = bake.irradiance[i].x;
    image.pixels[4 * i + 1] = bake.irradiance[i].y;
    image.pixels[4 * i + 2] = bake.irradiance[i].z;
    image.pixels[4 * i + 3] = bake.valid[i] != 0 ? 1.0f : 0.0f;
  }
  const fs::path exr = bundle_dir / kLightAtlasExrFile;
  const fs::path vpls = bundle_dir / kLightAtlasVplsFile;
  // The VPL file first: it checks the VPL arrays, so a bad bake writes nothing.
  if (engine::Status s = write_light_atlas_vpls(vpls, bake, geometry_hash); !s) return s;
  if (engine::Status s = engine::save_exr(exr, image, engine::ExrPixelType::Float); !s) return s;
  auto exr_sum = file_checksum(exr);
  if (!exr_sum) return exr_sum.error();
  auto vpls_sum = file_checksum(vpls);
  if (!vpls_sum) return vpls_sum.error();

  const json entry{{"files",
                    {{"irradiance", {{"file", kLightAtlasExrFile}, {"xxh3_64", *exr_sum}}},
                     {"vpls", {{"file", kLightAtlasVplsFile}, {"xxh3_64", *vpls_sum}}}}},
                   {"lights_hash", static_lights_hash(input)},
                   {"direct_light", direct_light_name(bake.settings)},
                   {"settings", settings_json(bake.settings)},
                   {"layout",
                    {{"requested_texels_per_metre", bake.layout.requested_texels_per_metre},
                     {"texels_per_metre", bake.layout.texels_per_metre},
                     {"padding_texels", bake.layout.padding_texels},
                     {"width", bake.layout.width},
                     {"height", bake.layout.height}}},
                   {"stats", stats_json(bake.stats)}};
  return update_manifest_method(bundle_dir, geometry_hash, scene_name, kLightAtlasMethod, entry);
}

engine::Result<LightAtlasBake> load_light_atlas(const fs::path& bundle_dir, const BakeInput& input) {
  auto manifest = read_current_manifest(bundle_dir, input, "re-bake");
  if (!manifest) return manifest.error();
  const fs::path manifest_file = bundle_dir / kManifestFileName;
  auto entry_json = manifest_method(bundle_dir, *manifest, kLightAtlasMethod);
  if (!entry_json) return entry_json.error();
  auto entry = read_entry(manifest_file, *entry_json);
  if (!entry) return entry.error();
  if (const std::string lights = static_lights_hash(input); entry->lights_hash != lights)
    return engine::Error{manifest_file.string(), "methods.light_atlas.lights_hash",
                         "stale light atlas in " + bundle_dir.string() + ": baked under static lights " +
                             entry->lights_hash + ", but the scene's static lights hash to " + lights +
                             " (a static light was edited; re-bake, or update it with gi::update_light_atlas)"};

  if (entry->direct_light.empty())
    return engine::Error{manifest_file.string(), "methods.light_atlas.direct_light",
                         "the light atlas in " + bundle_dir.string() +
                             " was baked before the atlas held the sky's direct light (the renderer drew the sky "
                             "unshadowed then); re-bake"};
  const fs::path vpls_path = bundle_dir / entry->vpls_file;
  const fs::path exr_path = bundle_dir / entry->exr_file;
  if (engine::Status s = check_file_checksum(vpls_path, entry->vpls_checksum); !s) return s.error();
  if (engine::Status s = check_file_checksum(exr_path, entry->exr_checksum); !s) return s.error();
  auto vpl_file = read_light_atlas_vpls(vpls_path);
  if (!vpl_file) return vpl_file.error();
  if (vpl_file->geometry_hash != manifest->geometry_hash)
    return engine::Error{
        vpls_path.string(), "",
        "belongs to geometry " + vpl_file->geometry_hash + ", the manifest to " + manifest->geometry_hash};

  auto layout = build_atlas_layout(
      atlas_inputs_from(input),
      AtlasSettings{.texels_per_metre = entry->requested_texels_per_metre, .padding_texels = entry->padding_texels});
  if (!layout) {
    engine::Error e = layout.error();
    e.message = "cannot rebuild the light atlas layout of " + manifest_file.string() + ": " + e.message;
    return e;
  }
  if (layout->width != entry->width || layout->height != entry->height ||
      layout->texels_per_metre != entry->texels_per_metre)
    return engine::Error{manifest_file.string(), "methods.light_atlas.layout",
                         "the rebuilt layout (" + std::to_string(layout->width) + "x" + std::to_string(layout->height) +
                             ") differs from the baked one (" + std::to_string(entry->width) + "x" +
                             std::to_string(entry->height) + "); the atlas code changed since the bake (re-bake)"};

  LightAtlasBake bake;
  bake.layout = std::move(layout).value();
  bake.width = bake.layout.width;
  bake.height = bake.layout.height;
  if (engine::Status s = read_atlas_exr(exr_path, bake); !s) return s.error();
  bake.settings = vpl_file->settings;
  if (entry->direct_light != direct_light_name(bake.settings))
    return engine::Error{manifest_file.string(), "methods.light_atlas.direct_light",
                         "\"" + entry->direct_light + "\" does not match the bake's settings (\"" +
                             direct_light_name(bake.settings) + "\")"};
  bake.stats = entry->stats;
  bake.vpls = std::move(vpl_file->vpls);
  bake.vpl_power = std::move(vpl_file->vpl_power);
  return bake;
}

}  // namespace gi
