#include "dlm/dlm_io.h"

#include <engine/byte_stream.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <system_error>
#include <glm/gtc/packing.hpp>
#include <nlohmann/json.hpp>

#include "bundle/bundle.h"
#include "bundle/bundle_reader.h"
#include "core/half_scale.h"
#include "io/json_fields.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int kMaxAtlasSide = 16384;

std::string str(std::size_t v) { return std::to_string(v); }

engine::Error file_error(const fs::path& path, std::string location, std::string message) {
  return engine::Error{path.string(), std::move(location), std::move(message)};
}

bool is_power_of_two(float s) {
  int e = 0;
  return std::isfinite(s) && s > 0.0f && std::frexp(s, &e) == 0.5f;
}

std::uint16_t to_half(float v) { return glm::packHalf1x16(v); }
float from_half(std::uint16_t h) { return glm::unpackHalf1x16(h); }

// Empty when the Dlm's arrays fit together and its values are valid, else what is wrong.
std::string check_dlm(const Dlm& d) {
  const DlmSettings& s = d.settings;
  if (!(s.texels_per_metre > 0.0f) || !std::isfinite(s.texels_per_metre) || s.directions < 8 || s.directions > 256 ||
      s.photons < 1 || !(s.splat_radius_texels > 0.0f) || !std::isfinite(s.splat_radius_texels) ||
      !(s.glossy_roughness > 0.0f) || !(s.glossy_roughness <= 1.0f) || !(s.glossy_roughness_min >= 0.0f) ||
      !(s.glossy_roughness_min < s.glossy_roughness) || s.max_bounces < 1 || s.area_light_samples < 1)
    return "settings out of range";
  if (d.width <= 0 || d.height <= 0 || d.width > kMaxAtlasSide || d.height > kMaxAtlasSide)
    return "atlas size " + std::to_string(d.width) + "x" + std::to_string(d.height) + " is outside 1..16384";
  if (d.directions.size() != static_cast<std::size_t>(s.directions))
    return str(d.directions.size()) + " directions for settings.directions " + std::to_string(s.directions);
  for (std::size_t k = 0; k < d.directions.size(); ++k)
    if (!std::isfinite(glm::length(d.directions[k])) || std::fabs(glm::length(d.directions[k]) - 1.0f) > 1e-3f)
      return "direction " + str(k) + " is not a unit vector";
    else if (k > 0 && d.directions[k].z > d.directions[k - 1].z)  // the renderer's search walks them by z
      return "direction " + str(k) + " is not sorted by decreasing z";
  const std::size_t texel_limit = static_cast<std::size_t>(d.width) * static_cast<std::size_t>(d.height);
  for (std::size_t i = 0; i < d.texels.size(); ++i)
    if (d.texels[i] >= texel_limit || (i > 0 && d.texels[i] <= d.texels[i - 1]))
      return "texel " + str(i) + " (" + std::to_string(d.texels[i]) + ") is out of range or not ascending";
  if (d.radiance.size() != d.directions.size() * d.texels.size() * 3)
    return "radiance has " + str(d.radiance.size()) + " values, " + str(d.directions.size()) + " directions x " +
           str(d.texels.size()) + " texels x 3 expected";
  for (std::size_t j = 0; j < d.radiance.size(); ++j)
    if (!std::isfinite(d.radiance[j]) || d.radiance[j] < 0.0f)
      return "radiance value " + str(j) + " (" + std::to_string(d.radiance[j]) + ") is negative, infinite or NaN";
  return {};
}

json settings_json(const DlmSettings& s) {
  return json{{"texels_per_metre", s.texels_per_metre},
              {"directions", s.directions},
              {"photons", s.photons},
              {"splat_radius_texels", s.splat_radius_texels},
              {"glossy_roughness", s.glossy_roughness},
              {"glossy_roughness_min", s.glossy_roughness_min},
              {"max_bounces", s.max_bounces},
              {"area_light_samples", s.area_light_samples},
              {"seed", s.seed},
              {"tangent_frame_bins", s.tangent_frame_bins}};
}

json stats_json(const DlmStats& s) {
  return json{{"photons", s.photons},
              {"rays", s.rays},
              {"deposits", s.deposits},
              {"lost_deposits", s.lost_deposits},
              {"emitted_watts", s.emitted_watts},
              {"glossy_texels", s.glossy_texels}};
}

// What the manifest entry says beyond its file: the lights, the layout and the sizes.
struct EntryInfo {
  std::string lights_hash;
  BakedAtlasLayout layout;
  std::size_t directions = 0, texels = 0;
  DlmStats stats;
};

