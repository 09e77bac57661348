// Saving a light-atlas bake into a bundle and loading it back: bit-exact round trip, stale
// bundles and damaged files rejected with messages naming the file.
#include "light_atlas/light_atlas_io.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/image.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>

#include "bundle/bundle.h"
#include "io/content_hash.h"
#include "light_atlas/light_atlas_vpl_file.h"
#include "uv/atlas_input.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "light_atlas_io_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

engine::SceneAsset cornell() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/cornell_box.gltf");
  EXPECT_TRUE(asset.ok()) << asset.error().to_string();
  return std::move(asset).value();
}

// A bake made by hand: the real layout, a deterministic irradiance pattern, three VPLs.
gi::LightAtlasBake fake_bake(const engine::SceneAsset& asset) {
  gi::LightAtlasBake b;
  auto layout = gi::build_atlas_layout(gi::atlas_inputs_from(gi::bake_input_from(asset)), {.texels_per_metre = 4.0f});
  EXPECT_TRUE(layout.ok()) << layout.error().to_string();
  b.layout = std::move(layout).value();
  b.width = b.layout.width;
  b.height = b.layout.height;
  const std::size_t n = static_cast<std::size_t>(b.width) * static_cast<std::size_t>(b.height);
  for (std::size_t i = 0; i < n; ++i) {
    const float f = static_cast<float>(i);
    b.irradiance.emplace_back(1.0f / (f + 3.0f), 0.37f * f, 1e5f + f * 1.1f);  // beyond half-float range
    b.valid.push_back(i % 3 == 0 ? 1 : 0);
  }
  b.settings.texels_per_metre = 4.0f;
  b.settings.vpl_count = 3;
  b.settings.samples_per_vpl = 2;
  b.settings.bounces = 4;
  b.settings.unshot_threshold = 3e-5f;
  b.settings.area_light_samples = 17;
  b.settings.include_direct = true;
  b.settings.seed = 0xfedcba9876543210ull;
  b.settings.threads = 2;
  b.stats = {.vpls = 3,
             .sample_points = 5,
             .light_points = 17,
             .shots = 9,
             .valid_texels = n / 3 + 1,
             .rays = 1ull << 40,
             .vpl_seconds = 0.125,
             .direct_seconds = 1.0 / 3.0,
             .propagate_seconds = 2.5,
             .final_seconds = 1e-3,
             .total_seconds = 4.2};
  gi::VplSet& v = b.vpls;
  v.position = {{0.1f, 0.2f, 0.3f}, {-1.0f, 0.5f, 2.0f}, {0.0f, 0.0f, 1.0f / 3.0f}};
  v.normal = {{0, 1, 0}, {1, 0, 0}, {0, 0, -1}};
  v.albedo = {{0.8f, 0.7f, 0.6f}, {0.5f, 0.04f, 0.04f}, {0.1f, 0.4f, 0.07f}};
  v.area_m2 = {0.25f, 0.5f, 1.0f / 7.0f};
  v.sample_first = {0, 2, 3, 5};
  v.sample_position = {{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}, {4, 4, 4}};
  v.sample_normal = {{0, 1, 0}, {0, 1, 0}, {1, 0, 0}, {0, 0, -1}, {0, 0, -1}};
  v.sample_area_m2 = {0.1f, 0.15f, 0.5f, 0.07f, 1.0f / 14.0f};
  b.vpl_power = {{1.0f, 2.0f, 3.0f}, {0.5f, 0.25f, 0.125f}, {1e-7f, 0.0f, 7.0f}};
  return b;
}

// A saved bundle of fake_bake(cornell()).
fs::path saved_bundle(const std::string& name) {
  const fs::path dir = scratch_dir(name);
  const engine::SceneAsset asset = cornell();
  const engine::Status s = gi::save_light_atlas(dir, fake_bake(asset), gi::bake_input_from(asset));
  EXPECT_TRUE(s.ok()) << s.error().to_string();
  return dir;
}

void expect_load_error(const fs::path& dir, const std::string& file, const std::string& what) {
  auto r = gi::load_light_atlas(dir, gi::bake_input_from(cornell()));
  ASSERT_FALSE(r.ok()) << "a bad bundle loaded (" << what << ")";
  std::printf("rejected as expected: %s\n", r.error().to_string().c_str());
  EXPECT_NE(r.error().to_string().find(file), std::string::npos) << r.error().to_string();
  EXPECT_NE(r.error().to_string().find(what), std::string::npos) << r.error().to_string();
}

template <class T>
void expect_bits_equal(const std::vector<T>& a, const std::vector<T>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size() * sizeof(T)), 0) << what;
}

}  // namespace

