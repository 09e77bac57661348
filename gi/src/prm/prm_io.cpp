#include "prm/prm_io.h"

#include <engine/byte_stream.h>
#include <engine/finite.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <system_error>
#include <nlohmann/json.hpp>

#include "bundle/bundle.h"
#include "bundle/bundle_reader.h"
#include "core/half_scale.h"
#include "io/json_fields.h"
#include "io/zstd_stream.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// zstd level of the pane array (1..19): a middle ground between bake-time speed and size.
constexpr int kZstdLevel = 9;
// Bounds a file may claim before anything is allocated (PrmSettings' limits).
constexpr int kMaxClusters = 65536;
constexpr int kMaxAtlasSide = 16384;

std::string str(std::size_t v) { return std::to_string(v); }

// Empty when the texels ascend inside the atlas.
std::string check_texels(const Prm& p) {
  const std::uint64_t atlas_texels = static_cast<std::uint64_t>(p.width) * static_cast<std::uint64_t>(p.height);
  for (std::size_t i = 0; i < p.texels.size(); ++i) {
    if (p.texels[i] >= atlas_texels)
      return "texel " + str(i) + " (index " + str(p.texels[i]) + ") is outside the " + std::to_string(p.width) + "x" +
             std::to_string(p.height) + " atlas";
    if (i > 0 && p.texels[i] <= p.texels[i - 1]) return "texels are not strictly ascending at element " + str(i);
  }
  return {};
}

// Empty when the sparse panes fit the texels and clusters and hold valid values.
std::string check_panes(const Prm& p) {
  const PrmPanes& q = p.panes;
  const auto clusters = static_cast<std::size_t>(p.cluster_count);
  const PrmBlockSettings& b = q.blocks_settings;
  if (b.tile_texels < 1 || b.tile_texels > 256 || !(b.threshold >= 0.0f) || b.threshold > 1.0f)
    return "pane blocks: tile " + std::to_string(b.tile_texels) + " outside 1..256 or threshold " +
           std::to_string(b.threshold) + " outside [0, 1]";
  if (q.tiles.elements.size() != p.texels.size()) return "pane tiles do not cover the texels";
  if (q.cluster_first.size() != clusters + 1 || q.cluster_first.front() != 0 ||
      q.cluster_first.back() != q.blocks.size())
    return "pane cluster_first has " + str(q.cluster_first.size()) + " entries for " + str(clusters) +
           " clusters, or does not span the " + str(q.blocks.size()) + " blocks";
  std::uint64_t elements = 0;
  for (std::size_t c = 0; c < clusters; ++c) {
    if (q.cluster_first[c] > q.cluster_first[c + 1]) return "pane cluster_first decreases at cluster " + str(c);
    for (std::uint32_t k = q.cluster_first[c]; k < q.cluster_first[c + 1]; ++k) {
      if (q.blocks[k] >= q.tiles.tiles())
        return "pane " + str(c) + " block " + str(k) + " is tile " + str(q.blocks[k]) + ", there are " +
               str(q.tiles.tiles());
      if (k > q.cluster_first[c] && q.blocks[k] <= q.blocks[k - 1])
        return "pane " + str(c) + " blocks are not strictly ascending at block " + str(k);
      elements += q.tiles.size(q.blocks[k]);
    }
  }
  if (q.values.size() != elements * 3 || q.block_value.size() != q.blocks.size())
    return "panes hold " + str(q.values.size()) + " values, their blocks " + std::to_string(elements) +
           " elements x 3 = " + std::to_string(elements * 3) + " expected";
  for (std::size_t j = 0; j < q.values.size(); ++j) {
    const float v = q.values[j];
    if (!std::isfinite(v) || v < 0.0f)
      return "stored pane value " + str(j / 3) + " channel " + str(j % 3) + " is " +
             (std::isnan(v)       ? "NaN"
              : !std::isfinite(v) ? "infinite"
                                  : "negative (" + std::to_string(v) + ")") +
             ": panes must be finite and non-negative";
  }
  return {};
}