engine::Result<EntryInfo> read_entry(const BundleReader& bundle) {
  JsonFields f = bundle.fields();
  EntryInfo e;
  e.lights_hash = f.get<std::string>("lights_hash");
  e.layout = read_baked_atlas_layout(f);
  e.directions = f.get<std::size_t>("directions");
  e.texels = f.get<std::size_t>("texels");
  e.stats.photons = f.get<std::uint64_t>("stats.photons");
  e.stats.rays = f.get<std::uint64_t>("stats.rays");
  e.stats.deposits = f.get<std::uint64_t>("stats.deposits");
  e.stats.lost_deposits = f.get<std::uint64_t>("stats.lost_deposits");
  e.stats.emitted_watts = f.get<double>("stats.emitted_watts");
  e.stats.glossy_texels = f.get<std::size_t>("stats.glossy_texels");
  if (f.error()) return *f.error();
  return e;
}

}  // namespace

engine::Status write_dlm_file(const fs::path& path, const Dlm& dlm, const std::string& geometry_hash) {
  if (std::string problem = check_dlm(dlm); !problem.empty())
    return file_error(path, "", "cannot save the directional light maps: " + problem);
  const std::size_t per_bin = dlm.texels.size() * 3;
  std::vector<float> scales(dlm.directions.size(), 1.0f);
  std::vector<std::uint16_t> halves(dlm.radiance.size());
  for (std::size_t k = 0; k < scales.size(); ++k) {
    const auto first = dlm.radiance.begin() + static_cast<std::ptrdiff_t>(k * per_bin);
    const float max_value =
        per_bin == 0 ? 0.0f : *std::max_element(first, first + static_cast<std::ptrdiff_t>(per_bin));
    scales[k] = half_layer_scale(max_value);
    for (std::size_t j = k * per_bin; j < (k + 1) * per_bin; ++j) halves[j] = to_half(dlm.radiance[j] / scales[k]);
  }
  const DlmSettings& s = dlm.settings;
  engine::ByteWriter w;
  w.put_string(geometry_hash);
  w.put(s.texels_per_metre);
  w.put(static_cast<std::int32_t>(s.directions));
  w.put(static_cast<std::uint64_t>(s.photons));
  w.put(s.splat_radius_texels);
  w.put(s.glossy_roughness);
  w.put(s.glossy_roughness_min);
  w.put(static_cast<std::int32_t>(s.max_bounces));
  w.put(static_cast<std::int32_t>(s.area_light_samples));
  w.put(static_cast<std::uint64_t>(s.seed));
  w.put(static_cast<std::int32_t>(s.tangent_frame_bins ? 1 : 0));
  w.put(static_cast<std::int32_t>(dlm.width));
  w.put(static_cast<std::int32_t>(dlm.height));
  w.put_array(dlm.directions);
  w.put_array(dlm.texels);
  w.put_array(scales);
  w.put_array(halves);
  return write_blob(path, kDlmMagic, kDlmVersion, w.bytes());
}

