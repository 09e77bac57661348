// Basis radiance fields in a bake bundle: the dynamic meshes a scene needs them for, a bake
// with small settings saved and loaded back bit for bit, stale meshes and damaged files
// rejected with messages naming the file.
#include "brf/brf_io.h"

#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/gltf_brdf.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <engine/byte_stream.h>
#include "bundle/bundle.h"
#include "raytrace/scene_adapter.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "brf_io_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir.parent_path());
  return dir;
}

const engine::Scene& crates_room() {
  static const engine::Scene scene = [] {
    auto a = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf");
    EXPECT_TRUE(a.ok()) << a.error().to_string();
    return engine::instantiate(std::move(a).value());
  }();
  return scene;
}

const std::vector<gi::BrfSource>& sources() {
  static const std::vector<gi::BrfSource> s = gi::dynamic_brf_meshes(gi::bake_input_from(crates_room())).value();
  return s;
}

// Small enough for a test (well under a second for both crate meshes).
gi::BrfSettings tiny_settings() {
  gi::BrfSettings s = gi::brf_preset("preview").value();
  s.basis.lights = 32;
  s.basis.basis = 6;
  s.field.spheres = 3;
  s.field.face_resolution = 3;
  s.field.directions = 32;
  return s;
}

const gi::BrfBake& baked() {
  static const gi::BrfBake bake = [] {
    gi::BrfBake b{.settings = tiny_settings(), .meshes = {}};
    for (const gi::BrfSource& s : sources()) b.meshes.push_back(gi::bake_brf_mesh(s, b.settings).value());
    return b;
  }();
  return bake;
}

// A bundle with the tiny bake saved into it.
fs::path saved_bundle(const std::string& name) {
  const fs::path dir = scratch_dir(name);
  const engine::Status s = gi::save_brf(dir, baked(), gi::bake_input_from(crates_room().assets));
  EXPECT_TRUE(s.ok()) << s.error().to_string();
  return dir;
}

template <class T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

bool same_bits(const glm::vec3& a, const glm::vec3& b) { return std::memcmp(&a, &b, sizeof a) == 0; }

std::vector<std::byte> payload_of(const fs::path& file) {
  return gi::read_blob(file, gi::kBrfMeshMagic, gi::kBrfMeshVersion).value();
}

// Writes `payload` as a valid container (correct size and checksum) at `file`.
void put_payload(const fs::path& file, const std::vector<std::byte>& payload) {
  ASSERT_TRUE(gi::write_blob(file, gi::kBrfMeshMagic, gi::kBrfMeshVersion, payload).ok());
}

template <class T>
void poke(std::vector<std::byte>& bytes, std::size_t offset, T value) {
  std::memcpy(bytes.data() + offset, &value, sizeof value);
}

void poke_file(const fs::path& file, std::size_t offset, std::uint8_t value) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.put(static_cast<char>(value));
}

// Payload offsets of the fields after the two leading strings (brf_io.h).
struct Offsets {
  std::size_t vertex_count, basis_count, condition, psi_count, psi_data;
};
Offsets offsets_of(const gi::BrfMeshBake& b) {
  Offsets o{};
  o.vertex_count = 8 + b.model.name.size() + 8 + b.mesh_hash.size();
  o.basis_count = o.vertex_count + 8;
  o.condition = o.basis_count + 4;
  o.psi_count = o.condition + 8 + 12 + 4;
  o.psi_data = o.psi_count + 8;
  return o;
}

// read_brf_mesh's error for `file`: must fail and name the file.
std::string read_error(const fs::path& file) {
  auto r = gi::read_brf_mesh(file);
  EXPECT_FALSE(r.ok());
  if (r.ok()) return {};
  EXPECT_EQ(r.error().file, file.string());
  return r.error().to_string();
}

