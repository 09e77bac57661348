// Saving an antiradiance bake into a bundle and loading it back: the same region, and
// truncated, damaged, stale and inconsistent files rejected with messages naming the file.
#include "antiradiance/antiradiance_io.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "antiradiance_scenes.h"
#include "bundle/atlas_layout_file.h"
#include "io/blob_file.h"
#include "uv/atlas_layout.h"

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

namespace {

bool same_links(const gi::LinkMesh& a, const gi::LinkMesh& b) {
  if (a.links.size() != b.links.size() || a.offsets != b.offsets || a.relinked_elements != b.relinked_elements ||
      a.links_made != b.links_made)
    return false;
  for (std::size_t k = 0; k < a.links.size(); ++k) {
    const gi::Link &x = a.links[k], &y = b.links[k];
    if (x.receiver != y.receiver || x.sender != y.sender || x.bin != y.bin ||
        std::memcmp(&x.form_factor, &y.form_factor, 4) != 0)
      return false;
  }
  return true;
}

bool same_blends(const std::vector<gi::AntiradianceTexelBlend>& a, const std::vector<gi::AntiradianceTexelBlend>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t k = 0; k < a.size(); ++k)
    if (a[k].texel != b[k].texel || a[k].leaves != b[k].leaves ||
        std::memcmp(&a[k].weights, &b[k].weights, sizeof(glm::vec4)) != 0)
      return false;
  return true;
}

}  // namespace

// The bake stores what a load at its pose computed (the deforming groups' links, the atlas
// texels' blends); read back, they are bit for bit what the load computes without them.
TEST(AntiradianceIo, WhatTheBakePreparesIsWhatTheLoadComputes) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  auto bake = gi::bake_antiradiance(scene.input, small());
  ASSERT_TRUE(bake) << bake.error().to_string();
  auto layout = gi::static_world_layout(scene.input, 8.0f);
  ASSERT_TRUE(layout) << layout.error().to_string();
  gi::AntiradianceBake prepared = *bake;
  gi::prepare_antiradiance_load(prepared, scene.input, &*layout);
  EXPECT_FALSE(prepared.at_baked_pose.links.links.empty()) << "the door links to the room";
  EXPECT_FALSE(prepared.at_baked_pose.blends.empty());
  const fs::path dir = scratch_dir("at_pose");
  ASSERT_TRUE(gi::save_antiradiance(dir, prepared, scene.input));
  ASSERT_TRUE(fs::exists(dir / gi::kAntiradianceAtPoseFile));
  auto loaded = gi::load_antiradiance(dir, scene.input);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  ASSERT_TRUE(loaded->at_baked_pose.present);
  EXPECT_EQ(loaded->at_baked_pose.layout_fingerprint, gi::atlas_layout_fingerprint(*layout));
  // The blends the load used to compute, from the loaded hierarchy.
  EXPECT_TRUE(same_blends(loaded->at_baked_pose.blends,
                          gi::antiradiance_texel_blends(loaded->hierarchy, scene.input, *layout)));
  // The region from the stored links against the region relinked as before.
  gi::AntiradianceBake without = *loaded;
  without.at_baked_pose = {};
  auto merged = gi::AntiradianceRegion::create(scene.input, std::move(loaded).value());
  auto relinked = gi::AntiradianceRegion::create(scene.input, std::move(without));
  ASSERT_TRUE(merged && relinked);
  EXPECT_TRUE(merged->at_baked_pose());
  EXPECT_TRUE(same_links(merged->links(), relinked->links()));
  EXPECT_EQ(merged->counters().links, relinked->counters().links);
  EXPECT_EQ(merged->counters().relinked_elements, relinked->counters().relinked_elements);
  merged->update();
  relinked->update();
  EXPECT_EQ(merged->irradiance(), relinked->irradiance());
}

// Away from the baked pose the stored links do not apply: the region relinks.
TEST(AntiradianceIo, AScenePosedElsewhereRelinksInsteadOfUsingTheStoredLinks) {
  const artest::DoorScene baked = artest::door_scene(30.0f);
  auto bake = gi::bake_antiradiance(baked.input, small());
  ASSERT_TRUE(bake) << bake.error().to_string();
  gi::prepare_antiradiance_load(*bake, baked.input, nullptr);
  EXPECT_EQ(bake->at_baked_pose.layout_fingerprint, 0u);
  const artest::DoorScene moved = artest::door_scene(60.0f);
  gi::AntiradianceBake without = *bake;
  without.at_baked_pose = {};
  auto a = gi::AntiradianceRegion::create(moved.input, std::move(bake).value());
  auto b = gi::AntiradianceRegion::create(moved.input, std::move(without));
  ASSERT_TRUE(a && b);
  EXPECT_FALSE(a->at_baked_pose());
  EXPECT_TRUE(same_links(a->links(), b->links()));
}

