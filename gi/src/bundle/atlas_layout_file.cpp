#include "bundle/atlas_layout_file.h"

#include <engine/byte_stream.h>
#include <engine/finite.h>

#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "io/content_hash.h"
#include "io/zstd_stream.h"

namespace gi {

namespace {

// zstd level of the body: UV1 and index arrays compress well at a fast level.
constexpr int kZstdLevel = 6;

std::string str(std::size_t v) { return std::to_string(v); }

// Empty when `layout` keeps the invariants the runtime relies on (atlas_layout_file.h), else
// what is wrong.
std::string check_layout(const AtlasLayout& l) {
  if (l.width < 1 || l.height < 1 || l.width > 16384 || l.height > 16384)
    return "atlas size " + std::to_string(l.width) + "x" + std::to_string(l.height) + " is outside 1..16384";
  if (!std::isfinite(l.texels_per_metre) || !(l.texels_per_metre > 0.0f) ||
      !std::isfinite(l.requested_texels_per_metre) || !(l.requested_texels_per_metre > 0.0f))
    return "texel densities must be finite and positive";
  if (l.padding_texels < 0 || l.padding_texels > 64) return "padding_texels is outside 0..64";
  for (std::size_t c = 0; c < l.charts.size(); ++c) {
    const AtlasChart& ch = l.charts[c];
    if (ch.mesh >= l.meshes.size())
      return "chart " + str(c) + " names mesh " + str(ch.mesh) + " of " + str(l.meshes.size());
    if (ch.origin.x < 0 || ch.origin.y < 0 || ch.size.x < 1 || ch.size.y < 1 || ch.size.x > l.width - ch.origin.x ||
        ch.size.y > l.height - ch.origin.y)
      return "chart " + str(c) + " does not lie inside the atlas";
    if (!engine::all_finite(ch.normal) || !std::isfinite(ch.area_m2)) return "chart " + str(c) + " is not finite";
  }
  for (std::size_t m = 0; m < l.meshes.size(); ++m) {
    const AtlasMeshUv& mesh = l.meshes[m];
    const std::string where = "mesh " + str(m) + ": ";
    if (mesh.indices.size() % 3 != 0) return where + "index count is not a multiple of 3";
    if (mesh.triangle_chart.size() != mesh.indices.size() / 3) return where + "one chart per triangle expected";
    if (mesh.source_vertex.size() != mesh.uv1.size()) return where + "source_vertex and uv1 differ in size";
    for (std::uint32_t i : mesh.indices)
      if (i >= mesh.uv1.size()) return where + "index " + str(i) + " beyond its " + str(mesh.uv1.size()) + " vertices";
    for (std::uint32_t c : mesh.triangle_chart)
      if (c >= l.charts.size()) return where + "triangle chart " + str(c) + " beyond " + str(l.charts.size());
    for (const glm::vec2& uv : mesh.uv1)
      if (!(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f)) return where + "uv1 outside [0, 1]";
  }
  return {};
}

std::vector<std::byte> pack_body(const AtlasLayout& l) {
  engine::ByteWriter w;
  w.put<std::uint64_t>(l.charts.size());
  for (const AtlasChart& c : l.charts) {
    w.put(c.mesh);
    w.put<std::int32_t>(c.origin.x);
    w.put<std::int32_t>(c.origin.y);
    w.put<std::int32_t>(c.size.x);
    w.put<std::int32_t>(c.size.y);
    w.put(c.normal);
    w.put(c.triangle_count);
    w.put(c.area_m2);
  }
  w.put<std::uint64_t>(l.meshes.size());
  for (const AtlasMeshUv& m : l.meshes) {
    w.put(m.id);
    w.put_array(m.indices);
    w.put_array(m.source_vertex);
    w.put_array(m.uv1);
    w.put_array(m.triangle_chart);
  }
  return w.take();
}

// Charts then meshes from the decompressed body; false when it is truncated. Counts are
// bounded by the bytes left (a chart takes 48 bytes, a mesh at least 40).
bool unpack_body(engine::ByteReader& r, AtlasLayout& l) {
  std::uint64_t charts = 0;
  if (!r.get(charts) || charts > r.remaining() / 48) return false;
  l.charts.resize(static_cast<std::size_t>(charts));
  for (AtlasChart& c : l.charts) {
    std::int32_t ox = 0, oy = 0, sx = 0, sy = 0;
    if (!(r.get(c.mesh) && r.get(ox) && r.get(oy) && r.get(sx) && r.get(sy) && r.get(c.normal) &&
          r.get(c.triangle_count) && r.get(c.area_m2)))
      return false;
    c.origin = glm::ivec2(ox, oy);
    c.size = glm::ivec2(sx, sy);
  }
  std::uint64_t meshes = 0;
  if (!r.get(meshes) || meshes > r.remaining() / 40) return false;
  l.meshes.resize(static_cast<std::size_t>(meshes));
  for (AtlasMeshUv& m : l.meshes)
    if (!(r.get(m.id) && r.get_array(m.indices) && r.get_array(m.source_vertex) && r.get_array(m.uv1) &&
          r.get_array(m.triangle_chart)))
      return false;
  return true;
}

}  // namespace

engine::Status write_atlas_layout_file(const std::filesystem::path& path, const AtlasLayout& layout,
                                       const std::string& geometry_hash) {
  if (std::string problem = check_layout(layout); !problem.empty())
    return engine::Error{path.string(), "", "cannot save the atlas layout: " + problem};
  const std::vector<std::byte> body = pack_body(layout);
  auto frame = write_zstd_stream(
      path, std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(body.data()), body.size()), kZstdLevel);
  if (!frame) return frame.error();
  engine::ByteWriter w;
  w.put_string(geometry_hash);
  w.put<std::int32_t>(layout.width);
  w.put<std::int32_t>(layout.height);
  w.put(layout.texels_per_metre);
  w.put(layout.requested_texels_per_metre);
  w.put<std::int32_t>(layout.padding_texels);
  w.put<std::uint64_t>(body.size());
  w.put_array(*frame);
  return write_blob(path, kAtlasLayoutMagic, kAtlasLayoutVersion, w.bytes());
}