engine::Result<DlmFile> read_dlm_file(const fs::path& path) {
  auto payload = read_blob(path, kDlmMagic, kDlmVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  DlmFile f;
  Dlm& d = f.dlm;
  DlmSettings& s = d.settings;
  std::int32_t directions = 0, max_bounces = 0, area_samples = 0, tangent_frame = 0, width = 0, height = 0;
  std::uint64_t photons = 0, seed = 0;
  std::vector<float> scales;
  std::vector<std::uint16_t> halves;
  const bool complete = r.get_string(f.geometry_hash) && r.get(s.texels_per_metre) && r.get(directions) &&
                        r.get(photons) && r.get(s.splat_radius_texels) && r.get(s.glossy_roughness) &&
                        r.get(s.glossy_roughness_min) && r.get(max_bounces) && r.get(area_samples) && r.get(seed) &&
                        r.get(tangent_frame) && r.get(width) && r.get(height) && r.get_array(d.directions) &&
                        r.get_array(d.texels) && r.get_array(scales) && r.get_array(halves);
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return file_error(path, location, "truncated payload");
  if (r.remaining() != 0) return file_error(path, location, "unexpected data after the last field");
  s.directions = directions;
  s.photons = photons;
  s.max_bounces = max_bounces;
  s.area_light_samples = area_samples;
  s.seed = seed;
  if (tangent_frame != 0 && tangent_frame != 1)
    return file_error(path, "tangent_frame_bins", "is " + std::to_string(tangent_frame) + ", 0 or 1 expected");
  s.tangent_frame_bins = tangent_frame == 1;
  d.width = width;
  d.height = height;
  if (scales.size() != d.directions.size())
    return file_error(path, "bin_scale",
                      str(scales.size()) + " scales for " + str(d.directions.size()) + " directions");
  for (std::size_t k = 0; k < scales.size(); ++k)
    if (!is_power_of_two(scales[k]))
      return file_error(
          path, "bin_scale",
          "the scale of bin " + str(k) + " (" + std::to_string(scales[k]) + ") is not a positive power of two");
  if (halves.size() != d.directions.size() * d.texels.size() * 3)
    return file_error(path, "radiance_half",
                      str(halves.size()) + " values, " + str(d.directions.size()) + " directions x " +
                          str(d.texels.size()) + " texels x 3 expected");
  const std::size_t per_bin = d.texels.size() * 3;
  d.radiance.resize(halves.size());
  for (std::size_t j = 0; j < halves.size(); ++j) {
    const std::uint16_t h = halves[j];
    if ((h & 0x8000u) != 0 || (h & 0x7c00u) == 0x7c00u)
      return file_error(path, "radiance_half",
                        "bin " + str(j / per_bin) + " texel " + str(d.texels[(j % per_bin) / 3]) + " channel " +
                            str(j % 3) + " is negative, infinite or NaN (corrupt)");
    d.radiance[j] = from_half(h) * scales[j / per_bin];
  }
  if (std::string problem = check_dlm(d); !problem.empty()) return file_error(path, "", problem);
  return f;
}

engine::Status save_dlm(const fs::path& bundle_dir, const Dlm& dlm, const BakeInput& input) {
  const std::string scene_name = fs::path(input.name).filename().string();
  const fs::path file = bundle_dir / kDlmFile;
  if (dlm.width != dlm.layout.width || dlm.height != dlm.layout.height)
    return file_error(file, "", "cannot save the directional light maps: their size differs from their layout's");
  if (std::string problem = check_dlm(dlm); !problem.empty())
    return file_error(file, "", "cannot save the directional light maps: " + problem);
  std::error_code ec;
  fs::create_directories(bundle_dir, ec);
  if (ec) return engine::Error{bundle_dir.string(), "", "cannot create the bundle directory: " + ec.message()};
  const std::string geometry_hash = scene_geometry_hash(input);
  if (engine::Status st = write_dlm_file(file, dlm, geometry_hash); !st) return st;
  auto sum = file_checksum(file);
  if (!sum) return sum.error();
  const std::uintmax_t file_bytes = fs::file_size(file, ec);
  if (ec) return file_error(file, "", "cannot read the file size: " + ec.message());
  auto layout_file = write_bundle_atlas_layout(bundle_dir, kDlmLayoutFile, dlm.layout, geometry_hash);
  if (!layout_file) return layout_file.error();
  const std::uint64_t n = dlm.directions.size();
  const json entry{
      {"files", {{"maps", {{"file", kDlmFile}, {"xxh3_64", *sum}}}, {"layout", *layout_file}}},
      {"lights_hash", static_lights_hash(input)},
      {"settings", settings_json(dlm.settings)},
      {"layout", baked_atlas_layout_json(dlm.layout)},
      {"directions", n},
      {"texels", dlm.texels.size()},
      {"stats", stats_json(dlm.stats)},
      {"memory",
       {{"gpu_bytes", static_cast<std::uint64_t>(dlm.texels.size()) * n * 8 +
                          static_cast<std::uint64_t>(dlm.width) * static_cast<std::uint64_t>(dlm.height) * 4},
        {"bytes_per_texel", n * 6},
        {"file_bytes", static_cast<std::uint64_t>(file_bytes)}}}};
  return update_manifest_method(bundle_dir, geometry_hash, scene_name, kDlmMethod, entry);
}

engine::Result<Dlm> load_dlm(const fs::path& bundle_dir, const BakeInput& input) {
  auto bundle = BundleReader::open(bundle_dir, kDlmMethod, input, "re-bake the directional light maps");
  if (!bundle) return bundle.error();
  auto entry = read_entry(*bundle);
  if (!entry) return entry.error();
  if (engine::Status st = bundle->check_lights(entry->lights_hash, input, "directional light maps", "re-bake"); !st)
    return st.error();
  auto path = bundle->file("maps");
  if (!path) return path.error();
  auto file = read_dlm_file(*path);
  if (!file) return file.error();
  if (engine::Status st = bundle->check_geometry(*path, file->geometry_hash); !st) return st.error();
  Dlm& dlm = file->dlm;
  const BakedAtlasLayout& l = entry->layout;
  if (entry->directions != dlm.directions.size() || entry->texels != dlm.texels.size() || l.width != dlm.width ||
      l.height != dlm.height)
    return bundle->entry_error("", "the manifest describes " + str(entry->directions) + " directions, " +
                                       str(entry->texels) + " texels, " + std::to_string(l.width) + "x" +
                                       std::to_string(l.height) + "; " + path->string() + " holds " +
                                       str(dlm.directions.size()) + ", " + str(dlm.texels.size()) + ", " +
                                       std::to_string(dlm.width) + "x" + std::to_string(dlm.height));
  auto layout = bundle->atlas_layout(input, l, "DLM atlas layout");
  if (!layout) return layout.error();
  dlm.layout = std::move(layout).value();
  dlm.stats = entry->stats;
  return std::move(file->dlm);
}

}  // namespace gi
