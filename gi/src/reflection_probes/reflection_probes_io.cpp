#include "reflection_probes/reflection_probes_io.h"

#include <engine/byte_stream.h>
#include <gi/methods.h>

#include <cmath>
#include <system_error>
#include <nlohmann/json.hpp>

#include "bundle/bundle.h"
#include "bundle/bundle_reader.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string method_key() { return std::string(method_descriptor(EffectMethod::ReflectionProbes).key); }

engine::Error file_error(const fs::path& path, std::string location, std::string message) {
  return engine::Error{path.string(), std::move(location), std::move(message)};
}

// Empty when the set's arrays fit together and its values are valid, else what is wrong.
std::string check_set(const ReflectionProbeSet& set) {
  if (std::string p = check_reflection_probe_settings(set.settings); !p.empty()) return p;
  if (set.cubes.size() != set.probes.size())
    return std::to_string(set.cubes.size()) + " cube maps for " + std::to_string(set.probes.size()) + " probes";
  const int levels = full_mip_count(set.settings.resolution);
  for (std::size_t i = 0; i < set.probes.size(); ++i) {
    const ProbeVolume& v = set.probes[i];
    if (!glm::all(glm::lessThanEqual(v.box_min, v.box_max)) || !std::isfinite(glm::length(v.box_max - v.box_min)) ||
        !std::isfinite(glm::length(v.centre)))
      return "probe " + std::to_string(i) + " has an empty or non-finite box";
    const ProbeCube& c = set.cubes[i];
    if (c.size != set.settings.resolution || static_cast<int>(c.levels.size()) != levels)
      return "probe " + std::to_string(i) + "'s cube map is not " + std::to_string(set.settings.resolution) +
             " texels wide with " + std::to_string(levels) + " levels";
    for (int m = 0; m < levels; ++m) {
      const int s = cube_level_size(c.size, m);
      if (c.levels[static_cast<std::size_t>(m)].size() != static_cast<std::size_t>(6 * s * s))
        return "probe " + std::to_string(i) + " level " + std::to_string(m) + " has the wrong texel count";
      for (const glm::vec3& t : c.levels[static_cast<std::size_t>(m)])
        if (!(t.x >= 0.0f && t.y >= 0.0f && t.z >= 0.0f) || !std::isfinite(t.x + t.y + t.z))
          return "probe " + std::to_string(i) + " level " + std::to_string(m) +
                 " has a negative, infinite or NaN radiance";
    }
    const int ds = cube_distance_size(c);
    if (ds != cube_distance_size(set.cubes.front()))
      return "probe " + std::to_string(i) + " has distances of another size than the first probe's";
    if (ds < 1 || ds > kProbeMaxDistanceScale * c.size || c.distance.size() != static_cast<std::size_t>(6 * ds * ds))
      return "probe " + std::to_string(i) + " has " + std::to_string(c.distance.size()) +
             " distances for a distance cube of face size " + std::to_string(ds) +
             " (level 0: " + std::to_string(c.size) + ")";
    for (float d : c.distance)
      if (!(d >= 0.0f && d <= kProbeFarDistance)) return "probe " + std::to_string(i) + " has a distance out of range";
  }
  return {};
}

json settings_json(const ReflectionProbeSettings& s) {
  return json{{"resolution", s.resolution},
              {"supersample", s.supersample},
              {"prefilter_samples", s.prefilter_samples},
              {"max_roughness", s.max_roughness},
              {"area_light_samples", s.area_light_samples},
              {"cell_m", s.placement.cell_m},
              {"spread_m", s.placement.spread_m},
              {"min_box_m", s.placement.min_box_m},
              {"max_probes", s.placement.max_probes},
              {"seed", s.seed}};
}

void put_settings(engine::ByteWriter& w, const ReflectionProbeSettings& s) {
  w.put(static_cast<std::int32_t>(s.resolution));
  w.put(static_cast<std::int32_t>(s.supersample));
  w.put(static_cast<std::int32_t>(s.prefilter_samples));
  w.put(s.max_roughness);
  w.put(static_cast<std::int32_t>(s.area_light_samples));
  w.put(s.placement.cell_m);
  w.put(s.placement.spread_m);
  w.put(s.placement.min_box_m);
  w.put(static_cast<std::int32_t>(s.placement.max_probes));
  w.put(static_cast<std::uint64_t>(s.seed));
}

bool get_settings(engine::ByteReader& r, ReflectionProbeSettings& s) {
  std::int32_t resolution = 0, supersample = 0, samples = 0, area = 0, max_probes = 0;
  std::uint64_t seed = 0;
  const bool ok = r.get(resolution) && r.get(supersample) && r.get(samples) && r.get(s.max_roughness) && r.get(area) &&
                  r.get(s.placement.cell_m) && r.get(s.placement.spread_m) && r.get(s.placement.min_box_m) &&
                  r.get(max_probes) && r.get(seed);
  s.resolution = resolution;
  s.supersample = supersample;
  s.prefilter_samples = samples;
  s.area_light_samples = area;
  s.placement.max_probes = max_probes;
  s.seed = seed;
  return ok;
}

struct EntryInfo {
  std::string lights_hash;
  std::size_t probes = 0;
  int resolution = 0;
  ReflectionProbeStats stats;
};

engine::Result<EntryInfo> read_entry(const BundleReader& bundle) {
  JsonFields f = bundle.fields();
  EntryInfo e;
  e.lights_hash = f.get<std::string>("lights_hash");
  e.probes = f.get<std::size_t>("probes");
  e.resolution = f.get<int>("resolution");
  e.stats.rays = f.get<std::uint64_t>("stats.rays");
  if (f.error()) return *f.error();
  return e;
}

}  // namespace

