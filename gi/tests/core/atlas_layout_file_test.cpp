// The atlas layout a bake writes into its bundle (bundle/atlas_layout_file.h) and
// BundleReader::atlas_layout, which reads it at load instead of re-charting the geometry:
// an exact round trip, and every damaged, missing or stale file refused with its name.
#include "bundle/atlas_layout_file.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "bundle/bundle.h"
#include "bundle/bundle_reader.h"

namespace {

namespace fs = std::filesystem;

constexpr const char* kMethod = "layout_test";

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "atlas_layout_file_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

gi::BakeInput cornell_input() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf", {.load_images = false});
  EXPECT_TRUE(asset.ok()) << asset.error().to_string();
  return gi::bake_input_from(asset.value());
}

// A bundle in `dir` holding a layout of `input` as a method's entry would (files.layout and
// the "layout" summary); returns the layout written.
gi::AtlasLayout write_bundle(const fs::path& dir, const gi::BakeInput& input) {
  auto layout = gi::static_world_layout(input, 8.0f);
  EXPECT_TRUE(layout.ok());
  const std::string hash = gi::scene_geometry_hash(input);
  auto file = gi::write_bundle_atlas_layout(dir, "layout.bin", *layout, hash);
  EXPECT_TRUE(file.ok()) << file.error().to_string();
  const nlohmann::json entry{{"files", {{"layout", *file}}}, {"layout", gi::baked_atlas_layout_json(*layout)}};
  EXPECT_TRUE(gi::update_manifest_method(dir, hash, "cornell_box.gltf", kMethod, entry).ok());
  return std::move(layout).value();
}

engine::Result<gi::AtlasLayout> read_back(const fs::path& dir, const gi::BakeInput& input) {
  auto bundle = gi::BundleReader::open(dir, kMethod, input, "re-bake");
  if (!bundle) return bundle.error();
  gi::JsonFields f = bundle->fields();
  const gi::BakedAtlasLayout baked = gi::read_baked_atlas_layout(f);
  if (f.error()) return *f.error();
  return bundle->atlas_layout(input, baked, "test atlas layout");
}

template <class T>
bool same_bytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_error(const engine::Result<gi::AtlasLayout>& r, const fs::path& file, const std::string& what) {
  ASSERT_FALSE(r.ok()) << "accepted (" << what << ")";
  EXPECT_EQ(r.error().file, file.string());
  EXPECT_NE(r.error().to_string().find(what), std::string::npos) << r.error().to_string();
}

void rewrite(const fs::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::vector<char> read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(AtlasLayoutFile, RoundTripsTheBakedLayoutExactly) {
  const fs::path dir = scratch_dir("round_trip");
  const gi::BakeInput input = cornell_input();
  const gi::AtlasLayout written = write_bundle(dir, input);
  auto read = read_back(dir, input);
  ASSERT_TRUE(read.ok()) << read.error().to_string();
  EXPECT_EQ(read->width, written.width);
  EXPECT_EQ(read->height, written.height);
  EXPECT_EQ(read->texels_per_metre, written.texels_per_metre);
  EXPECT_EQ(read->requested_texels_per_metre, written.requested_texels_per_metre);
  EXPECT_EQ(read->padding_texels, written.padding_texels);
  ASSERT_EQ(read->charts.size(), written.charts.size());
  for (std::size_t c = 0; c < written.charts.size(); ++c) {
    const gi::AtlasChart &a = read->charts[c], &b = written.charts[c];
    EXPECT_TRUE(a.mesh == b.mesh && a.origin == b.origin && a.size == b.size && a.normal == b.normal &&
                a.triangle_count == b.triangle_count && a.area_m2 == b.area_m2)
        << "chart " << c;
  }
  ASSERT_EQ(read->meshes.size(), written.meshes.size());
  for (std::size_t m = 0; m < written.meshes.size(); ++m) {
    const gi::AtlasMeshUv &a = read->meshes[m], &b = written.meshes[m];
    EXPECT_EQ(a.id, b.id);
    EXPECT_TRUE(same_bytes(a.indices, b.indices) && same_bytes(a.source_vertex, b.source_vertex) &&
                same_bytes(a.uv1, b.uv1) && same_bytes(a.triangle_chart, b.triangle_chart))
        << "mesh " << m;
  }
  // The same layout rebuilt from the geometry: what load used to compute.
  auto rebuilt = gi::static_world_layout(input, 8.0f);
  ASSERT_TRUE(rebuilt.ok());
  EXPECT_TRUE(same_bytes(rebuilt->meshes[0].uv1, read->meshes[0].uv1));
}

TEST(AtlasLayoutFile, ATruncatedFileIsRefusedNamingIt) {
  const fs::path dir = scratch_dir("truncated");
  const gi::BakeInput input = cornell_input();
  const gi::AtlasLayout layout = write_bundle(dir, input);
  const fs::path file = dir / "layout.bin";
  std::vector<char> bytes = read_all(file);
  bytes.resize(bytes.size() - 7);
  rewrite(file, bytes);
  // The manifest's checksum catches it first; the file's own header too.
  expect_error(read_back(dir, input), file, "checksum");
  auto direct = gi::read_atlas_layout_file(file);
  ASSERT_FALSE(direct.ok());
  EXPECT_EQ(direct.error().file, file.string());
  EXPECT_NE(direct.error().message.find("truncated"), std::string::npos) << direct.error().to_string();
}

TEST(AtlasLayoutFile, AWrongChecksumIsRefusedNamingIt) {
  const fs::path dir = scratch_dir("checksum");
  const gi::BakeInput input = cornell_input();
  write_bundle(dir, input);
  const fs::path file = dir / "layout.bin";
  std::vector<char> bytes = read_all(file);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x10);
  rewrite(file, bytes);
  expect_error(read_back(dir, input), file, "checksum");
  auto direct = gi::read_atlas_layout_file(file);
  ASSERT_FALSE(direct.ok());
  EXPECT_NE(direct.error().message.find("checksum mismatch"), std::string::npos) << direct.error().to_string();
}

