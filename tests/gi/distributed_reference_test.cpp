// Distributed path-traced references (issue 19, docs/distributed-bake.md): gi::reference_shard
// computes one shard's blocks of 64 pixels / valid atlas texels into a shard file,
// gi::merge_reference_shards assembles the job's outputs from them. The merged image and
// atlas are bit-identical to a one-process run for N = 1, 2 and 7, and a merge refuses a
// missing, duplicated, damaged or foreign shard, naming it.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake_input.h>
#include <gi/reference.h>
#include <gi/reference_shard.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

void expect_identical(const gi::ReferenceOutputs& a, const gi::ReferenceOutputs& b) {
  ASSERT_EQ(a.image.has_value(), b.image.has_value());
  ASSERT_EQ(a.atlas.has_value(), b.atlas.has_value());
  if (a.image) {
    EXPECT_EQ(a.image->width, b.image->width);
    EXPECT_EQ(a.image->height, b.image->height);
    EXPECT_TRUE(same_bits(a.image->pixels, b.image->pixels)) << "image pixels differ";
  }
  if (a.atlas) {
    EXPECT_EQ(a.atlas->width, b.atlas->width);
    EXPECT_EQ(a.atlas->height, b.atlas->height);
    EXPECT_EQ(a.atlas->texels_per_metre, b.atlas->texels_per_metre);
    EXPECT_TRUE(same_bits(a.atlas->direct, b.atlas->direct)) << "atlas direct differs";
    EXPECT_TRUE(same_bits(a.atlas->indirect, b.atlas->indirect)) << "atlas indirect differs";
    EXPECT_TRUE(same_bits(a.atlas->total, b.atlas->total)) << "atlas total differs";
    EXPECT_TRUE(same_bits(a.atlas->valid, b.atlas->valid)) << "atlas validity differs";
    EXPECT_TRUE(same_bits(a.atlas->indirect_variance, b.atlas->indirect_variance)) << "atlas variance differs";
  }
}

std::vector<char> file_bytes(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::vector<char>(std::istreambuf_iterator<char>(in), {});
}