// Empty when the Prm's arrays fit together and its values are valid, else what is wrong.
std::string check_prm(const Prm& p) {
  const PrmSettings& s = p.settings;
  if (!(s.texels_per_metre > 0.0f) || !std::isfinite(s.texels_per_metre) || !(s.splitting > 0.0f) ||
      !std::isfinite(s.splitting) || s.entry_points < 1 || s.clusters < 1 || s.max_path_nodes < 1 ||
      !(s.pane_texels_per_metre >= 0.0f) || s.pane_texels_per_metre > s.texels_per_metre)
    return "settings out of range (texels_per_metre and splitting must be positive, entry_points, clusters and "
           "max_path_nodes at least 1, pane_texels_per_metre in [0, texels_per_metre])";
  if (p.width <= 0 || p.height <= 0 || p.width > kMaxAtlasSide || p.height > kMaxAtlasSide)
    return "atlas size " + std::to_string(p.width) + "x" + std::to_string(p.height) + " is outside 1..16384";
  if (p.cluster_count < 1 || p.cluster_count > kMaxClusters)
    return "cluster_count " + std::to_string(p.cluster_count) + " is outside 1..65536";
  const auto clusters = static_cast<std::size_t>(p.cluster_count);
  if (p.cluster_size.size() != clusters)
    return "cluster_size has " + str(p.cluster_size.size()) + " elements for " + str(clusters) + " clusters";
  if (std::string problem = check_texels(p); !problem.empty()) return problem;
  std::vector<std::uint32_t> members(clusters, 0);
  for (std::size_t k = 0; k < p.entries.size(); ++k) {
    const PrmEntryPoint& e = p.entries[k];
    if (e.cluster >= clusters)
      return "entry point " + str(k) + " is in cluster " + str(e.cluster) + ", there are " + str(clusters);
    if (!engine::all_finite(e.position) || !engine::all_finite(e.normal) || !std::isfinite(e.area_m2))
      return "entry point " + str(k) + " has a NaN or infinite value";
    if (e.area_m2 < 0.0f) return "entry point " + str(k) + " has a negative area";
    ++members[e.cluster];
  }
  for (std::size_t c = 0; c < clusters; ++c)
    if (members[c] != p.cluster_size[c])
      return "cluster_size[" + str(c) + "] is " + str(p.cluster_size[c]) + " but " + str(members[c]) +
             " entry points are in that cluster";
  return check_panes(p);
}

bool is_power_of_two(float s) {
  int e = 0;
  return std::isfinite(s) && s > 0.0f && std::frexp(s, &e) == 0.5f;
}

engine::Error file_error(const fs::path& path, std::string location, std::string message) {
  return engine::Error{path.string(), std::move(location), std::move(message)};
}

json settings_json(const PrmSettings& s) {
  return json{{"texels_per_metre", s.texels_per_metre},
              {"entry_points", s.entry_points},
              {"clusters", s.clusters},
              {"splitting", s.splitting},
              {"max_path_nodes", s.max_path_nodes},
              {"kmeans", s.kmeans},
              {"seed", s.seed},
              {"pane_texels_per_metre", s.pane_texels_per_metre},
              {"pane_tile_texels", s.pane_tile_texels},
              {"pane_threshold", s.pane_threshold}};
}

json stats_json(const PrmStats& s) { return json{{"paths", s.paths}, {"path_nodes", s.path_nodes}, {"rays", s.rays}}; }

// What the manifest entry says beyond its file: the layout and the sizes.
struct EntryInfo {
  BakedAtlasLayout layout;
  std::optional<BakedAtlasLayout> atlas_layout;  ///< Coarse panes: the light atlas's they are read at.
  std::size_t entry_points = 0, clusters = 0, pane_texels = 0;
  PrmStats stats;
};

