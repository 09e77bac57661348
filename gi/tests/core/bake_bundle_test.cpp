// The bake bundle's building blocks: the checksummed blob container (round trip, every
// corruption rejected with the file named), atomic writes that leave nothing behind on
// failure, manifest.json, and the scene geometry hash that detects stale bundles.
#include <gtest/gtest.h>
#include <engine/gltf.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <span>
#include <string>
#include <vector>

#include "bundle/bundle.h"
#include "io/content_hash.h"

namespace {

namespace fs = std::filesystem;

constexpr gi::BlobMagic kMagic{"GITESTBL"};

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "bake_bundle_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

std::vector<std::byte> pattern(std::size_t n) {
  std::vector<std::byte> v(n);
  for (std::size_t i = 0; i < n; ++i) v[i] = static_cast<std::byte>((i * 131 + 7) & 0xff);
  return v;
}

std::vector<std::byte> read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::vector<char> c((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::byte> b(c.size());
  for (std::size_t i = 0; i < c.size(); ++i) b[i] = static_cast<std::byte>(c[i]);
  return b;
}

void write_all(const fs::path& p, const std::vector<std::byte>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// Expects a read error naming the file and containing `what`.
void expect_read_error(const fs::path& p, const std::string& what, std::uint32_t version = 3) {
  auto r = gi::read_blob(p, kMagic, version);
  ASSERT_FALSE(r.ok()) << "a damaged file was accepted (" << what << ")";
  EXPECT_EQ(r.error().file, p.string());
  EXPECT_NE(r.error().to_string().find(what), std::string::npos) << r.error().to_string();
}

std::size_t files_in(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

engine::SceneAsset cornell() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset.ok()) << asset.error().to_string();
  return std::move(asset).value();
}

}  // namespace

TEST(BundleBlob, RoundTripsPayloadExactly) {
  const fs::path dir = scratch_dir("round_trip");
  const auto payload = pattern(1000);
  ASSERT_TRUE(gi::write_blob(dir / "a.bin", kMagic, 3, payload).ok());
  EXPECT_EQ(fs::file_size(dir / "a.bin"), gi::kBlobHeaderBytes + payload.size());
  auto back = gi::read_blob(dir / "a.bin", kMagic, 3);
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back.value(), payload);
  EXPECT_EQ(files_in(dir), 1u) << "no temporary file left";

  ASSERT_TRUE(gi::write_blob(dir / "empty.bin", kMagic, 3, {}).ok());
  auto empty = gi::read_blob(dir / "empty.bin", kMagic, 3);
  ASSERT_TRUE(empty.ok()) << empty.error().to_string();
  EXPECT_TRUE(empty->empty());
}

TEST(BundleBlob, RejectsEveryCorruptionNamingTheFile) {
  const fs::path dir = scratch_dir("corrupt");
  const fs::path good = dir / "good.bin";
  ASSERT_TRUE(gi::write_blob(good, kMagic, 3, pattern(256)).ok());
  const std::vector<std::byte> bytes = read_all(good);

  expect_read_error(dir / "missing.bin", "not found");

  std::vector<std::byte> b(bytes.begin(), bytes.begin() + 20);
  write_all(dir / "short_header.bin", b);
  expect_read_error(dir / "short_header.bin", "truncated header");

  b = bytes;
  b.resize(bytes.size() - 10);
  write_all(dir / "truncated.bin", b);
  expect_read_error(dir / "truncated.bin", "truncated");

  b = bytes;
  b.push_back(std::byte{0});
  write_all(dir / "trailing.bin", b);
  expect_read_error(dir / "trailing.bin", "trailing bytes");

  b = bytes;
  b[gi::kBlobHeaderBytes + 100] ^= std::byte{0x10};
  write_all(dir / "flipped.bin", b);
  expect_read_error(dir / "flipped.bin", "checksum mismatch");

  b = bytes;
  b[0] = std::byte{'X'};
  write_all(dir / "magic.bin", b);
  expect_read_error(dir / "magic.bin", "wrong magic");

  expect_read_error(good, "unsupported version 3", /*version=*/4);
  EXPECT_TRUE(gi::read_blob(good, kMagic, 3).ok());
}

