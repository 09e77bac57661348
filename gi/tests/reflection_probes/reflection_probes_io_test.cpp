// reflection_probes.bin in a bake bundle: a round trip is exact, and a truncated, stale or
// inconsistent bundle is refused with an error that names the file.
#include "reflection_probes/reflection_probes_io.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "bundle/geometry_hash.h"
#include "uv/atlas_layout.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "reflection_probes_io_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

// A closed 3 m room (one static instance) and a small set of two probes over it.
gi::BakeInput room_input() {
  gi::BakeInput in;
  in.name = "room.gltf";
  in.materials.push_back(gi::BakeMaterial{.base_color = glm::vec3(0.5f), .roughness = 1.0f});
  gi::BakePrimitive p;
  const auto quad = [&](glm::vec3 c, glm::vec3 u, glm::vec3 v) {
    const auto base = static_cast<std::uint32_t>(p.positions.size());
    p.positions.insert(p.positions.end(), {c, c + u, c + u + v, c + v});
    p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  };
  quad({0, 0, 0}, {0, 0, 3}, {3, 0, 0});
  quad({0, 3, 0}, {3, 0, 0}, {0, 0, 3});
  gi::BakeMesh mesh;
  mesh.name = "room";
  mesh.primitives.push_back(std::move(p));
  in.meshes.push_back(std::move(mesh));
  in.instances.push_back(gi::BakeInstance{.name = "room", .mesh = 0, .id = 0});
  return in;
}

gi::ReflectionProbeSet small_set() {
  gi::ReflectionProbeSet set;
  set.settings.resolution = 4;
  for (int i = 0; i < 2; ++i) {
    set.probes.push_back(
        gi::ProbeVolume{glm::vec3(1.5f, 1.5f, 0.5f + static_cast<float>(i)), glm::vec3(0.0f), glm::vec3(3.0f)});
    gi::ProbeCube c = gi::make_probe_cube(4, gi::full_mip_count(4));
    float v = 0.1f * static_cast<float>(i + 1);
    for (auto& level : c.levels)
      for (glm::vec3& t : level) {
        v += 0.01f;
        t = glm::vec3(v, 2.0f * v, 0.5f);
      }
    for (std::size_t t = 0; t < c.levels[0].size(); ++t) c.distance.push_back(0.5f + 0.01f * static_cast<float>(t));
    set.cubes.push_back(std::move(c));
  }
  return set;
}

TEST(ReflectionProbesIo, RoundTripIsExact) {
  const fs::path dir = scratch_dir("round_trip");
  const gi::BakeInput in = room_input();
  const gi::ReflectionProbeSet set = small_set();
  ASSERT_TRUE(gi::save_reflection_probes(dir, set, in));
  auto back = gi::load_reflection_probes(dir, in);
  ASSERT_TRUE(back) << back.error().to_string();
  ASSERT_EQ(back->probes.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(back->probes[i].centre, set.probes[i].centre);
    EXPECT_EQ(back->probes[i].box_max, set.probes[i].box_max);
    EXPECT_EQ(back->cubes[i].levels, set.cubes[i].levels);
    EXPECT_EQ(back->cubes[i].distance, set.cubes[i].distance);
  }
  EXPECT_EQ(back->settings.resolution, 4);
}

TEST(ReflectionProbesIo, TruncatedFileIsRefusedNamingIt) {
  const fs::path dir = scratch_dir("truncated");
  const fs::path file = dir / gi::kReflectionProbesFile;
  fs::create_directories(dir);
  ASSERT_TRUE(gi::write_reflection_probes_file(file, small_set(), "hash"));
  fs::resize_file(file, fs::file_size(file) - 10);
  auto r = gi::read_reflection_probes_file(file);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().file, file.string());
  EXPECT_NE(r.error().to_string().find("reflection_probes.bin"), std::string::npos) << r.error().to_string();
}

// Truncated inside a bundle: the manifest's checksum no longer matches, and the error names the file.
TEST(ReflectionProbesIo, TruncatedBundleFileIsRefusedAtLoad) {
  const fs::path dir = scratch_dir("truncated_bundle");
  const gi::BakeInput in = room_input();
  ASSERT_TRUE(gi::save_reflection_probes(dir, small_set(), in));
  fs::resize_file(dir / gi::kReflectionProbesFile, 100);
  auto r = gi::load_reflection_probes(dir, in);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().to_string().find("reflection_probes.bin"), std::string::npos) << r.error().to_string();
}

TEST(ReflectionProbesIo, StaleBundleIsRefused) {
  const fs::path dir = scratch_dir("stale");
  gi::BakeInput in = room_input();
  ASSERT_TRUE(gi::save_reflection_probes(dir, small_set(), in));
  in.meshes[0].primitives[0].positions[0].x += 0.5f;  // the level changed after the bake
  auto r = gi::load_reflection_probes(dir, in);
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().to_string().find("manifest.json"), std::string::npos) << r.error().to_string();
}

// Version 1 files (before the captured distances) are refused, naming the file and asking for a re-bake.
TEST(ReflectionProbesIo, AVersionOneFileIsRefusedNamingIt) {
  const fs::path dir = scratch_dir("version_one");
  fs::create_directories(dir);
  const fs::path file = dir / gi::kReflectionProbesFile;
  ASSERT_TRUE(gi::write_blob(file, gi::kReflectionProbesMagic, 1, std::vector<std::byte>(64)));
  auto r = gi::read_reflection_probes_file(file);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().file, file.string());
  EXPECT_NE(r.error().to_string().find("unsupported version 1"), std::string::npos) << r.error().to_string();
}

// A distance out of range (negative, NaN) or a cube without its distances is not written.
TEST(ReflectionProbesIo, MissingOrInvalidDistancesAreNotWritten) {
  const fs::path dir = scratch_dir("distances");
  fs::create_directories(dir);
  gi::ReflectionProbeSet set = small_set();
  set.cubes[1].distance[3] = std::nanf("");
  auto st = gi::write_reflection_probes_file(dir / gi::kReflectionProbesFile, set, "hash");
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("distance out of range"), std::string::npos) << st.error().message;
  set.cubes[1].distance.clear();
  st = gi::write_reflection_probes_file(dir / gi::kReflectionProbesFile, set, "hash");
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("0 distances for"), std::string::npos) << st.error().message;
}

TEST(ReflectionProbesIo, InconsistentSetIsNotWritten) {
  const fs::path dir = scratch_dir("inconsistent");
  fs::create_directories(dir);
  gi::ReflectionProbeSet set = small_set();
  set.cubes.pop_back();
  const auto st = gi::write_reflection_probes_file(dir / gi::kReflectionProbesFile, set, "hash");
  ASSERT_FALSE(st);
  EXPECT_NE(st.error().message.find("1 cube maps for 2 probes"), std::string::npos) << st.error().message;
}

}  // namespace