TEST(AtlasLayoutFile, ALayoutOfOtherGeometryIsStale) {
  const fs::path dir = scratch_dir("stale");
  const gi::BakeInput input = cornell_input();
  write_bundle(dir, input);
  // A scene whose static geometry changed: the manifest's geometry hash refuses it.
  gi::BakeInput moved = input;
  moved.meshes[1].primitives[0].positions[0].y += 0.01f;
  auto stale = read_back(dir, moved);
  ASSERT_FALSE(stale.ok());
  EXPECT_NE(stale.error().to_string().find("re-bake"), std::string::npos) << stale.error().to_string();
  // A layout file of other geometry under a current manifest: its own hash refuses it.
  auto layout = gi::static_world_layout(input, 8.0f);
  ASSERT_TRUE(layout.ok());
  auto other = gi::write_bundle_atlas_layout(dir, "layout.bin", *layout, "0123456789abcdef");
  ASSERT_TRUE(other.ok());
  const nlohmann::json entry{{"files", {{"layout", *other}}}, {"layout", gi::baked_atlas_layout_json(*layout)}};
  ASSERT_TRUE(gi::update_manifest_method(dir, gi::scene_geometry_hash(input), "cornell_box.gltf", kMethod, entry).ok());
  expect_error(read_back(dir, input), dir / "layout.bin", "belongs to geometry 0123456789abcdef");
}

TEST(AtlasLayoutFile, ABundleWithoutTheFileSaysReBake) {
  const fs::path dir = scratch_dir("missing");
  const gi::BakeInput input = cornell_input();
  const gi::AtlasLayout layout = write_bundle(dir, input);
  // The entry without files.layout (as a bundle of an older bake would be).
  const nlohmann::json entry{{"layout", gi::baked_atlas_layout_json(layout)}};
  ASSERT_TRUE(gi::update_manifest_method(dir, gi::scene_geometry_hash(input), "cornell_box.gltf", kMethod, entry).ok());
  auto r = read_back(dir, input);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, (dir / gi::kManifestFileName).string());
  EXPECT_NE(r.error().to_string().find("files.layout"), std::string::npos) << r.error().to_string();
  EXPECT_NE(r.error().to_string().find("re-bake"), std::string::npos) << r.error().to_string();
  // The entry names the file, the file is gone.
  write_bundle(dir, input);
  fs::remove(dir / "layout.bin");
  auto gone = read_back(dir, input);
  ASSERT_FALSE(gone.ok());
  EXPECT_NE(gone.error().to_string().find("layout.bin"), std::string::npos) << gone.error().to_string();
}

TEST(AtlasLayoutFile, ALayoutThatBreaksItsInvariantsIsNotWritten) {
  const fs::path dir = scratch_dir("invalid");
  auto layout = gi::static_world_layout(cornell_input(), 8.0f);
  ASSERT_TRUE(layout.ok());
  layout->meshes[0].indices[0] = static_cast<std::uint32_t>(layout->meshes[0].uv1.size());
  const engine::Status s = gi::write_atlas_layout_file(dir / "layout.bin", *layout, "0123456789abcdef");
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().message.find("beyond"), std::string::npos) << s.error().to_string();
  EXPECT_FALSE(fs::exists(dir / "layout.bin"));
}