// A file claiming terabytes (here a sparse one: no disk used) is refused before anything is
// allocated, naming the limit.
TEST(BundleBlob, AFileLargerThanAnyBakeFileIsRefusedBeforeReading) {
  const fs::path dir = scratch_dir("huge");
  const fs::path path = dir / "prm_panes.bin";
  std::ofstream(path) << "GIPRMPAN";
  fs::resize_file(path, std::uintmax_t{4} << 40);  // 4 TiB, sparse
  auto r = gi::read_blob(path, gi::BlobMagic{"GIPRMPAN"}, 1);
  fs::remove(path);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, path.string());
  EXPECT_NE(r.error().to_string().find("larger than any bake file can be"), std::string::npos) << r.error().to_string();
}

TEST(BundleAtomicWrite, FailedWritesLeaveNoFile) {
  const fs::path dir = scratch_dir("atomic");
  const auto payload = pattern(64);
  // The parent is a file: nothing can be created.
  write_all(dir / "plain_file", pattern(4));
  auto s = gi::write_file_atomic(dir / "plain_file" / "out.bin", payload);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().to_string().find("out.bin"), std::string::npos) << s.error().to_string();

  // The temporary file is written but the rename fails (the target is a non-empty
  // directory): the temporary file must be removed, the target untouched.
  fs::create_directories(dir / "target.bin" / "inside");
  s = gi::write_file_atomic(dir / "target.bin", payload);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().to_string().find("target.bin"), std::string::npos) << s.error().to_string();
  EXPECT_TRUE(fs::is_directory(dir / "target.bin" / "inside"));
  EXPECT_EQ(files_in(dir), 2u) << "only plain_file and target.bin: no temporary file left";

  // Replacing an existing file works and is complete.
  ASSERT_TRUE(gi::write_blob(dir / "a.bin", kMagic, 3, pattern(10)).ok());
  ASSERT_TRUE(gi::write_blob(dir / "a.bin", kMagic, 3, payload).ok());
  EXPECT_EQ(gi::read_blob(dir / "a.bin", kMagic, 3).value(), payload);
  EXPECT_EQ(files_in(dir), 3u);
}

TEST(BundleManifest, RoundTripsAndUpdatesOneMethodKeepingOthers) {
  const fs::path dir = scratch_dir("manifest");
  ASSERT_TRUE(gi::update_manifest_method(dir, "00000000000000aa", "a.gltf", "light_atlas", {{"x", 1}}).ok());
  ASSERT_TRUE(gi::update_manifest_method(dir, "00000000000000aa", "a.gltf", "prm", {{"y", 2}}).ok());
  ASSERT_TRUE(gi::update_manifest_method(dir, "00000000000000aa", "a.gltf", "light_atlas", {{"x", 3}}).ok());
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok()) << m.error().to_string();
  EXPECT_EQ(m->format_version, gi::kManifestFormatVersion);
  EXPECT_EQ(m->geometry_hash, "00000000000000aa");
  EXPECT_EQ(m->scene, "a.gltf");
  EXPECT_EQ(m->methods["light_atlas"]["x"], 3);
  EXPECT_EQ(m->methods["prm"]["y"], 2);
  auto missing = gi::manifest_method(dir, *m, "dlm");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().to_string().find("dlm"), std::string::npos);

  // Other geometry: the old entries describe another bake and are dropped.
  ASSERT_TRUE(gi::update_manifest_method(dir, "00000000000000bb", "a.gltf", "light_atlas", {{"x", 4}}).ok());
  m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok());
  EXPECT_FALSE(m->methods.contains("prm"));
  EXPECT_EQ(files_in(dir), 1u);
}

