// Distributed bakes (issue 19, docs/distributed-bake.md): gi::bake_bundle with
// BakeOptions::shard_index/shard_count bakes one shard's share of the light atlas's final
// gather and the PRM's panes into a shard file; merge_shards writes the bundle from them.
// The merged bundle is byte-identical to a one-process bake for N = 1, 2 and 7, and a merge
// refuses a missing, duplicated, damaged or foreign shard, naming it, without leaving a bundle.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <gi/bake.h>
#include <gi/bake_input.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace {

namespace fs = std::filesystem;

std::map<std::string, std::vector<char>> bundle_files(const fs::path& dir) {
  std::map<std::string, std::vector<char>> out;
  for (const auto& e : fs::directory_iterator(dir)) {
    std::ifstream in(e.path(), std::ios::binary);
    out[e.path().filename().string()] = std::vector<char>(std::istreambuf_iterator<char>(in), {});
  }
  return out;
}

// The Cornell box's light atlas and PRM at the preview preset, at a density giving ~1000
// texels (16 blocks of 64: seven shards all get work, some three blocks).
gi::BakeOptions small_options() {
  return {.preset = "preview", .methods = {"light_atlas", "prm"}, .texels_per_metre = 20.0f, .threads = 2, .seed = 5};
}

class DistributedBake : public ::testing::Test {
 protected:
  void SetUp() override {
    auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
    ASSERT_TRUE(asset.ok()) << asset.error().to_string();
    input_ = gi::bake_input_from(*asset);
    root_ = fs::path(GI_BINARY_DIR) / "test_output" / "distributed_bake" /
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::error_code ec;
    fs::remove_all(root_, ec);
    fs::create_directories(root_);
  }

  // Shards 0..count-1 of `dir` (each in its own call, as separate processes would).
  void bake_shards(const fs::path& dir, std::uint32_t count, const gi::BakeOptions& base = small_options()) {
    for (std::uint32_t i = 0; i < count; ++i) {
      gi::BakeOptions o = base;
      o.shard_index = i;
      o.shard_count = count;
      auto r = gi::bake_bundle(input_, dir, o);
      ASSERT_TRUE(r.ok()) << r.error().to_string();
      ASSERT_TRUE(fs::exists(gi::shard_directory(dir) / gi::shard_file_name(i, count)));
    }
    EXPECT_FALSE(fs::exists(dir)) << "a shard bake must not write the bundle";
  }

  engine::Result<gi::BakeReport> merge(const fs::path& dir, gi::BakeOptions o = small_options()) {
    o.merge_shards = true;
    return gi::bake_bundle(input_, dir, o);
  }

  gi::BakeInput input_;
  fs::path root_;
};

TEST_F(DistributedBake, MergedBundleIsByteIdenticalToOneProcessForOneTwoAndSevenShards) {
  const fs::path whole = root_ / "whole.gibake";
  auto w = gi::bake_bundle(input_, whole, small_options());
  ASSERT_TRUE(w.ok()) << w.error().to_string();
  const auto expected = bundle_files(whole);
  for (const char* name : {"manifest.json", "light_atlas.exr", "light_atlas_vpls.bin", "prm_panes.bin"})
    ASSERT_TRUE(expected.contains(name)) << name;
  for (std::uint32_t n : {1u, 2u, 7u}) {
    const fs::path dir = root_ / ("merged_" + std::to_string(n) + ".gibake");
    bake_shards(dir, n);
    auto m = merge(dir);
    ASSERT_TRUE(m.ok()) << "N = " << n << ": " << m.error().to_string();
    const auto got = bundle_files(dir);
    ASSERT_EQ(got.size(), expected.size()) << "N = " << n;
    for (const auto& [name, bytes] : expected) {
      if (name == gi::kBakeStatsFileName) continue;
      ASSERT_TRUE(got.contains(name)) << name << " missing for N = " << n;
      EXPECT_TRUE(got.at(name) == bytes) << name << " differs from the one-process bake for N = " << n;
    }
  }
}