TEST(LightAtlasIo, RoundTripIsBitExact) {
  const engine::SceneAsset asset = cornell();
  const gi::LightAtlasBake bake = fake_bake(asset);
  const fs::path dir = saved_bundle("round_trip");
  EXPECT_TRUE(fs::exists(dir / "light_atlas.exr"));
  EXPECT_TRUE(fs::exists(dir / "light_atlas_vpls.bin"));
  EXPECT_TRUE(fs::exists(dir / "manifest.json"));

  auto back = gi::load_light_atlas(dir, gi::bake_input_from(asset));
  ASSERT_TRUE(back.ok()) << back.error().to_string();
  EXPECT_EQ(back->width, bake.width);
  EXPECT_EQ(back->height, bake.height);
  EXPECT_EQ(back->layout.requested_texels_per_metre, 4.0f);
  EXPECT_EQ(back->layout.charts.size(), bake.layout.charts.size());
  expect_bits_equal(back->irradiance, bake.irradiance, "irradiance");
  expect_bits_equal(back->valid, bake.valid, "valid");
  const gi::VplSet &a = back->vpls, &b = bake.vpls;
  expect_bits_equal(a.position, b.position, "position");
  expect_bits_equal(a.normal, b.normal, "normal");
  expect_bits_equal(a.albedo, b.albedo, "albedo");
  expect_bits_equal(a.area_m2, b.area_m2, "area_m2");
  expect_bits_equal(a.sample_first, b.sample_first, "sample_first");
  expect_bits_equal(a.sample_position, b.sample_position, "sample_position");
  expect_bits_equal(a.sample_normal, b.sample_normal, "sample_normal");
  expect_bits_equal(a.sample_area_m2, b.sample_area_m2, "sample_area_m2");
  expect_bits_equal(back->vpl_power, bake.vpl_power, "vpl_power");

  const gi::LightAtlasSettings &s = back->settings, &t = bake.settings;
  EXPECT_EQ(s.texels_per_metre, t.texels_per_metre);
  EXPECT_EQ(s.vpl_count, t.vpl_count);
  EXPECT_EQ(s.samples_per_vpl, t.samples_per_vpl);
  EXPECT_EQ(s.bounces, t.bounces);
  EXPECT_EQ(s.unshot_threshold, t.unshot_threshold);
  EXPECT_EQ(s.area_light_samples, t.area_light_samples);
  EXPECT_EQ(s.include_direct, t.include_direct);
  EXPECT_EQ(s.seed, t.seed);
  EXPECT_EQ(s.threads, 0u) << "the thread count is not part of a bundle (bake_stats.json holds it)";

  const gi::LightAtlasStats &x = back->stats, &y = bake.stats;
  EXPECT_EQ(x.vpls, y.vpls);
  EXPECT_EQ(x.sample_points, y.sample_points);
  EXPECT_EQ(x.light_points, y.light_points);
  EXPECT_EQ(x.shots, y.shots);
  EXPECT_EQ(x.valid_texels, y.valid_texels);
  EXPECT_EQ(x.rays, y.rays);
  // Timings are not part of a bundle (bake_stats.json holds them): a load reads none.
  EXPECT_EQ(x.total_seconds, 0.0);
  EXPECT_NE(y.total_seconds, 0.0);

  auto manifest = gi::read_manifest(dir);
  ASSERT_TRUE(manifest.ok()) << manifest.error().to_string();
  EXPECT_EQ(manifest->scene, "cornell_box.gltf");
  EXPECT_EQ(manifest->methods["light_atlas"]["layout"]["width"], bake.width);
  EXPECT_EQ(manifest->methods["light_atlas"]["settings"]["seed"], bake.settings.seed);
}

TEST(LightAtlasIo, StaleBundleIsRejectedWithBothHashes) {
  const fs::path dir = saved_bundle("stale");
  engine::SceneAsset changed = cornell();
  changed.meshes[1].primitives[0].positions[0].x += 0.02f;
  auto r = gi::load_light_atlas(dir, gi::bake_input_from(changed));
  ASSERT_FALSE(r.ok());
  const std::string message = r.error().to_string();
  EXPECT_NE(message.find("stale"), std::string::npos) << message;
  EXPECT_NE(message.find(gi::scene_geometry_hash(gi::bake_input_from(cornell()))), std::string::npos) << message;
  EXPECT_NE(message.find(gi::scene_geometry_hash(gi::bake_input_from(changed))), std::string::npos) << message;
  EXPECT_NE(message.find("manifest.json"), std::string::npos) << message;
}

TEST(LightAtlasIo, AtlasBakedUnderOtherStaticLightsIsRejected) {
  const fs::path dir = saved_bundle("stale_lights");
  engine::SceneAsset relit = cornell();
  ASSERT_FALSE(relit.lights.empty());
  relit.lights[0].light.intensity *= 1.5f;
  auto r = gi::load_light_atlas(dir, gi::bake_input_from(relit));
  ASSERT_FALSE(r.ok());
  const std::string message = r.error().to_string();
  EXPECT_NE(message.find("stale light atlas"), std::string::npos) << message;
  EXPECT_NE(message.find(gi::static_lights_hash(gi::bake_input_from(cornell()))), std::string::npos) << message;
  EXPECT_NE(message.find(gi::static_lights_hash(gi::bake_input_from(relit))), std::string::npos) << message;
  // The same bundle still loads for the scene it was baked from.
  EXPECT_TRUE(gi::load_light_atlas(dir, gi::bake_input_from(cornell())).ok());
}