TEST(BundleManifest, RejectsBadManifestsNamingTheFile) {
  const fs::path dir = scratch_dir("manifest_bad");
  const fs::path file = dir / gi::kManifestFileName;
  const auto expect_error = [&](const std::string& text, const std::string& what) {
    std::ofstream(file, std::ios::trunc) << text;
    auto m = gi::read_manifest(dir);
    ASSERT_FALSE(m.ok()) << text;
    EXPECT_EQ(m.error().file, file.string());
    EXPECT_NE(m.error().to_string().find(what), std::string::npos) << m.error().to_string();
  };
  auto none = gi::read_manifest(dir);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().file, file.string());
  expect_error("{ \"format_version\": 3, ", "malformed JSON");
  expect_error("[1, 2]", "not a JSON object");
  // Version 1 bundles (FNV-1a checksums) and future ones are refused with what to do.
  expect_error(R"({"format_version": 1, "geometry_hash": "a", "scene": "s", "methods": {}})", "format_version 1");
  expect_error(R"({"format_version": 1, "geometry_hash": "a", "scene": "s", "methods": {}})", "re-bake");
  expect_error(R"({"format_version": 2, "geometry_hash": "a", "scene": "s", "methods": {}})", "re-bake");
  expect_error(R"({"format_version": 4, "geometry_hash": "a", "scene": "s", "methods": {}})", "format_version 4");
  expect_error(R"({"format_version": 4294967299, "geometry_hash": "a", "scene": "s", "methods": {}})",
               "format_version 4294967299");  // 2^32 + 3 does not narrow to 3
  expect_error(R"({"format_version": 3, "scene": "s", "methods": {}})", "geometry_hash: missing field");
  expect_error(R"({"format_version": 3, "geometry_hash": "a", "scene": "s", "methods": []})", "methods");
  expect_error(R"({"format_version": "1", "geometry_hash": "a", "scene": "s", "methods": {}})", "integer");
  // A crafted manifest nested 200,000 levels deep: refused, not a stack overflow.
  expect_error(R"({"format_version": 3, "geometry_hash": "a", "scene": "s", "methods": {"x": )" +
                   std::string(200000, '[') + std::string(200000, ']') + "}}",
               "nested deeper than 64 levels");
}

TEST(BundleFileName, OnlyPlainNamesInsideTheBundle) {
  EXPECT_TRUE(gi::is_bundle_file_name("light_atlas.exr"));
  EXPECT_FALSE(gi::is_bundle_file_name(""));
  EXPECT_FALSE(gi::is_bundle_file_name(".."));
  EXPECT_FALSE(gi::is_bundle_file_name("../secret"));
  EXPECT_FALSE(gi::is_bundle_file_name("/etc/passwd"));
}

TEST(BundleGeometryHash, StableForTheSameScene) {
  const engine::SceneAsset a = cornell();
  engine::SceneAsset b = cornell();
  b.source = "/elsewhere/copy.gltf";
  const std::string h = gi::scene_geometry_hash(gi::bake_input_from(a));
  EXPECT_EQ(h.size(), 16u);
  EXPECT_EQ(h, gi::scene_geometry_hash(gi::bake_input_from(a)));
  EXPECT_EQ(h, gi::scene_geometry_hash(gi::bake_input_from(b))) << "independent of the file path";
}

TEST(BundleGeometryHash, ChangesWithStaticGeometryAndAlbedo) {
  const engine::SceneAsset base = cornell();
  const std::string h = gi::scene_geometry_hash(gi::bake_input_from(base));

  engine::SceneAsset moved_vertex = base;
  moved_vertex.meshes[1].primitives[0].positions[0].y += 0.01f;  // short_block, a static node
  EXPECT_NE(gi::scene_geometry_hash(gi::bake_input_from(moved_vertex)), h);

  engine::SceneAsset moved_node = base;
  moved_node.nodes[2].translation.x += 0.01f;  // tall_block
  EXPECT_NE(gi::scene_geometry_hash(gi::bake_input_from(moved_node)), h);

  engine::SceneAsset albedo = base;
  albedo.materials[0].base_color.x *= 0.9f;
  EXPECT_NE(gi::scene_geometry_hash(gi::bake_input_from(albedo)), h);

  engine::SceneAsset emissive = base;
  emissive.materials[3].emissive.y += 0.5f;
  EXPECT_NE(gi::scene_geometry_hash(gi::bake_input_from(emissive)), h);

  // A double-sided emitter lights through its back too: a bundle of the one-sided scene is stale.
  engine::SceneAsset two_sided = base;
  two_sided.materials[3].double_sided = !two_sided.materials[3].double_sided;
  EXPECT_NE(gi::scene_geometry_hash(gi::bake_input_from(two_sided)), h);
}