std::uint64_t atlas_layout_fingerprint(const AtlasLayout& layout) {
  const std::vector<std::byte> body = pack_body(layout);
  ContentHash h;
  h.add_value(static_cast<std::int32_t>(layout.width));
  h.add_value(static_cast<std::int32_t>(layout.height));
  h.add_value(layout.texels_per_metre);
  h.add_value(layout.requested_texels_per_metre);
  h.add_value(static_cast<std::int32_t>(layout.padding_texels));
  h.add_bytes(body.data(), body.size());
  return h.value();
}

engine::Result<AtlasLayoutFile> read_atlas_layout_file(const std::filesystem::path& path) {
  auto payload = read_blob(path, kAtlasLayoutMagic, kAtlasLayoutVersion);
  if (!payload) return payload.error();
  engine::ByteReader r(payload.value());
  AtlasLayoutFile f;
  AtlasLayout& l = f.layout;
  std::int32_t width = 0, height = 0, padding = 0;
  std::uint64_t body_bytes = 0;
  std::vector<std::uint8_t> frame;
  const bool complete = r.get_string(f.geometry_hash) && r.get(width) && r.get(height) && r.get(l.texels_per_metre) &&
                        r.get(l.requested_texels_per_metre) && r.get(padding) && r.get(body_bytes) &&
                        r.get_array(frame);
  const std::string location = "payload byte " + std::to_string(r.offset());
  if (!complete) return engine::Error{path.string(), location, "truncated payload"};
  if (r.remaining() != 0) return engine::Error{path.string(), location, "unexpected data after the last field"};
  l.width = width;
  l.height = height;
  l.padding_texels = padding;
  auto body = read_zstd_stream(path, "body", frame, body_bytes);
  if (!body) return body.error();
  engine::ByteReader b(std::as_bytes(std::span<const std::uint8_t>(*body)));
  if (!unpack_body(b, l)) return engine::Error{path.string(), "body byte " + str(b.offset()), "truncated body"};
  if (b.remaining() != 0)
    return engine::Error{path.string(), "body byte " + str(b.offset()), "unexpected data after the last mesh"};
  if (std::string problem = check_layout(l); !problem.empty())
    return engine::Error{path.string(), "layout", problem + " (corrupt)"};
  return f;
}

}  // namespace gi
