// The frame-vs-truth instrument (gi/frame_truth.h): the bench's pixels split into regions,
// "other" and background and nothing else, its comparisons repeatable, its bad input refused.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <gi/frame_truth.h>

namespace {

engine::SceneAsset cornell_box() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset) << asset.error().to_string();
  return std::move(asset).value();
}

// The Cornell box's own camera, as a FrameCamera: at (0.278, 0.273, -0.8) looking +Z.
const gi::FrameCamera kCornellCamera{
    .name = "front", .position_m = {0.278f, 0.273f, -0.8f}, .target_m = {0.278f, 0.273f, 0.0f}, .yfov_rad = 0.686f};

}  // namespace

TEST(FrameTruthBench, PixelsSplitIntoRegionsOtherAndBackgroundAndRepeatedComparisonsAgree) {
  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  // The left (green) wall at x = 0 and the floor: two regions; the rest of the box is "other".
  gi::FrameTruthSettings s{.width = 32, .height = 24, .samples_per_pixel = 4, .threads = 2};
  s.regions = {{"left wall", {-0.1f, -0.1f, -0.1f}, {0.1f, 0.6f, 0.6f}},
               {"floor", {-0.1f, -0.1f, -0.1f}, {0.6f, 0.1f, 0.6f}}};
  auto bench = gi::FrameTruthBench::create(cornell_box(), "", s);
  ASSERT_TRUE(bench) << bench.error().to_string();
  EXPECT_EQ((*bench)->gi_label(), "constant ambient (stand-in)");
  auto a = (*bench)->compare(kCornellCamera);
  ASSERT_TRUE(a) << a.error().to_string();
  ASSERT_EQ(a->regions.size(), 3u);
  EXPECT_EQ(a->regions[0].name, "left wall");
  EXPECT_EQ(a->regions[2].name, "other");
  EXPECT_EQ(a->overall.name, "frame");
  EXPECT_EQ(a->frame.width, 32);
  EXPECT_EQ(a->truth.height, 24);
  std::size_t in_regions = 0;
  for (const gi::RegionAccuracy& r : a->regions) {
    EXPECT_GT(r.pixels, 0u) << r.name << ": the box's own camera sees the left wall, the floor and more";
    in_regions += r.pixels;
  }
  EXPECT_EQ(in_regions, a->overall.pixels);
  EXPECT_EQ(a->overall.pixels + a->background_pixels + a->nonfinite_pixels, 32u * 24u);
  std::size_t counted[4] = {0, 0, 0, 0};
  for (std::uint8_t r : a->region_of_pixel) ++counted[r == gi::kBackgroundPixel ? 3 : r];
  EXPECT_EQ(counted[0], a->regions[0].pixels);
  EXPECT_EQ(counted[3], a->background_pixels);
  EXPECT_GT(a->cost.frame_ms, 0.0);
  EXPECT_FALSE(a->cost.frame.empty());

  auto b = (*bench)->compare(kCornellCamera);
  ASSERT_TRUE(b) << b.error().to_string();
  EXPECT_EQ(a->truth.pixels, b->truth.pixels) << "the truth is deterministic";
  EXPECT_EQ(a->frame.pixels, b->frame.pixels) << "so is the still frame";
  EXPECT_EQ(a->overall.bias, b->overall.bias);
  const engine::ImageRgba8 ratio = gi::ratio_image(*a);
  EXPECT_EQ(ratio.pixels.size(), 4u * 32u * 24u);
}

TEST(FrameTruthBench, RefusesBadSettingsAndDegenerateCameras) {
  auto gpu = engine::GpuContext::create_headless();
  ASSERT_TRUE(gpu) << gpu.error().to_string();
  gi::FrameTruthSettings one_sample{.width = 8, .height = 8, .samples_per_pixel = 1};
  auto b1 = gi::FrameTruthBench::create(cornell_box(), "", one_sample);
  ASSERT_FALSE(b1);
  EXPECT_EQ(b1.error().kind, engine::ErrorKind::Invalid);
  gi::FrameTruthSettings named_other{.width = 8, .height = 8, .samples_per_pixel = 2};
  named_other.regions = {{"other", glm::vec3(0.0f), glm::vec3(1.0f)}};
  EXPECT_FALSE(gi::FrameTruthBench::create(cornell_box(), "", named_other));
  gi::FrameTruthSettings inverted{.width = 8, .height = 8, .samples_per_pixel = 2};
  inverted.regions = {{"box", glm::vec3(1.0f), glm::vec3(0.0f)}};
  EXPECT_FALSE(gi::FrameTruthBench::create(cornell_box(), "", inverted));

  auto bench = gi::FrameTruthBench::create(cornell_box(), "", {.width = 8, .height = 8, .samples_per_pixel = 2});
  ASSERT_TRUE(bench) << bench.error().to_string();
  auto r = (*bench)->compare({.name = "nowhere", .position_m = glm::vec3(1.0f), .target_m = glm::vec3(1.0f)});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().kind, engine::ErrorKind::Invalid);
}

TEST(FrameTruth, WithoutTexturesKeepsTheFactorsAndDropsEveryTexture) {
  engine::SceneAsset a;
  engine::Material m;
  m.base_color = {0.5f, 0.4f, 0.3f, 1.0f};
  m.base_color_texture.image = 0;
  m.metallic_roughness_texture.image = 1;
  m.emissive_texture.image = 2;
  m.normal_texture.image = 3;
  a.materials.push_back(m);
  const engine::SceneAsset b = gi::without_textures(a);
  EXPECT_EQ(b.materials[0].base_color, m.base_color);
  EXPECT_EQ(b.materials[0].base_color_texture.image, -1);
  EXPECT_EQ(b.materials[0].metallic_roughness_texture.image, -1);
  EXPECT_EQ(b.materials[0].emissive_texture.image, -1);
  EXPECT_EQ(b.materials[0].normal_texture.image, -1);
}