TEST(BrfMeshes, CratesRoomGivesOneSourcePerDynamicMeshAndSkipsStaticOnes) {
  const engine::Scene& scene = crates_room();
  const std::vector<gi::BrfSource>& s = sources();
  // crate_red (mesh 5, one node) comes first in node order, then crate (mesh 4, four nodes);
  // room, floor, ceiling panel and statue are static.
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s[0].name, "crate_red");
  EXPECT_EQ(s[0].mesh_index, 5u);
  EXPECT_EQ(s[0].instances.size(), 1u);
  EXPECT_EQ(s[1].name, "crate");
  EXPECT_EQ(s[1].mesh_index, 4u);
  EXPECT_EQ(s[1].instances.size(), 4u);
  const gi::BakeInput input = gi::bake_input_from(scene);
  for (const gi::BrfSource& src : s) {
    const engine::Mesh& mesh = scene.assets.meshes[src.mesh_index];
    std::size_t vertices = 0;
    for (const engine::Primitive& p : mesh.primitives) vertices += p.positions.size();
    EXPECT_EQ(src.mesh.positions.size(), vertices);
    EXPECT_EQ(src.mesh.normals.size(), vertices);
    EXPECT_EQ(src.mesh.reflectance.size(), vertices);
    // Object space, in primitive order: the renderer's per-vertex buffer order.
    EXPECT_TRUE(same_bits(src.mesh.positions[0], mesh.primitives[0].positions[0]));
    for (const glm::vec3& n : src.mesh.normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
    // The folded reflectance: the luminance of the material's hemispherical albedo (both lobes).
    const gi::BakeMaterial& m = input.materials[static_cast<std::size_t>(mesh.primitives[0].material)];
    const glm::vec3 rho = engine::gltf_hemispherical_albedo(gi::reference_material(m).brdf).sum();
    EXPECT_NEAR(src.mesh.reflectance[0], 0.2126f * rho.x + 0.7152f * rho.y + 0.0722f * rho.z, 1e-6f);
    EXPECT_GT(src.mesh.reflectance[0],
              0.2126f * m.base_color.x + 0.7152f * m.base_color.y + 0.0722f * m.base_color.z - 0.05f);
    EXPECT_EQ(src.mesh_hash, gi::brf_mesh_hash(src.mesh));
    for (std::uint32_t i : src.instances) {
      const engine::Entity e = input.instances[i].entity;
      EXPECT_EQ(input.instances[i].mobility, gi::BakeMobility::Dynamic);
      EXPECT_TRUE(scene.registry.has<engine::DynamicTag>(e));
      EXPECT_EQ(scene.registry.get<engine::MeshRenderer>(e).mesh, src.mesh_index);
    }
  }
  EXPECT_NE(s[0].mesh_hash, s[1].mesh_hash);  // other base colour
}

TEST(BrfMeshes, DemoLevelSkipsTheLampPivotAndStaticMeshes) {
  auto a = engine::load_gltf(GI_SOURCE_DIR "/assets/demo_level.gltf");
  ASSERT_TRUE(a.ok()) << a.error().to_string();
  const engine::Scene scene = engine::instantiate(std::move(a).value());
  auto s = gi::dynamic_brf_meshes(gi::bake_input_from(scene));
  ASSERT_TRUE(s.ok()) << s.error().to_string();
  std::vector<std::string> names;
  for (const gi::BrfSource& src : *s) names.push_back(src.name);
  EXPECT_EQ(names, (std::vector<std::string>{"crate_red", "crate", "lamp_shade"}));
}

TEST(BrfMeshes, HashFollowsGeometryAndReflectance) {
  gi::BrfMesh m = sources()[1].mesh;
  const std::string h = gi::brf_mesh_hash(m);
  EXPECT_EQ(h.size(), 16u);
  m.positions[3].x += 1e-3f;
  EXPECT_NE(gi::brf_mesh_hash(m), h);
  m = sources()[1].mesh;
  m.reflectance[0] *= 0.5f;
  EXPECT_NE(gi::brf_mesh_hash(m), h);
}