TEST(AntiradianceIo, ADamagedOrTruncatedAtPoseFileIsRejectedByName) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  auto bake = gi::bake_antiradiance(scene.input, small());
  ASSERT_TRUE(bake) << bake.error().to_string();
  gi::prepare_antiradiance_load(*bake, scene.input, nullptr);
  const fs::path dir = scratch_dir("at_pose_damaged");
  ASSERT_TRUE(gi::save_antiradiance(dir, *bake, scene.input));
  const fs::path file = dir / gi::kAntiradianceAtPoseFile;
  const std::vector<char> good = read_all(file);
  std::vector<char> truncated(good.begin(), good.end() - 5);
  write_all(file, truncated);
  auto r = gi::load_antiradiance(dir, scene.input);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().file, file.string());
  auto direct = gi::read_antiradiance_at_pose(file);
  ASSERT_FALSE(direct);
  EXPECT_TRUE(contains(direct.error().to_string(), "truncated")) << direct.error().to_string();
  std::vector<char> flipped = good;
  flipped[flipped.size() - 3] = static_cast<char>(flipped[flipped.size() - 3] ^ 1);
  write_all(file, flipped);
  auto c = gi::load_antiradiance(dir, scene.input);
  ASSERT_FALSE(c);
  EXPECT_TRUE(contains(c.error().to_string(), "checksum")) << c.error().to_string();
}

namespace {

// Rewrites `file`'s container with another payload layout version (re-sealed, so only the
// version is wrong) and the manifest's checksum of it, as an older gi-bake left the bundle.
void reseal_with_version(const fs::path& dir, const fs::path& file, std::uint32_t version) {
  auto payload = gi::read_blob(file, gi::kAntiradianceMagic, gi::kAntiradianceVersion);
  ASSERT_TRUE(payload) << payload.error().to_string();
  ASSERT_TRUE(gi::write_blob(file, gi::kAntiradianceMagic, version, *payload));
  auto sum = gi::file_checksum(file);
  ASSERT_TRUE(sum) << sum.error().to_string();
  std::ifstream in(dir / "manifest.json");
  nlohmann::json manifest = nlohmann::json::parse(in);
  in.close();
  manifest["methods"]["antiradiance"]["files"]["elements"]["xxh3_64"] = *sum;
  std::ofstream(dir / "manifest.json", std::ios::trunc) << manifest.dump(2);
}

}  // namespace

// Version 3 stores the refinement settings (issue 37): a load relinks the door with the
// bake's split leaf links, not with the defaults (which would link the leaves regardless).
TEST(AntiradianceIo, TheRefinementSettingsComeBackAndTheLoadRelinksWithThem) {
  const artest::DoorScene baked = artest::door_scene(30.0f);
  gi::AntiradianceSettings s = small();
  s.leaf_link_pieces = 16;
  s.near_patch_size_m = 0.3f;
  s.near_radius_m = 0.4f;
  auto bake = gi::bake_antiradiance(baked.input, s);
  ASSERT_TRUE(bake) << bake.error().to_string();
  const fs::path dir = scratch_dir("refinement");
  ASSERT_TRUE(gi::save_antiradiance(dir, *bake, baked.input));
  auto loaded = gi::load_antiradiance(dir, baked.input);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  EXPECT_EQ(loaded->settings.leaf_link_pieces, 16);
  EXPECT_EQ(loaded->settings.near_patch_size_m, 0.3f);
  EXPECT_EQ(loaded->settings.near_radius_m, 0.4f);
  EXPECT_EQ(loaded->hierarchy.leaf_count(), bake->hierarchy.leaf_count());
  // Posed elsewhere, the loaded region relinks the door as the fresh bake's region does,
  // and not as a region with the links unsplit.
  const artest::DoorScene moved = artest::door_scene(70.0f);
  gi::AntiradianceBake unsplit = *bake;
  unsplit.settings.leaf_link_pieces = 0;
  auto fresh = gi::AntiradianceRegion::create(moved.input, std::move(bake).value());
  auto from_file = gi::AntiradianceRegion::create(moved.input, std::move(loaded).value());
  auto regardless = gi::AntiradianceRegion::create(moved.input, std::move(unsplit));
  ASSERT_TRUE(fresh && from_file && regardless);
  EXPECT_TRUE(same_links(fresh->links(), from_file->links()));
  EXPECT_FALSE(same_links(fresh->links(), regardless->links())) << "the door's leaf links split or not alike";
}

