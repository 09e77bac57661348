// Saving an antiradiance bake into a bundle and loading it back: the same region, and
// truncated, damaged, stale and inconsistent files rejected with messages naming the file.
#include "antiradiance/antiradiance_io.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include "antiradiance_scenes.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "antiradiance_io_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

gi::AntiradianceSettings small() {
  gi::AntiradianceSettings s;
  s.patch_size_m = 0.5f;
  s.bins_per_side = 6;
  s.iterations = 4;
  return s;
}

std::vector<char> read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_all(const fs::path& p, const std::vector<char>& b) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

TEST(AntiradianceIo, ABakeSavedAndLoadedGivesTheSameRegion) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  auto bake = gi::bake_antiradiance(scene.input, small());
  ASSERT_TRUE(bake) << bake.error().to_string();
  const fs::path dir = scratch_dir("roundtrip");
  ASSERT_TRUE(gi::save_antiradiance(dir, *bake, scene.input));
  auto loaded = gi::load_antiradiance(dir, scene.input);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  EXPECT_EQ(loaded->hierarchy.nodes.size(), bake->hierarchy.nodes.size());
  EXPECT_EQ(loaded->static_links.links.size(), bake->static_links.links.size());
  EXPECT_EQ(loaded->static_links.offsets, bake->static_links.offsets);
  // The links come back bit for bit from their compressed planes.
  for (std::size_t k = 0; k < bake->static_links.links.size() && k < loaded->static_links.links.size(); ++k) {
    const gi::Link& a = bake->static_links.links[k];
    const gi::Link& b = loaded->static_links.links[k];
    ASSERT_TRUE(a.receiver == b.receiver && a.sender == b.sender && a.bin == b.bin && a.form_factor == b.form_factor)
        << "link " << k;
  }
  // And take well under the 16 bytes of a link record (measured ~4.5 bytes per link here).
  const double bytes_per_link = static_cast<double>(fs::file_size(dir / gi::kAntiradianceFile)) /
                                static_cast<double>(bake->static_links.links.size());
  std::printf("antiradiance.bin: %.2f bytes per static link (%zu links)\n", bytes_per_link,
              bake->static_links.links.size());
  EXPECT_LT(bytes_per_link, 8.0);
  EXPECT_EQ(loaded->baseline, bake->baseline);
  auto fresh = gi::AntiradianceRegion::create(scene.input, std::move(bake).value());
  auto from_file = gi::AntiradianceRegion::create(scene.input, std::move(loaded).value());
  ASSERT_TRUE(fresh && from_file);
  fresh->update();
  from_file->update();
  EXPECT_EQ(fresh->irradiance(), from_file->irradiance());
  EXPECT_EQ(fresh->links().links.size(), from_file->links().links.size());
}

TEST(AntiradianceIo, StaleDamagedAndTruncatedFilesAreRejectedByName) {
  const artest::DoorScene scene = artest::door_scene(0.0f);
  auto bake = gi::bake_antiradiance(scene.input, small());
  ASSERT_TRUE(bake);
  const fs::path dir = scratch_dir("damaged");
  ASSERT_TRUE(gi::save_antiradiance(dir, *bake, scene.input));
  const fs::path file = dir / gi::kAntiradianceFile;
  const std::vector<char> good = read_all(file);

  // Stale: the receiver moved 1 cm.
  gi::BakeInput moved = scene.input;
  moved.instances[scene.receiver].object_to_world[3].x += 0.01f;
  auto stale = gi::load_antiradiance(dir, moved);
  ASSERT_FALSE(stale);
  EXPECT_TRUE(contains(stale.error().to_string(), "stale")) << stale.error().to_string();

  // A flipped bit: the manifest's checksum no longer matches.
  std::vector<char> flipped = good;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x10);
  write_all(file, flipped);
  auto damaged = gi::load_antiradiance(dir, scene.input);
  ASSERT_FALSE(damaged);
  EXPECT_TRUE(contains(damaged.error().to_string(), gi::kAntiradianceFile)) << damaged.error().to_string();
  // The same file read directly: the container's own checksum fails.
  auto direct = gi::read_antiradiance(file);
  ASSERT_FALSE(direct);
  EXPECT_TRUE(contains(direct.error().to_string(), gi::kAntiradianceFile)) << direct.error().to_string();

  // Truncated.
  write_all(file, std::vector<char>(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(good.size() / 3)));
  auto truncated = gi::read_antiradiance(file);
  ASSERT_FALSE(truncated);
  EXPECT_TRUE(contains(truncated.error().to_string(), gi::kAntiradianceFile)) << truncated.error().to_string();
  write_all(file, good);
  ASSERT_TRUE(gi::read_antiradiance(file));
}

// Inconsistent content inside a valid container (written through write_blob with a correct
// checksum): the reader's own checks name the problem.
TEST(AntiradianceIo, InconsistentBakesAreRefusedBeforeWritingAndForeignScenesOnLoad) {
  const artest::DoorScene scene = artest::door_scene(0.0f);
  auto bake = gi::bake_antiradiance(scene.input, small());
  ASSERT_TRUE(bake);
  const fs::path dir = scratch_dir("inconsistent");
  fs::create_directories(dir);
  gi::AntiradianceBake bad = *bake;
  bad.static_links.links[0].sender = static_cast<std::int32_t>(bad.hierarchy.nodes.size());
  auto st = gi::write_antiradiance(dir / "a.bin", bad, "h");
  ASSERT_FALSE(st);
  EXPECT_TRUE(contains(st.error().to_string(), "static link 0")) << st.error().to_string();
  EXPECT_FALSE(fs::exists(dir / "a.bin"));
  bad = *bake;
  bad.baseline.pop_back();
  EXPECT_FALSE(gi::write_antiradiance(dir / "b.bin", bad, "h"));
  bad = *bake;
  bad.hierarchy.nodes[3].center.x = std::nanf("");
  EXPECT_FALSE(gi::write_antiradiance(dir / "c.bin", bad, "h"));
  // A region whose deforming instances are not the scene's.
  gi::BakeInput other = scene.input;
  other.instances[scene.door].deforming = false;
  other.instances[scene.receiver].deforming = true;
  auto region = gi::AntiradianceRegion::create(other, *bake);
  ASSERT_FALSE(region);
  EXPECT_TRUE(contains(region.error().to_string(), "deforming")) << region.error().to_string();
}

}  // namespace