TEST(BrfIo, RoundTripIsBitExact) {
  const fs::path dir = saved_bundle("round_trip");
  auto loaded = gi::load_brf(dir, gi::bake_input_from(crates_room()));
  ASSERT_TRUE(loaded.ok()) << loaded.error().to_string();
  const gi::BrfBake& a = baked();
  ASSERT_EQ(loaded->meshes.size(), a.meshes.size());
  EXPECT_EQ(loaded->settings.basis.lights, a.settings.basis.lights);
  EXPECT_EQ(loaded->settings.basis.basis, a.settings.basis.basis);
  EXPECT_EQ(loaded->settings.field.spheres, a.settings.field.spheres);
  EXPECT_EQ(loaded->settings.field.directions, a.settings.field.directions);
  for (std::size_t i = 0; i < a.meshes.size(); ++i) {
    const gi::BrfMeshBake& x = a.meshes[i];
    const gi::BrfMeshBake& y = loaded->meshes[i];
    EXPECT_EQ(y.model.name, x.model.name);
    EXPECT_FALSE(y.model.mesh.positions.empty());  // load_brf fills in the scene's mesh, as the bake had it
    EXPECT_TRUE(same_bits(y.model.mesh.positions, x.model.mesh.positions));
    EXPECT_TRUE(same_bits(y.model.mesh.normals, x.model.mesh.normals));
    EXPECT_EQ(y.mesh_hash, x.mesh_hash);
    EXPECT_EQ(y.model.basis.vertex_count, x.model.basis.vertex_count);
    EXPECT_EQ(y.model.basis.basis_count, x.model.basis.basis_count);
    EXPECT_TRUE(same_bits(y.model.basis.psi, x.model.basis.psi));
    EXPECT_TRUE(same_bits(y.model.basis.a_inverse, x.model.basis.a_inverse));
    EXPECT_TRUE(same_bits(y.model.basis.singular_values, x.model.basis.singular_values));
    EXPECT_EQ(std::memcmp(&y.model.basis.condition, &x.model.basis.condition, sizeof(double)), 0);
    EXPECT_TRUE(same_bits(y.model.basis.centre, x.model.basis.centre));
    EXPECT_EQ(std::memcmp(&y.model.basis.radius, &x.model.basis.radius, sizeof(float)), 0);
    EXPECT_EQ(y.model.field.spheres, x.model.field.spheres);
    EXPECT_EQ(y.model.field.face_resolution, x.model.field.face_resolution);
    EXPECT_EQ(y.model.field.sh_bands, x.model.field.sh_bands);
    EXPECT_EQ(y.model.field.basis_count, x.model.field.basis_count);
    EXPECT_TRUE(same_bits(y.model.field.centre, x.model.field.centre));
    EXPECT_EQ(std::memcmp(&y.model.field.inner_radius, &x.model.field.inner_radius, sizeof(float)), 0);
    EXPECT_EQ(std::memcmp(&y.model.field.outer_radius, &x.model.field.outer_radius, sizeof(float)), 0);
    EXPECT_TRUE(same_bits(y.model.field.coefficients, x.model.field.coefficients));
    EXPECT_EQ(y.basis_seconds, 0.0) << "timings are in bake_stats.json, not in the bundle's files";
    EXPECT_EQ(y.field_seconds, 0.0);
  }
}