engine::Result<EntryInfo> read_entry(const BundleReader& bundle) {
  JsonFields f = bundle.fields();
  EntryInfo e;
  e.layout = read_baked_atlas_layout(f);
  if (bundle.entry().contains(kPrmAtlasLayoutKey)) e.atlas_layout = read_baked_atlas_layout(f, kPrmAtlasLayoutKey);
  e.entry_points = f.get<std::size_t>("entry_points");
  e.clusters = f.get<std::size_t>("clusters");
  e.pane_texels = f.get<std::size_t>("pane_texels");
  e.stats.paths = f.get<std::size_t>("stats.paths");
  e.stats.path_nodes = f.get<std::size_t>("stats.path_nodes");
  e.stats.rays = f.get<std::uint64_t>("stats.rays");
  if (f.error()) return *f.error();
  return e;
}

// The panes as scaled halves in two byte planes (prm_io.h), plus each pane's scale.
// Error text when a value does not survive (cannot happen for finite values below ~1e38).
std::string encode_panes(const Prm& p, std::vector<float>& scales, std::vector<std::byte>& planes) {
  const PrmPanes& q = p.panes;
  const std::size_t total = q.values.size();
  scales.assign(static_cast<std::size_t>(p.cluster_count), 1.0f);
  planes.assign(total * 2, std::byte{0});
  for (std::size_t c = 0; c < scales.size(); ++c) {
    const std::size_t first = q.cluster_first[c] < q.blocks.size() ? q.block_value[q.cluster_first[c]] * 3 : total;
    const std::size_t last =
        q.cluster_first[c + 1] < q.blocks.size() ? q.block_value[q.cluster_first[c + 1]] * 3 : total;
    const auto begin = q.values.begin() + static_cast<std::ptrdiff_t>(first);
    const float max_value =
        first == last ? 0.0f : *std::max_element(begin, begin + static_cast<std::ptrdiff_t>(last - first));
    const float scale = half_layer_scale(max_value);
    scales[c] = scale;
    for (std::size_t j = first; j < last; ++j) {
      const std::uint16_t h = float_to_half(q.values[j] / scale);
      if (!std::isfinite(half_to_float(h) * scale))
        return "pane " + str(c) + " value " + std::to_string(q.values[j]) + " is too large to store";
      planes[j] = static_cast<std::byte>(h & 0xffu);
      planes[total + j] = static_cast<std::byte>(h >> 8);
    }
  }
  return {};
}

// The stored values of `q`'s blocks (their sizes checked against pane_half_bytes) from the
// zstd frame of scaled halves in two byte planes.
engine::Status decode_pane_values(const fs::path& path, std::span<const std::uint8_t> frame,
                                  std::uint64_t pane_half_bytes, const std::vector<float>& scales, PrmPanes& q) {
  auto unpacked = read_zstd_stream(path, "panes", frame, pane_half_bytes);
  if (!unpacked) return unpacked.error();
  const std::vector<std::uint8_t>& planes = *unpacked;

  const auto total = static_cast<std::size_t>(pane_half_bytes / 2);
  q.values.resize(total);
  std::size_t c = 0;
  for (std::size_t b = 0; b < q.blocks.size(); ++b) {
    while (q.cluster_first[c + 1] <= b) ++c;
    const std::size_t first = q.block_value[b] * 3, last = first + q.tiles.size(q.blocks[b]) * 3;
    for (std::size_t j = first; j < last; ++j) {
      const auto h = static_cast<std::uint16_t>(planes[j] | (planes[total + j] << 8));
      if ((h & 0x8000u) != 0 || (h & 0x7c00u) == 0x7c00u)
        return file_error(path, "panes",
                          "pane " + str(c) + " block " + str(b) + " value " + str(j / 3) + " channel " + str(j % 3) +
                              " is negative, infinite or NaN (corrupt)");
      q.values[j] = half_to_float(h) * scales[c];
    }
  }
  return {};
}

}  // namespace