engine::Status write_reflection_probes_file(const fs::path& path, const ReflectionProbeSet& set,
                                            const std::string& geometry_hash) {
  if (std::string problem = check_set(set); !problem.empty())
    return file_error(path, "", "cannot save the reflection probes: " + problem);
  engine::ByteWriter w;
  w.put_string(geometry_hash);
  put_settings(w, set.settings);
  w.put(static_cast<std::uint32_t>(set.probes.size()));
  for (const ProbeVolume& v : set.probes) {
    w.put(v.centre);
    w.put(v.box_min);
    w.put(v.box_max);
  }
  for (const ProbeCube& c : set.cubes) {
    for (const std::vector<glm::vec3>& level : c.levels) w.put_array(level);
    w.put(static_cast<std::uint32_t>(cube_distance_size(c)));
    w.put_array(c.distance);
  }
  return write_blob(path, kReflectionProbesMagic, kReflectionProbesVersion, w.bytes());
}

engine::Result<ReflectionProbesFile> read_reflection_probes_file(const fs::path& path) {
  auto payload = read_blob(path, kReflectionProbesMagic, kReflectionProbesVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  ReflectionProbesFile f;
  ReflectionProbeSet& set = f.set;
  std::uint32_t count = 0;
  bool complete = r.get_string(f.geometry_hash) && get_settings(r, set.settings) && r.get(count);
  if (complete && !check_reflection_probe_settings(set.settings).empty())
    return file_error(path, "settings", check_reflection_probe_settings(set.settings));
  if (complete && count > static_cast<std::uint32_t>(set.settings.placement.max_probes))
    return file_error(path, "probes", std::to_string(count) + " probes, more than max_probes");
  set.probes.resize(complete ? count : 0);
  for (ProbeVolume& v : set.probes) complete = complete && r.get(v.centre) && r.get(v.box_min) && r.get(v.box_max);
  const int levels = complete ? full_mip_count(set.settings.resolution) : 0;
  set.cubes.resize(set.probes.size());
  for (ProbeCube& c : set.cubes) {
    c.size = set.settings.resolution;
    c.levels.resize(static_cast<std::size_t>(levels));
    for (std::vector<glm::vec3>& level : c.levels) complete = complete && r.get_array(level);
    std::uint32_t distance_size = 0;
    complete = complete && r.get(distance_size) &&
               distance_size <= static_cast<std::uint32_t>(kProbeMaxDistanceScale * c.size) && r.get_array(c.distance);
    c.distance_size = static_cast<int>(distance_size);
  }
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return file_error(path, location, "truncated payload");
  if (r.remaining() != 0) return file_error(path, location, "unexpected data after the last field");
  if (std::string problem = check_set(set); !problem.empty()) return file_error(path, "", problem);
  return f;
}

engine::Status save_reflection_probes(const fs::path& bundle_dir, const ReflectionProbeSet& set,
                                      const BakeInput& input) {
  const fs::path file = bundle_dir / kReflectionProbesFile;
  std::error_code ec;
  fs::create_directories(bundle_dir, ec);
  if (ec) return engine::Error{bundle_dir.string(), "", "cannot create the bundle directory: " + ec.message()};
  const std::string geometry_hash = scene_geometry_hash(input);
  if (engine::Status st = write_reflection_probes_file(file, set, geometry_hash); !st) return st;
  auto sum = file_checksum(file);
  if (!sum) return sum.error();
  const std::uintmax_t file_bytes = fs::file_size(file, ec);
  if (ec) return file_error(file, "", "cannot read the file size: " + ec.message());
  std::uint64_t texels = 0;
  for (const ProbeCube& c : set.cubes)
    for (const auto& level : c.levels) texels += level.size();
  const json entry{{"files", {{"probes", {{"file", kReflectionProbesFile}, {"xxh3_64", *sum}}}}},
                   {"lights_hash", static_lights_hash(input)},
                   {"settings", settings_json(set.settings)},
                   {"probes", set.probes.size()},
                   {"resolution", set.settings.resolution},
                   {"levels", full_mip_count(set.settings.resolution)},
                   {"stats", {{"rays", set.stats.rays}}},
                   {"memory", {{"gpu_bytes", texels * 8}, {"file_bytes", static_cast<std::uint64_t>(file_bytes)}}}};
  return update_manifest_method(bundle_dir, geometry_hash, fs::path(input.name).filename().string(), method_key(),
                                entry);
}

engine::Result<ReflectionProbeSet> load_reflection_probes(const fs::path& bundle_dir, const BakeInput& input) {
  auto bundle = BundleReader::open(bundle_dir, method_key(), input, "re-bake the reflection probes");
  if (!bundle) return bundle.error();
  auto entry = read_entry(*bundle);
  if (!entry) return entry.error();
  if (engine::Status st = bundle->check_lights(entry->lights_hash, input, "reflection probes", "re-bake"); !st)
    return st.error();
  auto path = bundle->file("probes");
  if (!path) return path.error();
  auto file = read_reflection_probes_file(*path);
  if (!file) return file.error();
  if (engine::Status st = bundle->check_geometry(*path, file->geometry_hash); !st) return st.error();
  ReflectionProbeSet& set = file->set;
  if (entry->probes != set.probes.size() || entry->resolution != set.settings.resolution)
    return bundle->entry_error("", "the manifest describes " + std::to_string(entry->probes) + " probes of " +
                                       std::to_string(entry->resolution) + " texels; " + path->string() + " holds " +
                                       std::to_string(set.probes.size()) + " of " +
                                       std::to_string(set.settings.resolution));
  set.stats = entry->stats;
  return std::move(file->set);
}

}  // namespace gi