TEST(BrfIo, ManifestDescribesEveryMeshAndKeepsOtherMethods) {
  const fs::path dir = scratch_dir("manifest");
  fs::create_directories(dir);
  const std::string hash = gi::scene_geometry_hash(gi::bake_input_from(crates_room().assets));
  ASSERT_TRUE(gi::update_manifest_method(dir, hash, "crates_room.gltf", "prm", {{"kept", true}}).ok());
  ASSERT_TRUE(gi::save_brf(dir, baked(), gi::bake_input_from(crates_room().assets)).ok());
  auto m = gi::read_manifest(dir);
  ASSERT_TRUE(m.ok()) << m.error().to_string();
  EXPECT_TRUE(m->methods.contains("prm"));
  const nlohmann::json& e = m->methods["brf"];
  for (const gi::BrfMeshBake& b : baked().meshes) {
    EXPECT_EQ(e["files"][b.model.name]["file"], gi::brf_file_name(b.model.name));
    EXPECT_EQ(e["files"][b.model.name]["xxh3_64"], gi::file_checksum(dir / gi::brf_file_name(b.model.name)).value());
    const nlohmann::json& s = e["meshes"][b.model.name];
    EXPECT_EQ(s["vertices"], b.model.basis.vertex_count);
    EXPECT_EQ(s["basis_kept"], b.model.basis.basis_count);
    EXPECT_EQ(s["field_bytes"], b.model.field.bytes());
    EXPECT_EQ(s["file_bytes"], fs::file_size(dir / gi::brf_file_name(b.model.name)));
    // The float planes compress.
    EXPECT_LT(s["field_compressed_bytes"].get<std::uint64_t>(), b.model.field.bytes());
  }
  EXPECT_EQ(e["settings"]["field"]["spheres"], 3);
}

TEST(BrfIo, StaleMeshIsRejectedWithBothHashes) {
  const fs::path dir = saved_bundle("stale");
  std::vector<gi::BrfSource> edited = sources();
  edited[1].mesh.positions[0].y += 0.01f;
  edited[1].mesh_hash = gi::brf_mesh_hash(edited[1].mesh);
  auto r = gi::load_brf(dir, edited);
  ASSERT_FALSE(r.ok());
  const std::string msg = r.error().to_string();
  EXPECT_EQ(r.error().file, (dir / "brf_crate.bin").string());
  EXPECT_NE(msg.find("stale"), std::string::npos) << msg;
  EXPECT_NE(msg.find(edited[1].mesh_hash), std::string::npos) << msg;
  EXPECT_NE(msg.find(sources()[1].mesh_hash), std::string::npos) << msg;
}

TEST(BrfIo, MissingEntryOrFileIsRejected) {
  const fs::path dir = saved_bundle("missing");
  std::vector<gi::BrfSource> extra = sources();
  extra.push_back(sources()[0]);
  extra.back().name = "barrel";
  auto r = gi::load_brf(dir, extra);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().to_string().find("barrel"), std::string::npos) << r.error().to_string();

  fs::remove(dir / "brf_crate.bin");
  r = gi::load_brf(dir, gi::bake_input_from(crates_room()));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, (dir / "brf_crate.bin").string());
  EXPECT_NE(r.error().message.find("not found"), std::string::npos) << r.error().to_string();

  r = gi::load_brf(scratch_dir("no_bundle"), gi::bake_input_from(crates_room()));
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().file.find("manifest.json"), std::string::npos);
}

TEST(BrfIo, DamagedContainersAreRejected) {
  const fs::path dir = saved_bundle("damaged");
  const fs::path file = dir / "brf_crate.bin";
  const fs::path copy = dir / "original.bin";
  fs::copy_file(file, copy);
  const auto restore = [&] { fs::copy_file(copy, file, fs::copy_options::overwrite_existing); };

  poke_file(file, 0, 'X');  // magic
  EXPECT_NE(read_error(file).find("wrong magic"), std::string::npos);
  restore();
  poke_file(file, 8, 1);  // version 1: before glossy terms
  EXPECT_NE(read_error(file).find("unsupported version"), std::string::npos);
  restore();
  poke_file(file, fs::file_size(file) - 5, 0xa5);  // payload bit flips
  EXPECT_NE(read_error(file).find("checksum"), std::string::npos);
  // Through the bundle the manifest's file checksum catches it first.
  auto r = gi::load_brf(dir, gi::bake_input_from(crates_room()));
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, file.string());
  EXPECT_NE(r.error().message.find("checksum"), std::string::npos);
  restore();
  fs::resize_file(file, fs::file_size(file) - 10);
  EXPECT_NE(read_error(file).find("truncated"), std::string::npos);
  restore();
  { std::ofstream(file, std::ios::app | std::ios::binary) << "extra"; }
  EXPECT_NE(read_error(file).find("trailing"), std::string::npos);
  restore();
  EXPECT_TRUE(gi::read_brf_mesh(file).ok());
}

