#include "light_atlas/light_atlas_io.h"

#include <engine/image.h>

#include <cmath>
#include <system_error>
#include <nlohmann/json.hpp>

#include "bundle/bundle.h"
#include "bundle/bundle_reader.h"
#include "io/json_fields.h"
#include "light_atlas/light_atlas_vpl_file.h"

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

// What the manifest entry says beyond its files: the lights, the direct light, the layout.
struct EntryInfo {
  std::string lights_hash, direct_light;
  BakedAtlasLayout layout;
  LightAtlasStats stats;
};

engine::Result<EntryInfo> read_entry(const BundleReader& bundle) {
  JsonFields f = bundle.fields();
  EntryInfo e;
  e.lights_hash = f.get<std::string>("lights_hash");
  // Absent in bundles baked before the atlas held the sky (load_light_atlas says so).
  if (bundle.entry().is_object() && bundle.entry().contains("direct_light"))
    e.direct_light = f.get<std::string>("direct_light");
  e.layout = read_baked_atlas_layout(f);
  e.stats = read_stats(f);
  if (f.error()) return *f.error();
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
  auto layout_file = write_bundle_atlas_layout(bundle_dir, kLightAtlasLayoutFile, bake.layout, geometry_hash);
  if (!layout_file) return layout_file.error();

  const json entry{{"files",
                    {{"irradiance", {{"file", kLightAtlasExrFile}, {"xxh3_64", *exr_sum}}},
                     {"vpls", {{"file", kLightAtlasVplsFile}, {"xxh3_64", *vpls_sum}}},
                     {"layout", *layout_file}}},
                   {"lights_hash", static_lights_hash(input)},
                   {"direct_light", direct_light_name(bake.settings)},
                   {"settings", settings_json(bake.settings)},
                   {"layout", baked_atlas_layout_json(bake.layout)},
                   {"stats", stats_json(bake.stats)}};
  return update_manifest_method(bundle_dir, geometry_hash, scene_name, kLightAtlasMethod, entry);
}

engine::Result<LightAtlasBake> load_light_atlas(const fs::path& bundle_dir, const BakeInput& input) {
  auto bundle = BundleReader::open(bundle_dir, kLightAtlasMethod, input, "re-bake");
  if (!bundle) return bundle.error();
  auto entry = read_entry(*bundle);
  if (!entry) return entry.error();
  if (engine::Status s =
          bundle->check_lights(entry->lights_hash, input, "light atlas",
                               "a static light was edited; re-bake, or update it with gi::update_light_atlas");
      !s)
    return s.error();
  if (entry->direct_light.empty())
    return bundle->entry_error("direct_light", "the light atlas in " + bundle_dir.string() +
                                                   " was baked before the atlas held the sky's direct light (the "
                                                   "renderer drew the sky unshadowed then); re-bake");
  auto vpls_path = bundle->file("vpls");
  if (!vpls_path) return vpls_path.error();
  auto exr_path = bundle->file("irradiance");
  if (!exr_path) return exr_path.error();
  auto vpl_file = read_light_atlas_vpls(*vpls_path);
  if (!vpl_file) return vpl_file.error();
  if (engine::Status s = bundle->check_geometry(*vpls_path, vpl_file->geometry_hash); !s) return s.error();
  auto layout = bundle->atlas_layout(input, entry->layout, "light atlas layout");
  if (!layout) return layout.error();

  LightAtlasBake bake;
  bake.layout = std::move(layout).value();
  bake.width = bake.layout.width;
  bake.height = bake.layout.height;
  if (engine::Status s = read_atlas_exr(*exr_path, bake); !s) return s.error();
  bake.settings = vpl_file->settings;
  if (entry->direct_light != direct_light_name(bake.settings))
    return bundle->entry_error("direct_light", "\"" + entry->direct_light +
                                                   "\" does not match the bake's settings (\"" +
                                                   direct_light_name(bake.settings) + "\")");
  bake.stats = entry->stats;
  bake.vpls = std::move(vpl_file->vpls);
  bake.vpl_power = std::move(vpl_file->vpl_power);
  return bake;
}

}  // namespace gi