TEST_F(DistributedBake, MergeRefusesAMissingShardNamingIt) {
  const fs::path dir = root_ / "b.gibake";
  bake_shards(dir, 3);
  fs::remove(gi::shard_directory(dir) / gi::shard_file_name(1, 3));
  auto m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("shard-0001-of-0003.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_NE(m.error().to_string().find("missing"), std::string::npos) << m.error().to_string();
  EXPECT_FALSE(fs::exists(dir));
}

TEST_F(DistributedBake, MergeRefusesADuplicatedShardNamingIt) {
  const fs::path dir = root_ / "b.gibake";
  bake_shards(dir, 2);
  const fs::path shards = gi::shard_directory(dir);
  fs::copy_file(shards / gi::shard_file_name(0, 2), shards / "copy-of-shard-0.gishard");
  auto m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("duplicate shard 0"), std::string::npos) << m.error().to_string();
  EXPECT_NE(m.error().to_string().find("copy-of-shard-0.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_FALSE(fs::exists(dir));
}

TEST_F(DistributedBake, MergeRefusesADamagedShardNamingIt) {
  const fs::path dir = root_ / "b.gibake";
  bake_shards(dir, 2);
  const fs::path shard = gi::shard_directory(dir) / gi::shard_file_name(1, 2);
  std::vector<char> bytes;
  {
    std::ifstream in(shard, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  ASSERT_GT(bytes.size(), 1000u);
  // A flipped byte in the payload, then the file cut short.
  std::vector<char> flipped = bytes;
  flipped[bytes.size() / 2] ^= 0x10;
  std::ofstream(shard, std::ios::binary).write(flipped.data(), static_cast<std::streamsize>(flipped.size()));
  auto m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("shard-0001-of-0002.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_NE(m.error().to_string().find("checksum"), std::string::npos) << m.error().to_string();
  std::ofstream(shard, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() - 7));
  m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("shard-0001-of-0002.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_FALSE(fs::exists(dir));
  // Restored, the same shards merge.
  std::ofstream(shard, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  EXPECT_TRUE(merge(dir).ok());
}

TEST_F(DistributedBake, MergeRefusesForeignShardsNamingThem) {
  const fs::path dir = root_ / "b.gibake";
  const fs::path shards = gi::shard_directory(dir);
  bake_shards(dir, 2);
  const auto replace_shard_1_from = [&](const fs::path& other_dir, std::uint32_t count) {
    fs::copy_file(gi::shard_directory(other_dir) / gi::shard_file_name(1, count), shards / gi::shard_file_name(1, 2),
                  fs::copy_options::overwrite_existing);
  };
  const fs::path keep = root_ / "shard1.keep";
  fs::copy_file(shards / gi::shard_file_name(1, 2), keep);

  // Other settings (seed).
  gi::BakeOptions seed = small_options();
  seed.seed = 6;
  bake_shards(root_ / "seed.gibake", 2, seed);
  replace_shard_1_from(root_ / "seed.gibake", 2);
  auto m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("shard-0001-of-0002.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_NE(m.error().to_string().find("other settings"), std::string::npos) << m.error().to_string();

  // Other N: shard 1 of 3 among shards of 2.
  fs::copy_file(keep, shards / gi::shard_file_name(1, 2), fs::copy_options::overwrite_existing);
  bake_shards(root_ / "three.gibake", 3);
  fs::copy_file(gi::shard_directory(root_ / "three.gibake") / gi::shard_file_name(1, 3),
                shards / gi::shard_file_name(1, 3));
  m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("shard-0001-of-0003.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_NE(m.error().to_string().find("of 3"), std::string::npos) << m.error().to_string();
  fs::remove(shards / gi::shard_file_name(1, 3));

  // Another scene: the same options on the scene with its geometry changed.
  gi::BakeInput moved = input_;
  bool changed = false;
  for (gi::BakeInstance& inst : moved.instances)
    if (!changed && inst.mobility == gi::BakeMobility::Static) inst.object_to_world[3].x += 0.25f, changed = true;
  ASSERT_TRUE(changed);
  gi::BakeOptions o = small_options();
  o.shard_index = 1;
  o.shard_count = 2;
  auto other = gi::bake_bundle(moved, root_ / "moved.gibake", o);
  ASSERT_TRUE(other.ok()) << other.error().to_string();
  replace_shard_1_from(root_ / "moved.gibake", 2);
  m = merge(dir);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("shard-0001-of-0002.gishard"), std::string::npos) << m.error().to_string();
  EXPECT_NE(m.error().to_string().find("other geometry"), std::string::npos) << m.error().to_string();
  EXPECT_FALSE(fs::exists(dir));

  fs::copy_file(keep, shards / gi::shard_file_name(1, 2), fs::copy_options::overwrite_existing);
  EXPECT_TRUE(merge(dir).ok());
}

TEST_F(DistributedBake, AnInterruptedMergeLeavesNoBundle) {
  const fs::path dir = root_ / "b.gibake";
  bake_shards(dir, 2);
  gi::BakeOptions o = small_options();
  o.merge_shards = true;
  // Cancelled in the PRM, after the light atlas was written into the staging directory.
  const gi::BakeHost host{.progress = [](std::string_view stage, double) { return stage != "PRM"; }, .log = {}};
  auto m = gi::bake_bundle(input_, dir, o, host);
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error().kind, engine::ErrorKind::Cancelled) << m.error().to_string();
  EXPECT_FALSE(fs::exists(dir)) << "an interrupted merge must leave no bundle";
  EXPECT_FALSE(fs::exists(dir.parent_path() / ".b.gibake.staging"));
}

TEST_F(DistributedBake, ShardOutOfRangeIsInvalid) {
  gi::BakeOptions o = small_options();
  o.shard_index = 2;
  o.shard_count = 2;
  auto r = gi::bake_bundle(input_, root_ / "x.gibake", o);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().kind, engine::ErrorKind::Invalid);
}

}  // namespace

// Antiradiance's links are sharded by receiver element blocks; the merge solves the baseline
// from all of them: the corridor (a door) bakes to the same antiradiance.bin for N = 1, 2, 7.
TEST_F(DistributedBake, AntiradianceMergedBundleIsByteIdenticalForOneTwoAndSevenShards) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/corridor.gltf");
  ASSERT_TRUE(asset.ok()) << asset.error().to_string();
  input_ = gi::bake_input_from(*asset);
  const gi::BakeOptions options{.preset = "preview", .methods = {"antiradiance"}, .threads = 2, .seed = 5};
  const fs::path whole = root_ / "whole.gibake";
  auto w = gi::bake_bundle(input_, whole, options);
  ASSERT_TRUE(w.ok()) << w.error().to_string();
  const auto expected = bundle_files(whole);
  ASSERT_TRUE(expected.contains("antiradiance.bin"));
  for (std::uint32_t n : {1u, 2u, 7u}) {
    const fs::path dir = root_ / ("merged_" + std::to_string(n) + ".gibake");
    bake_shards(dir, n, options);
    auto m = merge(dir, options);
    ASSERT_TRUE(m.ok()) << "N = " << n << ": " << m.error().to_string();
    const auto got = bundle_files(dir);
    ASSERT_EQ(got.size(), expected.size()) << "N = " << n;
    for (const auto& [name, bytes] : expected) {
      if (name == gi::kBakeStatsFileName) continue;
      ASSERT_TRUE(got.contains(name)) << name << " missing for N = " << n;
      EXPECT_TRUE(got.at(name) == bytes) << name << " differs from the one-process bake for N = " << n;
    }
  }
  // A shard of the atlas-only bake is foreign to this one (its methods differ).
  const fs::path mixed = root_ / "mixed.gibake";
  bake_shards(mixed, 2, options);
  gi::BakeOptions atlas_only = small_options();
  atlas_only.methods = {"light_atlas"};
  atlas_only.seed = 5;
  atlas_only.shard_index = 1;
  atlas_only.shard_count = 2;
  ASSERT_TRUE(gi::bake_bundle(input_, mixed, atlas_only).ok());
  auto m = merge(mixed, options);
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.error().to_string().find("foreign shard"), std::string::npos) << m.error().to_string();
  EXPECT_FALSE(fs::exists(mixed));
}