TEST(BrfIo, InconsistentPayloadsAreRejected) {
  const fs::path dir = saved_bundle("payloads");
  const fs::path file = dir / "brf_crate.bin";
  const std::vector<std::byte> original = payload_of(file);
  const gi::BrfMeshBake& b = baked().meshes[1];
  const Offsets o = offsets_of(b);

  std::vector<std::byte> p(original.begin(), original.end() - 3);  // truncated payload, valid container
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("truncated payload"), std::string::npos);

  p = original;
  p.push_back(std::byte{0});
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("unexpected data"), std::string::npos);

  p = original;
  poke(p, o.psi_data + 4 * 5, std::numeric_limits<float>::quiet_NaN());
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("NaN or infinite"), std::string::npos);

  p = original;
  poke(p, o.condition, std::numeric_limits<double>::infinity());
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("condition"), std::string::npos);

  p = original;
  poke(p, o.basis_count, static_cast<std::int32_t>(b.model.basis.basis_count + 1));
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("psi has"), std::string::npos);

  p = original;
  poke(p, o.vertex_count, std::uint64_t{1} << 40);
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("vertex_count"), std::string::npos);

  // The field header: spheres (after psi, a_inverse, singular_values and the basis's terms).
  const std::size_t a_inv = o.psi_data + b.model.basis.psi.size() * 4;
  const std::size_t sv = a_inv + 8 + b.model.basis.a_inverse.size() * 4;
  const std::size_t spheres = sv + 8 + b.model.basis.singular_values.size() * 4 + 4;
  p = original;
  poke(p, spheres, std::int32_t{100000});
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("field settings out of range"), std::string::npos);
  p = original;
  poke(p, spheres, std::int32_t{b.model.field.spheres + 1});
  put_payload(file, p);
  EXPECT_NE(read_error(file).find("coefficient bytes"), std::string::npos);
  // coefficient_bytes and the frame's own size disagree.
  const std::size_t coefficient_bytes = spheres + 20 + 12 + 8;
  p = original;
  poke(p, coefficient_bytes, static_cast<std::uint64_t>(b.model.field.bytes() + 4));
  put_payload(file, p);
  EXPECT_FALSE(gi::read_brf_mesh(file).ok());

  put_payload(file, original);
  EXPECT_TRUE(gi::read_brf_mesh(file).ok());
}

TEST(BrfIo, InvalidBakeRefusesToSaveAndWritesNothing) {
  const fs::path dir = scratch_dir("invalid");
  gi::BrfBake bad = baked();
  bad.meshes[0].model.field.coefficients[7] = std::numeric_limits<float>::infinity();
  auto s = gi::save_brf(dir, bad, gi::bake_input_from(crates_room().assets));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().to_string().find("brf_crate_red.bin"), std::string::npos) << s.error().to_string();
  EXPECT_FALSE(fs::exists(dir));

  bad = baked();
  bad.meshes[1].model.basis.a_inverse.pop_back();
  s = gi::save_brf(dir, bad, gi::bake_input_from(crates_room().assets));
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().to_string().find("a_inverse"), std::string::npos);

  bad = baked();
  bad.meshes[1].model.name = bad.meshes[0].model.name;
  EXPECT_FALSE(gi::save_brf(dir, bad, gi::bake_input_from(crates_room().assets)).ok());
  EXPECT_FALSE(fs::exists(dir));
}

}  // namespace
