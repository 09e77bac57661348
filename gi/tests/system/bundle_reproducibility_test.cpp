// Reproducible bundles (issue 20, docs/reliability.md): the same scene, options and seed give
// byte-identical bundle files whatever the thread count or the run — every method (light
// atlas EXR + VPLs, PRM panes, directional light maps, basis radiance fields, antiradiance),
// the manifest included. Only bake_stats.json differs, and it says how (threads, timings).
// The world probes GISystem builds from the atlas at load time are compared too.
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <gi/bake.h>
#include <gi/bake_input.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>
#include <nlohmann/json.hpp>

#include "brf/world_probes.h"
#include "light_atlas/light_atlas_io.h"
#include "transport/static_scene.h"

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

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
}

// The demo level with every method at small settings: all five bake files in about a minute.
engine::Result<gi::BakeReport> bake(const gi::BakeInput& input, const fs::path& dir, unsigned threads) {
  std::error_code ec;
  fs::remove_all(dir, ec);
  return gi::bake_bundle(input, dir,
                         {.preset = "preview",
                          .methods = {"light_atlas", "prm", "dlm", "brf", "antiradiance"},
                          .texels_per_metre = 4.0f,
                          .brf_basis = 8,
                          .brf_spheres = 4,
                          .dlm_photons = 20000,
                          .threads = threads,
                          .seed = 7});
}

TEST(BundleReproducibility, OneAndTwoThreadsGiveByteIdenticalFilesAndWorldProbes) {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/demo_level.gltf");
  ASSERT_TRUE(asset.ok()) << asset.error().to_string();
  const gi::BakeInput input = gi::bake_input_from(*asset);
  const fs::path root = fs::path(GI_BINARY_DIR) / "test_output" / "bundle_reproducibility";
  fs::create_directories(root);
  const fs::path one = root / "one_thread.gibake", two = root / "two_threads.gibake";
  auto a = bake(input, one, 1);
  ASSERT_TRUE(a.ok()) << a.error().to_string();
  auto b = bake(input, two, 2);
  ASSERT_TRUE(b.ok()) << b.error().to_string();

  const auto fa = bundle_files(one), fb = bundle_files(two);
  std::vector<std::string> names_a, names_b;
  for (const auto& [name, bytes] : fa) names_a.push_back(name);
  for (const auto& [name, bytes] : fb) names_b.push_back(name);
  ASSERT_EQ(names_a, names_b);
  // Every method wrote its files (a method that silently wrote nothing would compare equal).
  for (const char* expected : {"manifest.json", "light_atlas.exr", "light_atlas_vpls.bin", "light_atlas_layout.bin",
                               "prm_panes.bin", "prm_layout.bin", "dlm.bin", "dlm_layout.bin", "antiradiance.bin",
                               "antiradiance_at_pose.bin", "brf_crate.bin", gi::kBakeStatsFileName})
    EXPECT_TRUE(fa.contains(expected)) << expected << " missing from the bundle";
  std::size_t compared = 0;
  for (const auto& [name, bytes] : fa) {
    if (name == gi::kBakeStatsFileName) continue;
    const std::vector<char>& other = fb.at(name);
    ASSERT_EQ(bytes.size(), other.size()) << name << " differs in size between 1 and 2 threads";
    const auto mismatch = std::mismatch(bytes.begin(), bytes.end(), other.begin());
    EXPECT_TRUE(mismatch.first == bytes.end())
        << name << " differs at byte " << (mismatch.first - bytes.begin()) << " between 1 and 2 threads";
    ++compared;
  }
  std::printf("%zu files byte-identical between 1 and 2 threads\n", compared);

  // What differs is in bake_stats.json, per method.
  const nlohmann::json sa = read_json(one / gi::kBakeStatsFileName), sb = read_json(two / gi::kBakeStatsFileName);
  ASSERT_TRUE(sa.is_object() && sb.is_object());
  for (const char* method : {"light_atlas", "prm", "dlm", "brf", "antiradiance"}) {
    ASSERT_TRUE(sa["methods"].contains(method)) << method;
    EXPECT_EQ(sa["methods"][method]["threads"], 1) << method;
    EXPECT_EQ(sb["methods"][method]["threads"], 2) << method;
    EXPECT_GT(sa["methods"][method]["seconds"].get<double>(), 0.0) << method;
  }
  // The manifest's method entries carry no thread count and no timing (the plan's
  // estimates are a deterministic model, not measurements).
  const std::string entries = read_json(one / "manifest.json")["methods"].dump();
  EXPECT_EQ(entries.find("threads"), std::string::npos);
  EXPECT_EQ(entries.find("seconds"), std::string::npos);

  // The world probes GISystem builds from the atlas's VPLs at load: same bits for 1 and 2 threads.
  auto atlas = gi::load_light_atlas(one, input);
  ASSERT_TRUE(atlas.ok()) << atlas.error().to_string();
  auto caster = gi::make_static_caster(input);
  ASSERT_TRUE(caster.ok()) << caster.error().to_string();
  auto p1 = gi::bake_world_probes(**caster, atlas->vpls, atlas->vpl_power, {.spacing_m = 1.0f, .threads = 1});
  auto p2 = gi::bake_world_probes(**caster, atlas->vpls, atlas->vpl_power, {.spacing_m = 1.0f, .threads = 2});
  ASSERT_TRUE(p1.ok() && p2.ok());
  ASSERT_GT(p1->probe_count(), 0u);
  ASSERT_EQ(p1->radiance_sh.size(), p2->radiance_sh.size());
  EXPECT_EQ(
      std::memcmp(p1->radiance_sh.data(), p2->radiance_sh.data(), p1->radiance_sh.size() * sizeof(p1->radiance_sh[0])),
      0);
  EXPECT_EQ(p1->valid, p2->valid);
}

}  // namespace