TEST(BundleGeometryHash, IgnoresDynamicNodes) {
  engine::SceneAsset base = cornell();
  base.nodes[2].gi.mobility = engine::Mobility::Dynamic;  // the tall block becomes a movable prop
  const std::string h = gi::scene_geometry_hash(gi::bake_input_from(base));
  EXPECT_NE(h, gi::scene_geometry_hash(gi::bake_input_from(cornell()))) << "what is static is part of the hash";

  engine::SceneAsset moved = base;
  moved.nodes[2].translation.x += 0.3f;
  moved.nodes[2].rotation = glm::angleAxis(0.5f, glm::vec3(0, 1, 0));
  EXPECT_EQ(gi::scene_geometry_hash(gi::bake_input_from(moved)), h);
  moved.meshes[2].primitives[0].positions[0].y += 0.2f;  // its own mesh deforms
  EXPECT_EQ(gi::scene_geometry_hash(gi::bake_input_from(moved)), h);
}

TEST(BundleLightsHash, ChangesWithStaticLightsOnly) {
  const engine::SceneAsset base = cornell();
  const std::string h = gi::static_lights_hash(gi::bake_input_from(base));
  EXPECT_EQ(gi::static_lights_hash(gi::bake_input_from(cornell())), h);
  EXPECT_EQ(gi::scene_geometry_hash(gi::bake_input_from(base)), gi::scene_geometry_hash(gi::bake_input_from(base)))
      << "lights do not enter the geometry hash";

  int light_node = -1;
  for (std::size_t n = 0; n < base.nodes.size(); ++n)
    if (base.nodes[n].light >= 0) light_node = static_cast<int>(n);
  ASSERT_GE(light_node, 0);
  const auto ln = static_cast<std::size_t>(light_node);
  const auto li = static_cast<std::size_t>(base.nodes[ln].light);

  engine::SceneAsset brighter = base;
  brighter.lights[li].light.intensity *= 2.0f;
  EXPECT_NE(gi::static_lights_hash(gi::bake_input_from(brighter)), h);
  EXPECT_EQ(gi::scene_geometry_hash(gi::bake_input_from(brighter)), gi::scene_geometry_hash(gi::bake_input_from(base)));
  engine::SceneAsset moved = base;
  moved.nodes[ln].translation.x += 0.01f;
  EXPECT_NE(gi::static_lights_hash(gi::bake_input_from(moved)), h);

  // A light that moves at runtime is not part of a static bake: editing it keeps the hash.
  engine::SceneAsset dynamic = base;
  dynamic.lights[li].light.moves = true;
  const std::string hd = gi::static_lights_hash(gi::bake_input_from(dynamic));
  dynamic.lights[li].light.intensity *= 3.0f;
  dynamic.nodes[ln].translation.y -= 0.1f;
  EXPECT_EQ(gi::static_lights_hash(gi::bake_input_from(dynamic)), hd);
}

// Bundle checksums are XXH3-64: the published value of the empty input, independence from
// how the bytes are split into calls, and a single flipped bit changing the hash.
TEST(ContentHash, IsXxh3OfTheByteStream) {
  EXPECT_EQ(gi::ContentHash().hex(), "2d06800538d394c2");  // XXH3_64bits("", 0), xxHash's test vector
  std::vector<float> v(1000);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = static_cast<float>(i) * 0.25f;
  gi::ContentHash whole, one_by_one;
  whole.add_values(std::span<const float>(v));
  one_by_one.add_value(static_cast<std::uint64_t>(v.size()));
  for (float f : v) one_by_one.add_value(f);
  EXPECT_EQ(whole.value(), one_by_one.value());
  v[517] = std::nextafter(v[517], 1e9f);
  gi::ContentHash flipped;
  flipped.add_values(std::span<const float>(v));
  EXPECT_NE(flipped.value(), whole.value());
  EXPECT_EQ(whole.hex().size(), 16u);
}
