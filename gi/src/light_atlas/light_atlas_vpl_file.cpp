#include "light_atlas/light_atlas_vpl_file.h"

#include <engine/byte_stream.h>
#include <engine/finite.h>

#include <cmath>
#include <span>

namespace gi {

namespace {

template <class T>
std::span<const T> as_span(const std::vector<T>& v) {
  return std::span<const T>(v);
}

// Empty when the VPL arrays fit together, else what is wrong.
std::string check_vpls(const VplSet& s, const std::vector<glm::vec3>& power) {
  const std::size_t n = s.position.size();
  if (s.normal.size() != n || s.albedo.size() != n || s.area_m2.size() != n)
    return "VPL arrays differ in size (position " + std::to_string(n) + ", normal " + std::to_string(s.normal.size()) +
           ", albedo " + std::to_string(s.albedo.size()) + ", area " + std::to_string(s.area_m2.size()) + ")";
  if (power.size() != n)
    return "vpl_power has " + std::to_string(power.size()) + " entries for " + std::to_string(n) + " VPLs";
  const std::size_t samples = s.sample_position.size();
  if (s.sample_normal.size() != samples || s.sample_area_m2.size() != samples) return "sample arrays differ in size";
  if (n == 0 && s.sample_first.empty()) {
    if (samples != 0) return "sample points without VPLs";
  } else {
    if (s.sample_first.size() != n + 1)
      return "sample_first has " + std::to_string(s.sample_first.size()) + " entries, " + std::to_string(n + 1) +
             " expected";
    if (s.sample_first.front() != 0 || s.sample_first.back() != samples)
      return "sample_first does not span the samples";
    for (std::size_t j = 0; j < n; ++j)
      if (s.sample_first[j] > s.sample_first[j + 1]) return "sample_first decreases at VPL " + std::to_string(j);
  }
  for (std::size_t j = 0; j < n; ++j)
    if (!engine::all_finite(s.position[j]) || !engine::all_finite(s.normal[j]) || !engine::all_finite(s.albedo[j]) ||
        !std::isfinite(s.area_m2[j]) || !engine::all_finite(power[j]))
      return "VPL " + std::to_string(j) + " has a NaN or infinite value";
  for (std::size_t k = 0; k < samples; ++k)
    if (!engine::all_finite(s.sample_position[k]) || !engine::all_finite(s.sample_normal[k]) ||
        !std::isfinite(s.sample_area_m2[k]))
      return "sample point " + std::to_string(k) + " has a NaN or infinite value";
  return {};
}

}  // namespace

engine::Status write_light_atlas_vpls(const std::filesystem::path& path, const LightAtlasBake& bake,
                                      const std::string& geometry_hash) {
  if (std::string problem = check_vpls(bake.vpls, bake.vpl_power); !problem.empty())
    return engine::Error{path.string(), "", "cannot save the VPLs: " + problem};
  const LightAtlasSettings& s = bake.settings;
  const VplSet& v = bake.vpls;
  engine::ByteWriter w;
  w.put_string(geometry_hash);
  w.put(s.texels_per_metre);
  w.put(static_cast<std::int32_t>(s.vpl_count));
  w.put(static_cast<std::int32_t>(s.samples_per_vpl));
  w.put(static_cast<std::int32_t>(s.bounces));
  w.put(s.unshot_threshold);
  w.put(static_cast<std::int32_t>(s.area_light_samples));
  w.put(static_cast<std::uint8_t>(s.include_direct ? 1 : 0));
  w.put(static_cast<std::uint64_t>(s.seed));
  w.put_array(as_span(v.position));
  w.put_array(as_span(v.normal));
  w.put_array(as_span(v.albedo));
  w.put_array(as_span(v.area_m2));
  w.put_array(as_span(v.sample_first));
  w.put_array(as_span(v.sample_position));
  w.put_array(as_span(v.sample_normal));
  w.put_array(as_span(v.sample_area_m2));
  w.put_array(as_span(bake.vpl_power));
  return write_blob(path, kLightAtlasVplsMagic, kLightAtlasVplsVersion, w.bytes());
}

engine::Result<LightAtlasVplFile> read_light_atlas_vpls(const std::filesystem::path& path) {
  auto payload = read_blob(path, kLightAtlasVplsMagic, kLightAtlasVplsVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  LightAtlasVplFile f;
  LightAtlasSettings& s = f.settings;
  VplSet& v = f.vpls;
  std::int32_t vpl_count = 0, samples_per_vpl = 0, bounces = 0, area_light_samples = 0;
  std::uint8_t include_direct = 0;
  std::uint64_t seed = 0;
  const bool complete = r.get_string(f.geometry_hash) && r.get(s.texels_per_metre) && r.get(vpl_count) &&
                        r.get(samples_per_vpl) && r.get(bounces) && r.get(s.unshot_threshold) &&
                        r.get(area_light_samples) && r.get(include_direct) && r.get(seed) && r.get_array(v.position) &&
                        r.get_array(v.normal) && r.get_array(v.albedo) && r.get_array(v.area_m2) &&
                        r.get_array(v.sample_first) && r.get_array(v.sample_position) && r.get_array(v.sample_normal) &&
                        r.get_array(v.sample_area_m2) && r.get_array(f.vpl_power);
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return engine::Error{path.string(), location, "truncated payload"};
  if (r.remaining() != 0) return engine::Error{path.string(), location, "unexpected data after the last field"};
  if (include_direct > 1) return engine::Error{path.string(), "settings", "include_direct must be 0 or 1"};
  s.vpl_count = vpl_count;
  s.samples_per_vpl = samples_per_vpl;
  s.bounces = bounces;
  s.area_light_samples = area_light_samples;
  s.include_direct = include_direct != 0;
  s.seed = seed;
  if (std::string problem = check_vpls(v, f.vpl_power); !problem.empty())
    return engine::Error{path.string(), "VPLs", problem};
  return f;
}

}  // namespace gi
