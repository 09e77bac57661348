// The shard file of a distributed bake (bake_shard.h).
#include "bake/bake_shard.h"

#include <engine/byte_stream.h>
#include <engine/finite.h>

#include <cmath>
#include <span>

#include "io/blob_file.h"

namespace gi {

namespace {

constexpr BlobMagic kShardMagic{"GISHARD1"};
constexpr std::uint32_t kShardVersion = 3;  // 2: the light atlas's baked_direct; 3: its variance
constexpr std::uint8_t kHasAtlas = 1, kHasPrm = 2, kHasAntiradiance = 4;

bool ascending(const std::vector<std::uint32_t>& v) {
  for (std::size_t i = 1; i < v.size(); ++i)
    if (v[i] <= v[i - 1]) return false;
  return true;
}

}  // namespace

engine::Status write_shard_file(const std::filesystem::path& path, const ShardFile& f) {
  engine::ByteWriter w;
  w.put(f.index);
  w.put(f.count);
  w.put_string(f.geometry_hash);
  w.put_string(f.lights_hash);
  w.put_string(f.settings_hash);
  w.put(f.seed);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(f.methods.size()));
  for (const std::string& m : f.methods) w.put_string(m);
  w.put<std::uint8_t>(static_cast<std::uint8_t>((f.atlas ? kHasAtlas : 0) | (f.prm ? kHasPrm : 0) |
                                                (f.antiradiance ? kHasAntiradiance : 0)));
  if (f.atlas) {
    const LightAtlasShardPart& a = *f.atlas;
    w.put_array(a.texels);
    w.put_array(a.indirect);
    w.put_array(a.direct);
    w.put_array(a.baked_direct);
    w.put_array(a.hidden);
    w.put_array(a.variance);
    w.put(a.shared_rays);
    w.put(a.own_rays);
  }
  if (f.prm) {
    const PrmShardPart& p = *f.prm;
    w.put<std::int32_t>(p.cluster_count);
    w.put_array(p.texels);
    w.put_array(p.values);
    w.put<std::uint64_t>(p.paths);
    w.put<std::uint64_t>(p.path_nodes);
    w.put(p.walk_rays);
    w.put(p.pane_rays);
  }
  if (f.antiradiance) {
    w.put(f.antiradiance->links);
    w.put_array(f.antiradiance->frame);
  }
  return write_blob(path, kShardMagic, kShardVersion, w.bytes());
}

// Long because it reads one shard in its file order (header, methods, then each part its
// flags name) and then checks what was read; the reader and the part flags run through both halves.
engine::Result<ShardFile> read_shard_file(const std::filesystem::path& path) {
  auto payload = read_blob(path, kShardMagic, kShardVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  ShardFile f;
  std::uint32_t methods = 0;
  std::uint8_t parts = 0;
  bool complete = r.get(f.index) && r.get(f.count) && r.get_string(f.geometry_hash) && r.get_string(f.lights_hash) &&
                  r.get_string(f.settings_hash) && r.get(f.seed) && r.get(methods) && methods <= 64;
  for (std::uint32_t i = 0; complete && i < methods; ++i) {
    std::string m;
    complete = r.get_string(m);
    f.methods.push_back(std::move(m));
  }
  complete = complete && r.get(parts);
  if (complete && (parts & kHasAtlas)) {
    LightAtlasShardPart a;
    complete = r.get_array(a.texels) && r.get_array(a.indirect) && r.get_array(a.direct) &&
               r.get_array(a.baked_direct) && r.get_array(a.hidden) && r.get_array(a.variance) &&
               r.get(a.shared_rays) && r.get(a.own_rays);
    f.atlas = std::move(a);
  }
  if (complete && (parts & kHasPrm)) {
    PrmShardPart p;
    std::int32_t clusters = 0;
    std::uint64_t paths = 0, nodes = 0;
    complete = r.get(clusters) && r.get_array(p.texels) && r.get_array(p.values) && r.get(paths) && r.get(nodes) &&
               r.get(p.walk_rays) && r.get(p.pane_rays);
    p.cluster_count = clusters;
    p.paths = static_cast<std::size_t>(paths);
    p.path_nodes = static_cast<std::size_t>(nodes);
    f.prm = std::move(p);
  }
  if (complete && (parts & kHasAntiradiance)) {
    AntiradianceShardPart a;
    complete = r.get(a.links) && r.get_array(a.frame);
    f.antiradiance = std::move(a);
  }
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return engine::Error{path.string(), location, "truncated payload"};
  if (r.remaining() != 0) return engine::Error{path.string(), location, "unexpected data after the last field"};
  if (parts > (kHasAtlas | kHasPrm | kHasAntiradiance))
    return engine::Error{path.string(), "parts", "unknown part flags"};
  if (f.count == 0 || f.index >= f.count)
    return engine::Error{path.string(), "shard",
                         "shard " + std::to_string(f.index) + " of " + std::to_string(f.count) + " does not exist"};
  if (f.atlas) {
    const LightAtlasShardPart& a = *f.atlas;
    const std::size_t n = a.texels.size();
    if (a.indirect.size() != n || a.direct.size() != n || a.baked_direct.size() != n || a.hidden.size() != n ||
        a.variance.size() != n || !ascending(a.texels))
      return engine::Error{path.string(), "light atlas", "texel arrays differ in size or are not ascending"};
    for (std::size_t k = 0; k < n; ++k)
      if (!engine::all_finite(a.indirect[k]) || !engine::all_finite(a.direct[k]) ||
          !engine::all_finite(a.baked_direct[k]) || a.hidden[k] > 1 || !(a.variance[k] >= 0.0f) ||
          !std::isfinite(a.variance[k]))
        return engine::Error{path.string(), "light atlas", "texel " + std::to_string(a.texels[k]) + " is not finite"};
  }
  if (f.prm) {
    const PrmShardPart& p = *f.prm;
    if (p.cluster_count < 1 || p.cluster_count > 65536 || !ascending(p.texels) ||
        p.values.size() != p.texels.size() * static_cast<std::size_t>(p.cluster_count) * 3)
      return engine::Error{path.string(), "PRM", "cluster count, texels and values do not fit together"};
    for (float v : p.values)
      if (!std::isfinite(v)) return engine::Error{path.string(), "PRM", "a value is not finite"};
  }
  return f;
}

}  // namespace gi