void write_bytes(const fs::path& p, const std::vector<char>& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

class DistributedReference : public ::testing::Test {
 protected:
  void SetUp() override {
    auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
    ASSERT_TRUE(asset.ok()) << asset.error().to_string();
    engine::Scene scene = engine::instantiate(std::move(asset).value());
    input_ = gi::bake_input_from(scene);
    const engine::Entity camera = engine::find_camera(scene.registry);
    ASSERT_FALSE(camera.is_null());
    const engine::Camera& cam = scene.registry.get<engine::Camera>(camera);
    // A 24x20 image (480 pixels: 8 blocks, so of 7 shards one gets two) and the atlas at 20
    // texels/m (about a thousand texels), 2 samples each, 2 bounces: seconds in all.
    job_.image =
        gi::ReferenceImageJob{.camera = {.camera_to_world = scene.registry.get<engine::WorldTransform>(camera).matrix,
                                         .yfov_rad = cam.yfov_rad,
                                         .aspect = cam.aspect},
                              .width = 24,
                              .height = 20};
    job_.atlas = gi::ReferenceAtlasJob{.texels_per_metre = 20.0f};
    job_.settings.samples_per_pixel = 2;
    job_.settings.max_bounces = 2;
    job_.settings.seed = 7;
    job_.settings.threads = 2;
    root_ = fs::path(GI_BINARY_DIR) / "test_output" / "distributed_reference" /
            ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::error_code ec;
    fs::remove_all(root_, ec);
    fs::create_directories(root_);
  }

  // Shards 0..count-1 into `dir`, each in its own call (as separate processes would).
  void shard_all(const fs::path& dir, std::uint32_t count, const gi::ReferenceJob& job) {
    for (std::uint32_t i = 0; i < count; ++i) {
      auto path = gi::reference_shard(input_, job, i, count, dir);
      ASSERT_TRUE(path.ok()) << path.error().to_string();
      EXPECT_EQ(*path, dir / gi::reference_shard_file_name(i, count));
    }
  }

  std::string merge_error(const fs::path& dir, std::uint32_t count = 0) {
    auto r = gi::merge_reference_shards(input_, job_, dir, count);
    return r.ok() ? std::string("(merged)") : r.error().to_string();
  }

  gi::BakeInput input_;
  gi::ReferenceJob job_;
  fs::path root_;
};

TEST_F(DistributedReference, MergedReferenceIsBitIdenticalToOneProcessForOneTwoAndSevenShards) {
  auto whole = gi::render_reference_job(input_, job_);
  ASSERT_TRUE(whole.ok()) << whole.error().to_string();
  ASSERT_TRUE(whole->atlas.has_value());
  std::size_t valid = 0;
  for (std::uint8_t v : whole->atlas->valid) valid += v;
  ASSERT_GT(valid, 7u * 64u) << "every one of 7 shards should get atlas texels";
  // The job's outputs are the public one-process functions' own.
  auto image = gi::render_reference_image(input_, job_.image->camera, 24, 20, job_.settings);
  auto atlas = gi::reference_atlas(input_, 20.0f, job_.settings);
  ASSERT_TRUE(image.ok() && atlas.ok());
  expect_identical(*whole, gi::ReferenceOutputs{.image = *image, .atlas = *atlas});

  for (std::uint32_t n : {1u, 2u, 7u}) {
    SCOPED_TRACE("N = " + std::to_string(n));
    const fs::path dir = root_ / ("n" + std::to_string(n));
    shard_all(dir, n, job_);
    auto merged = gi::merge_reference_shards(input_, job_, dir);
    ASSERT_TRUE(merged.ok()) << merged.error().to_string();
    expect_identical(*whole, *merged);
  }
  // Another thread count for the shards changes nothing either.
  gi::ReferenceJob one_thread = job_;
  one_thread.settings.threads = 1;
  shard_all(root_ / "t1", 2, one_thread);
  auto merged = gi::merge_reference_shards(input_, job_, root_ / "t1");
  ASSERT_TRUE(merged.ok()) << merged.error().to_string();
  expect_identical(*whole, *merged);
}

TEST_F(DistributedReference, AShardComputesOnlyItsBlocks) {
  // A shard's file holds a fraction of the work: 2 of 7 shards' files are far smaller than
  // one shard of 1 (its values are the blocks', not the whole image and atlas).
  shard_all(root_ / "n1", 1, job_);
  shard_all(root_ / "n7", 7, job_);
  const auto whole = fs::file_size(root_ / "n1" / gi::reference_shard_file_name(0, 1));
  const auto part = fs::file_size(root_ / "n7" / gi::reference_shard_file_name(3, 7));
  EXPECT_LT(part * 4, whole);
}

TEST_F(DistributedReference, MergeRefusesAMissingShardNamingIt) {
  shard_all(root_ / "s", 3, job_);
  fs::remove(root_ / "s" / gi::reference_shard_file_name(1, 3));
  const std::string e = merge_error(root_ / "s");
  EXPECT_NE(e.find("shard-0001-of-0003.girefshard"), std::string::npos) << e;
  EXPECT_NE(e.find("shard 1 of 3 is missing"), std::string::npos) << e;
  // N given by the caller: the last shard missing is found too.
  shard_all(root_ / "t", 2, job_);
  fs::remove(root_ / "t" / gi::reference_shard_file_name(1, 2));
  EXPECT_NE(merge_error(root_ / "t", 2).find("shard 1 of 2 is missing"), std::string::npos);
  EXPECT_NE(merge_error(root_ / "empty").find("cannot list"), std::string::npos);
}

TEST_F(DistributedReference, MergeRefusesADuplicatedShardNamingBothFiles) {
  shard_all(root_ / "s", 2, job_);
  fs::copy_file(root_ / "s" / gi::reference_shard_file_name(0, 2), root_ / "s" / "copy-of-0.girefshard");
  const std::string e = merge_error(root_ / "s");
  EXPECT_NE(e.find("duplicate shard 0 of 2"), std::string::npos) << e;
  EXPECT_NE(e.find("copy-of-0.girefshard"), std::string::npos) << e;
}

TEST_F(DistributedReference, MergeRefusesADamagedOrTruncatedShardNamingIt) {
  shard_all(root_ / "s", 2, job_);
  const fs::path p = root_ / "s" / gi::reference_shard_file_name(1, 2);
  const std::vector<char> good = file_bytes(p);
  std::vector<char> bad = good;
  bad[bad.size() / 2] = static_cast<char>(bad[bad.size() / 2] ^ 0x10);
  write_bytes(p, bad);
  std::string e = merge_error(root_ / "s");
  EXPECT_NE(e.find("shard-0001-of-0002.girefshard"), std::string::npos) << e;
  EXPECT_NE(e.find("checksum"), std::string::npos) << e;
  write_bytes(p, std::vector<char>(good.begin(), good.end() - 5));
  e = merge_error(root_ / "s");
  EXPECT_NE(e.find("shard-0001-of-0002.girefshard"), std::string::npos) << e;
  EXPECT_NE(e.find("trunc"), std::string::npos) << e;
  write_bytes(p, good);
  EXPECT_EQ(merge_error(root_ / "s"), "(merged)");
}

TEST_F(DistributedReference, MergeRefusesForeignShardsNamingThem) {
  // Another seed.
  {
    shard_all(root_ / "seed", 2, job_);
    gi::ReferenceJob other = job_;
    other.settings.seed = 8;
    shard_all(root_ / "seed_other", 2, other);
    fs::copy_file(root_ / "seed_other" / gi::reference_shard_file_name(1, 2),
                  root_ / "seed" / gi::reference_shard_file_name(1, 2), fs::copy_options::overwrite_existing);
    const std::string e = merge_error(root_ / "seed");
    EXPECT_NE(e.find("shard-0001-of-0002.girefshard"), std::string::npos) << e;
    EXPECT_NE(e.find("foreign shard: traced with other settings"), std::string::npos) << e;
  }
  // Other samples per texel.
  {
    gi::ReferenceJob other = job_;
    other.settings.samples_per_pixel = 3;
    shard_all(root_ / "spp", 2, other);
    EXPECT_NE(merge_error(root_ / "spp").find("foreign shard: traced with other settings"), std::string::npos);
  }
  // Another N.
  {
    shard_all(root_ / "n", 2, job_);
    shard_all(root_ / "n3", 3, job_);
    fs::copy_file(root_ / "n3" / gi::reference_shard_file_name(2, 3),
                  root_ / "n" / gi::reference_shard_file_name(2, 3));
    const std::string e = merge_error(root_ / "n");
    EXPECT_NE(e.find("foreign shard: shard 2 of 3, the merge is of 2"), std::string::npos) << e;
  }
  // Another scene: a light twice as bright.
  {
    gi::BakeInput brighter = input_;
    ASSERT_FALSE(brighter.lights.empty());
    brighter.lights[0].light.intensity *= 2.0f;
    for (std::uint32_t i = 0; i < 2; ++i) ASSERT_TRUE(gi::reference_shard(brighter, job_, i, 2, root_ / "scene").ok());
    const std::string e = merge_error(root_ / "scene");
    EXPECT_NE(e.find("foreign shard: traced in another scene"), std::string::npos) << e;
  }
  // Other parts: an atlas-only job's shards for an image + atlas merge.
  {
    gi::ReferenceJob atlas_only = job_;
    atlas_only.image.reset();
    shard_all(root_ / "parts", 2, atlas_only);
    EXPECT_NE(merge_error(root_ / "parts").find("foreign shard: traced with other settings"), std::string::npos);
  }
}

TEST_F(DistributedReference, BadRequestsAreRefused) {
  EXPECT_FALSE(gi::reference_shard(input_, job_, 2, 2, root_ / "x").ok());
  EXPECT_FALSE(gi::reference_shard(input_, job_, 0, 0, root_ / "x").ok());
  gi::ReferenceJob nothing = job_;
  nothing.image.reset();
  nothing.atlas.reset();
  EXPECT_FALSE(gi::reference_shard(input_, nothing, 0, 1, root_ / "x").ok());
  EXPECT_FALSE(gi::render_reference_job(input_, nothing).ok());
  EXPECT_FALSE(fs::exists(root_ / "x"));
  EXPECT_NE(merge_error(root_).find("no shard file"), std::string::npos);
}

}  // namespace