std::uint16_t float_to_half(float v) {
  const auto bits = std::bit_cast<std::uint32_t>(v);
  const auto sign = static_cast<std::uint16_t>((bits >> 16) & 0x8000u);
  const std::uint32_t exponent = (bits >> 23) & 0xffu;
  std::uint32_t mantissa = bits & 0x7fffffu;
  if (exponent == 0xffu) return static_cast<std::uint16_t>(sign | 0x7c00u | (mantissa != 0 ? 0x200u : 0u));
  const int e = static_cast<int>(exponent) - 127 + 15;  // the half's biased exponent
  if (e >= 31) return static_cast<std::uint16_t>(sign | 0x7c00u);
  if (e <= 0) {
    // Half subnormal k x 2^-24 with k = (1.m x 2^23) >> (14 - e), rounded to nearest even.
    if (exponent == 0) return sign;  // float zero or subnormal: far below 2^-25
    mantissa |= 0x800000u;
    const int shift = 14 - e;
    if (shift > 24) return sign;  // below 2^-25: rounds to zero
    std::uint32_t k = mantissa >> shift;
    const std::uint32_t rest = mantissa & ((1u << shift) - 1u);
    const std::uint32_t halfway = 1u << (shift - 1);
    if (rest > halfway || (rest == halfway && (k & 1u) != 0)) ++k;
    return static_cast<std::uint16_t>(sign | k);  // k == 0x400 is the smallest normal, correctly
  }
  std::uint32_t h = (static_cast<std::uint32_t>(e) << 10) | (mantissa >> 13);
  const std::uint32_t rest = mantissa & 0x1fffu;
  if (rest > 0x1000u || (rest == 0x1000u && (h & 1u) != 0)) ++h;  // a carry may reach infinity, correctly
  return static_cast<std::uint16_t>(sign | h);
}

float half_to_float(std::uint16_t h) {
  const std::uint32_t sign = static_cast<std::uint32_t>(h & 0x8000u) << 16;
  const std::uint32_t exponent = (h >> 10) & 0x1fu;
  const std::uint32_t mantissa = h & 0x3ffu;
  if (exponent == 0) {
    const float magnitude = std::ldexp(static_cast<float>(mantissa), -24);
    return sign != 0 ? -magnitude : magnitude;
  }
  if (exponent == 31) return std::bit_cast<float>(sign | 0x7f800000u | (mantissa << 13));
  return std::bit_cast<float>(sign | ((exponent - 15 + 127) << 23) | (mantissa << 13));
}

engine::Status write_prm_panes(const fs::path& path, const Prm& prm, const std::string& geometry_hash) {
  if (std::string problem = check_prm(prm); !problem.empty())
    return file_error(path, "", "cannot save the PRM: " + problem);
  std::vector<float> scales;
  std::vector<std::byte> planes;
  if (std::string problem = encode_panes(prm, scales, planes); !problem.empty())
    return file_error(path, "", "cannot save the PRM: " + problem);

  auto packed = write_zstd_stream(
      path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(planes.data()), planes.size()),
      kZstdLevel);
  if (!packed) return packed.error();
  const std::vector<std::uint8_t>& frame = *packed;

  const PrmSettings& s = prm.settings;
  std::vector<glm::vec3> position, normal;
  std::vector<float> area;
  std::vector<std::uint32_t> cluster;
  for (const PrmEntryPoint& e : prm.entries) {
    position.push_back(e.position);
    normal.push_back(e.normal);
    area.push_back(e.area_m2);
    cluster.push_back(e.cluster);
  }
  engine::ByteWriter w;
  w.put_string(geometry_hash);
  w.put(s.texels_per_metre);
  w.put(s.pane_texels_per_metre);
  w.put(static_cast<std::int32_t>(s.entry_points));
  w.put(static_cast<std::int32_t>(s.clusters));
  w.put(s.splitting);
  w.put(static_cast<std::int32_t>(s.max_path_nodes));
  w.put(static_cast<std::uint8_t>(s.kmeans ? 1 : 0));
  w.put(static_cast<std::uint64_t>(s.seed));
  w.put(static_cast<std::int32_t>(prm.width));
  w.put(static_cast<std::int32_t>(prm.height));
  w.put(static_cast<std::int32_t>(prm.cluster_count));
  w.put_array(prm.texels);
  w.put_array(position);
  w.put_array(normal);
  w.put_array(area);
  w.put_array(cluster);
  w.put_array(prm.cluster_size);
  w.put(static_cast<std::int32_t>(prm.panes.blocks_settings.tile_texels));
  w.put(prm.panes.blocks_settings.threshold);
  w.put_array(prm.panes.cluster_first);
  w.put_array(prm.panes.blocks);
  w.put_array(scales);
  w.put(static_cast<std::uint64_t>(planes.size()));
  w.put_array(std::span<const std::uint8_t>(frame));
  return write_blob(path, kPrmPanesMagic, kPrmPanesVersion, w.bytes());
}