// A bundle of a previous layout (version 3: no near-door visibility, no triangles; version 4:
// no near set budget) is refused by name, not misread.
TEST(AntiradianceIo, AnOlderVersionIsRefusedWithTheFilesName) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  auto bake = gi::bake_antiradiance(scene.input, small());
  ASSERT_TRUE(bake) << bake.error().to_string();
  for (std::uint32_t version : {3u, 4u}) {
    const fs::path dir = scratch_dir("version" + std::to_string(version));
    ASSERT_TRUE(gi::save_antiradiance(dir, *bake, scene.input));
    const fs::path file = dir / gi::kAntiradianceFile;
    reseal_with_version(dir, file, version);
    auto loaded = gi::load_antiradiance(dir, scene.input);
    ASSERT_FALSE(loaded);
    const std::string message = loaded.error().to_string();
    EXPECT_EQ(loaded.error().file, file.string()) << message;
    EXPECT_TRUE(contains(message, "version " + std::to_string(version))) << message;
    EXPECT_TRUE(contains(message, "re-bake")) << message;
  }
  const fs::path dir = scratch_dir("version_bad_settings");
  // A file that claims a bad refinement setting (resealed payload) is refused by its checks.
  gi::AntiradianceBake bad = *bake;
  bad.settings.leaf_link_pieces = gi::kMaxLeafLinkPieces + 1;
  auto st = gi::write_antiradiance(dir / "bad.bin", bad, "h");
  ASSERT_FALSE(st);
  EXPECT_TRUE(contains(st.error().to_string(), "leaf_link_pieces")) << st.error().to_string();
}

// Version 4 carries near-door visibility (issue 37): its settings, and the elements' triangles
// its rays need (a loaded hierarchy had none), only when it is on.
TEST(AntiradianceIo, NearVisibilityComesBackWithTheTrianglesItTracesAgainst) {
  const artest::DoorScene scene = artest::door_scene(30.0f);
  gi::AntiradianceSettings s = small();
  s.near_visibility = true;
  s.near_visibility_radius_m = 0.7f;
  s.near_visibility_point_pairs = 8;
  s.near_visibility_budget_bytes = 3u << 20;
  auto bake = gi::bake_antiradiance(scene.input, s);
  ASSERT_TRUE(bake) << bake.error().to_string();
  ASSERT_EQ(bake->hierarchy.corners.size(), 3 * bake->hierarchy.nodes.size());
  const fs::path dir = scratch_dir("near_visibility");
  ASSERT_TRUE(gi::save_antiradiance(dir, *bake, scene.input));
  auto loaded = gi::load_antiradiance(dir, scene.input);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  EXPECT_TRUE(loaded->settings.near_visibility);
  EXPECT_EQ(loaded->settings.near_visibility_radius_m, 0.7f);
  EXPECT_EQ(loaded->settings.near_visibility_point_pairs, 8);
  EXPECT_EQ(loaded->settings.near_visibility_budget_bytes, 3u << 20);
  EXPECT_EQ(loaded->hierarchy.corners, bake->hierarchy.corners);
  EXPECT_EQ(loaded->hierarchy.object_corners, bake->hierarchy.object_corners);

  // Off: no triangles stored, and a load has none (as before version 4).
  gi::AntiradianceBake off = *bake;
  off.settings.near_visibility = false;
  const fs::path dir_off = scratch_dir("near_visibility_off");
  ASSERT_TRUE(gi::save_antiradiance(dir_off, off, scene.input));
  auto loaded_off = gi::load_antiradiance(dir_off, scene.input);
  ASSERT_TRUE(loaded_off) << loaded_off.error().to_string();
  EXPECT_FALSE(loaded_off->settings.near_visibility);
  EXPECT_TRUE(loaded_off->hierarchy.corners.empty());
  EXPECT_LT(fs::file_size(dir_off / gi::kAntiradianceFile), fs::file_size(dir / gi::kAntiradianceFile));

  // Bad settings and triangles are refused before writing, naming the problem.
  gi::AntiradianceBake bad = *bake;
  bad.settings.near_visibility_point_pairs = 65;
  auto st = gi::write_antiradiance(dir / "bad.bin", bad, "h");
  ASSERT_FALSE(st);
  EXPECT_TRUE(contains(st.error().to_string(), "near_visibility_point_pairs")) << st.error().to_string();
  bad = *bake;
  bad.settings.near_visibility_budget_bytes = std::uint64_t{1} << 50;
  st = gi::write_antiradiance(dir / "bad.bin", bad, "h");
  ASSERT_FALSE(st);
  EXPECT_TRUE(contains(st.error().to_string(), "near_visibility_budget_bytes")) << st.error().to_string();
  bad = *bake;
  bad.hierarchy.corners.pop_back();
  st = gi::write_antiradiance(dir / "bad.bin", bad, "h");
  ASSERT_FALSE(st);
  EXPECT_TRUE(contains(st.error().to_string(), "triangles")) << st.error().to_string();
}