TEST(LightAtlasIo, MissingOrDamagedFilesAreRejected) {
  {
    const fs::path dir = saved_bundle("missing_vpls");
    fs::remove(dir / "light_atlas_vpls.bin");
    expect_load_error(dir, "light_atlas_vpls.bin", "not found");
  }
  {
    const fs::path dir = saved_bundle("corrupt_exr");
    std::fstream f(dir / "light_atlas.exr", std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(fs::file_size(dir / "light_atlas.exr") / 2));
    f.put('\x5a');
    f.close();
    expect_load_error(dir, "light_atlas.exr", "checksum mismatch");
  }
  {
    const fs::path dir = saved_bundle("no_manifest");
    fs::remove(dir / "manifest.json");
    expect_load_error(dir, "manifest.json", "not found");
  }
  {
    const fs::path dir = saved_bundle("no_entry");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods.erase("light_atlas");
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "no \"light_atlas\" entry");
  }
  {
    const fs::path dir = saved_bundle("missing_field");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods["light_atlas"]["layout"].erase("padding_texels");
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "methods.light_atlas.layout.padding_texels: missing field");
  }
  {
    const fs::path dir = saved_bundle("escaping_name");
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    m->methods["light_atlas"]["files"]["vpls"]["file"] = "../other.bin";
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
    expect_load_error(dir, "manifest.json", "not a file name inside the bundle");
  }
}

// A bundle whose files are internally consistent (checksums updated) but whose EXR content
// is wrong: the checks behind the checksum still hold.
TEST(LightAtlasIo, WrongSizeOrInvalidTexelsInTheExrAreRejected) {
  const auto rewrite_exr = [](const fs::path& dir, const engine::ImageRgbaF& image) {
    ASSERT_TRUE(engine::save_exr(dir / "light_atlas.exr", image, engine::ExrPixelType::Float).ok());
    auto m = gi::read_manifest(dir);
    ASSERT_TRUE(m.ok());
    const auto bytes = gi::read_file_bytes(dir / "light_atlas.exr").value();
    gi::ContentHash h;
    h.add_bytes(bytes.data(), bytes.size());
    m->methods["light_atlas"]["files"]["irradiance"]["xxh3_64"] = h.hex();
    ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
  };
  const gi::LightAtlasBake bake = fake_bake(cornell());
  {
    const fs::path dir = saved_bundle("wrong_size");
    rewrite_exr(dir,
                engine::ImageRgbaF{bake.width + 1, bake.height,
                                   std::vector<float>(static_cast<std::size_t>((bake.width + 1) * bake.height) * 4)});
    expect_load_error(dir, "light_atlas.exr", "size mismatch");
  }
  auto good = engine::load_exr(saved_bundle("read_good") / "light_atlas.exr");
  ASSERT_TRUE(good.ok());
  const std::size_t texel = static_cast<std::size_t>(2 * bake.width + 5);
  const std::string where = "texel (5, 2)";
  const std::pair<int, float> cases[] = {
      {1, std::numeric_limits<float>::quiet_NaN()}, {0, std::numeric_limits<float>::infinity()}, {2, -0.5f}, {3, 0.5f}};
  const char* const what[] = {"NaN or infinite", "NaN or infinite", "negative", "alpha"};
  for (std::size_t c = 0; c < 4; ++c) {
    const fs::path dir = saved_bundle("bad_value_" + std::to_string(c));
    engine::ImageRgbaF image = good.value();
    image.pixels[4 * texel + static_cast<std::size_t>(cases[c].first)] = cases[c].second;
    rewrite_exr(dir, image);
    expect_load_error(dir, where, what[c]);
  }
}

TEST(LightAtlasIo, VplFileMustMatchTheManifestsGeometry) {
  const fs::path dir = saved_bundle("vpl_geometry");
  const engine::SceneAsset asset = cornell();
  const gi::LightAtlasBake bake = fake_bake(asset);
  ASSERT_TRUE(gi::write_light_atlas_vpls(dir / "light_atlas_vpls.bin", bake, "0123456789abcdef").ok());
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok());
  const auto bytes = gi::read_file_bytes(dir / "light_atlas_vpls.bin").value();
  gi::ContentHash h;
  h.add_bytes(bytes.data(), bytes.size());
  m->methods["light_atlas"]["files"]["vpls"]["xxh3_64"] = h.hex();
  ASSERT_TRUE(gi::write_manifest(dir, *m).ok());
  expect_load_error(dir, "light_atlas_vpls.bin", "0123456789abcdef");
}

TEST(LightAtlasIo, InconsistentVplsAreNotSaved) {
  const engine::SceneAsset asset = cornell();
  gi::LightAtlasBake bake = fake_bake(asset);
  bake.vpls.sample_first = {0, 2, 1, 5};
  const fs::path dir = scratch_dir("bad_vpls");
  const engine::Status s = gi::save_light_atlas(dir, bake, gi::bake_input_from(asset));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().to_string().find("sample_first"), std::string::npos) << s.error().to_string();
  EXPECT_TRUE(!fs::exists(dir) || fs::is_empty(dir)) << "a failed save writes nothing";
}