engine::Result<PrmPaneFile> read_prm_panes(const fs::path& path) {
  // Long because it reads the fields in file order, each count checked before the next array
  // is sized from it; split, the checks would be parted from the reads they guard.
  auto payload = read_blob(path, kPrmPanesMagic, kPrmPanesVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  PrmPaneFile f;
  Prm& p = f.prm;
  PrmSettings& s = p.settings;
  std::int32_t entry_points = 0, clusters = 0, max_path_nodes = 0, width = 0, height = 0, cluster_count = 0;
  std::int32_t tile_texels = 0;
  PrmPanes& q = p.panes;
  std::uint8_t kmeans = 0;
  std::uint64_t seed = 0, pane_half_bytes = 0;
  std::vector<glm::vec3> position, normal;
  std::vector<float> area, scales;
  std::vector<std::uint32_t> cluster;
  std::vector<std::uint8_t> frame;
  const bool complete = r.get_string(f.geometry_hash) && r.get(s.texels_per_metre) && r.get(s.pane_texels_per_metre) &&
                        r.get(entry_points) && r.get(clusters) && r.get(s.splitting) && r.get(max_path_nodes) &&
                        r.get(kmeans) && r.get(seed) && r.get(width) && r.get(height) && r.get(cluster_count) &&
                        r.get_array(p.texels) && r.get_array(position) && r.get_array(normal) && r.get_array(area) &&
                        r.get_array(cluster) && r.get_array(p.cluster_size) && r.get(tile_texels) &&
                        r.get(q.blocks_settings.threshold) && r.get_array(q.cluster_first) && r.get_array(q.blocks) &&
                        r.get_array(scales) && r.get(pane_half_bytes) && r.get_array(frame);
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return file_error(path, location, "truncated payload");
  if (r.remaining() != 0) return file_error(path, location, "unexpected data after the last field");
  if (kmeans > 1) return file_error(path, "settings", "kmeans must be 0 or 1");
  s.entry_points = entry_points;
  s.clusters = clusters;
  s.max_path_nodes = max_path_nodes;
  s.kmeans = kmeans != 0;
  s.seed = seed;
  p.width = width;
  p.height = height;
  p.cluster_count = cluster_count;

  const std::size_t n_entries = position.size();
  if (normal.size() != n_entries || area.size() != n_entries || cluster.size() != n_entries)
    return file_error(path, "entry points",
                      "arrays differ in size (position " + str(n_entries) + ", normal " + str(normal.size()) +
                          ", area " + str(area.size()) + ", cluster " + str(cluster.size()) + ")");
  p.entries.resize(n_entries);
  for (std::size_t k = 0; k < n_entries; ++k) p.entries[k] = {position[k], normal[k], area[k], cluster[k]};
  // Sizes before the panes are allocated: a corrupt count must not ask for gigabytes.
  if (cluster_count < 1 || cluster_count > kMaxClusters)
    return file_error(path, "cluster_count", "cluster_count " + std::to_string(cluster_count) + " is outside 1..65536");
  if (scales.size() != static_cast<std::size_t>(cluster_count) ||
      p.cluster_size.size() != static_cast<std::size_t>(cluster_count))
    return file_error(path, "clusters",
                      "cluster_size has " + str(p.cluster_size.size()) + " and pane_scale " + str(scales.size()) +
                          " elements for " + std::to_string(cluster_count) + " clusters");
  for (std::size_t c = 0; c < scales.size(); ++c)
    if (!is_power_of_two(scales[c]))
      return file_error(
          path, "pane_scale",
          "the scale of pane " + str(c) + " (" + std::to_string(scales[c]) + ") is not a positive power of two");
  if (tile_texels < 1 || tile_texels > 256)
    return file_error(path, "tile_texels", "tile_texels " + std::to_string(tile_texels) + " is outside 1..256");
  if (width < 1 || width > kMaxAtlasSide)
    return file_error(path, "width", "atlas width " + std::to_string(width) + " is outside 1..16384");
  if (std::string problem = check_texels(p); !problem.empty()) return file_error(path, "texels", problem);
  s.pane_tile_texels = q.blocks_settings.tile_texels = tile_texels;
  s.pane_threshold = q.blocks_settings.threshold;
  q.tiles = prm_tiles(p.texels, width, tile_texels);
  if (q.cluster_first.size() != static_cast<std::size_t>(cluster_count) + 1 ||
      q.cluster_first.back() != q.blocks.size())
    return file_error(path, "blocks",
                      "cluster_first has " + str(q.cluster_first.size()) + " entries for " +
                          std::to_string(cluster_count) + " clusters or does not end at the " + str(q.blocks.size()) +
                          " blocks");
  for (std::size_t c = 0; c + 1 < q.cluster_first.size(); ++c)
    if (q.cluster_first[c] > q.cluster_first[c + 1] || q.cluster_first.front() != 0)
      return file_error(path, "blocks", "cluster_first decreases at cluster " + str(c) + " or does not start at 0");
  std::uint64_t stored = 0;
  for (std::uint32_t k : q.blocks) {
    if (k >= q.tiles.tiles())
      return file_error(path, "blocks", "block tile " + str(k) + " is outside the " + str(q.tiles.tiles()) + " tiles");
    stored += q.tiles.size(k);
  }
  q.index_values();
  const std::uint64_t values = stored * 3;
  if (pane_half_bytes != values * 2)
    return file_error(path, "pane_half_bytes",
                      "the file says " + std::to_string(pane_half_bytes) + " bytes of halves, its blocks hold " +
                          std::to_string(stored) + " elements x 3 x 2 = " + std::to_string(values * 2) + " expected");
  if (engine::Status st = decode_pane_values(path, frame, pane_half_bytes, scales, q); !st) return st.error();
  if (std::string problem = check_prm(p); !problem.empty()) return file_error(path, "", problem);
  return f;
}

engine::Status save_prm(const fs::path& bundle_dir, const Prm& prm, const BakeInput& input) {
  const std::string scene_name = fs::path(input.name).filename().string();
  const fs::path panes = bundle_dir / kPrmPanesFile;
  if (prm.width != prm.layout.width || prm.height != prm.layout.height)
    return file_error(panes, "",
                      "cannot save the PRM: its size " + std::to_string(prm.width) + "x" + std::to_string(prm.height) +
                          " differs from its layout's " + std::to_string(prm.layout.width) + "x" +
                          std::to_string(prm.layout.height));
  // Checked before the directory is made, so a bad PRM leaves nothing behind.
  if (std::string problem = check_prm(prm); !problem.empty())
    return file_error(panes, "", "cannot save the PRM: " + problem);
  std::error_code ec;
  fs::create_directories(bundle_dir, ec);
  if (ec) return engine::Error{bundle_dir.string(), "", "cannot create the bundle directory: " + ec.message()};

  const std::string geometry_hash = scene_geometry_hash(input);
  if (engine::Status s = write_prm_panes(panes, prm, geometry_hash); !s) return s;
  auto sum = file_checksum(panes);
  if (!sum) return sum.error();
  const std::uintmax_t file_bytes = fs::file_size(panes, ec);
  if (ec) return file_error(panes, "", "cannot read the file size: " + ec.message());
  auto layout_file = write_bundle_atlas_layout(bundle_dir, kPrmLayoutFile, prm.layout, geometry_hash);
  if (!layout_file) return layout_file.error();

  json entry{{"files", {{"panes", {{"file", kPrmPanesFile}, {"xxh3_64", *sum}}}, {"layout", *layout_file}}},
             {"settings", settings_json(prm.settings)},
             {"layout", baked_atlas_layout_json(prm.layout)},
             {"entry_points", prm.entries.size()},
             {"clusters", prm.cluster_count},
             {"pane_texels", prm.texels.size()},
             {"stats", stats_json(prm.stats)},
             {"memory",
              {{"pane_bytes_half", static_cast<std::uint64_t>(prm.panes.values.size()) * 2},
               {"pane_blocks", prm.panes.blocks.size()},
               {"file_bytes", static_cast<std::uint64_t>(file_bytes)}}}};
  if (prm.atlas) {
    auto atlas_file = write_bundle_atlas_layout(bundle_dir, kPrmAtlasLayoutFile, prm.atlas->layout, geometry_hash);
    if (!atlas_file) return atlas_file.error();
    entry["files"][kPrmAtlasLayoutKey] = *atlas_file;
    entry[kPrmAtlasLayoutKey] = baked_atlas_layout_json(prm.atlas->layout);
  }
  return update_manifest_method(bundle_dir, geometry_hash, scene_name, kPrmMethod, entry);
}

engine::Result<Prm> load_prm(const fs::path& bundle_dir, const BakeInput& input) {
  auto bundle = BundleReader::open(bundle_dir, kPrmMethod, input, "re-bake the PRM");
  if (!bundle) return bundle.error();
  auto entry = read_entry(*bundle);
  if (!entry) return entry.error();
  auto panes_path = bundle->file("panes");
  if (!panes_path) return panes_path.error();
  auto file = read_prm_panes(*panes_path);
  if (!file) return file.error();
  if (engine::Status s = bundle->check_geometry(*panes_path, file->geometry_hash); !s) return s.error();
  Prm& prm = file->prm;
  const BakedAtlasLayout& l = entry->layout;
  if (entry->entry_points != prm.entries.size() || entry->clusters != static_cast<std::size_t>(prm.cluster_count) ||
      entry->pane_texels != prm.texels.size() || l.width != prm.width || l.height != prm.height)
    return bundle->entry_error("", "the manifest describes " + str(entry->entry_points) + " entry points, " +
                                       str(entry->clusters) + " clusters, " + str(entry->pane_texels) +
                                       " pane texels, " + std::to_string(l.width) + "x" + std::to_string(l.height) +
                                       "; " + panes_path->string() + " holds " + str(prm.entries.size()) + ", " +
                                       std::to_string(prm.cluster_count) + ", " + str(prm.texels.size()) + ", " +
                                       std::to_string(prm.width) + "x" + std::to_string(prm.height));
  auto layout = bundle->atlas_layout(input, l, "PRM pane layout");
  if (!layout) return layout.error();
  prm.layout = std::move(layout).value();
  prm.stats = entry->stats;
  if (coarse_panes(prm.settings) != entry->atlas_layout.has_value())
    return bundle->entry_error(kPrmAtlasLayoutKey,
                               coarse_panes(prm.settings)
                                   ? "the panes are coarser than the atlas but the entry has no atlas layout (re-bake)"
                                   : "the entry has an atlas layout but the panes are at the atlas's density");
  if (entry->atlas_layout) {
    // Coarse panes: the light atlas's layout as baked, and the read of the panes at its
    // texels built from the two layouts (rasterizing the atlas; docs/prm.md measures it).
    auto atlas = bundle->atlas_layout(input, *entry->atlas_layout, "PRM light atlas layout", kPrmAtlasLayoutKey);
    if (!atlas) return atlas.error();
    auto read = prm_atlas_read(prm, std::move(atlas).value(), input);
    if (!read) return bundle->entry_error(kPrmAtlasLayoutKey, read.error().message);
    prm.atlas = std::move(read).value();
  }
  return std::move(file->prm);
}

}  // namespace gi
