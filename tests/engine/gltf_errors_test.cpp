// Malformed glTF input: every case must give an engine::Error that names the file and says
// what is wrong (checked by a specific substring), never a crash or an exception.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wnull-dereference"
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#pragma GCC diagnostic pop
#include <nlohmann/json.hpp>

#include <engine/gltf.h>

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0u) |
                            (i + 2 < bytes.size() ? bytes[i + 2] : 0u);
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}

template <class T>
std::vector<std::uint8_t> bytes_of(const std::vector<T>& v) {
  std::vector<std::uint8_t> out(v.size() * sizeof(T));
  std::memcpy(out.data(), v.data(), out.size());
  return out;
}

/// A valid file: one triangle with indices. Buffer layout: 36 bytes of positions (view 0),
/// then 6 bytes of u16 indices (view 1). Accessor 0 = POSITION, accessor 1 = indices.
json valid_doc(const std::vector<std::uint16_t>& indices = {0, 1, 2}) {
  std::vector<std::uint8_t> bin = bytes_of(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  const auto idx = bytes_of(indices);
  bin.insert(bin.end(), idx.begin(), idx.end());
  json d = json::parse(R"({"asset": {"version": "2.0"},
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
    "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
  d["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                                  {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", idx.size()}}});
  d["buffers"] =
      json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
  return d;
}

fs::path dir() {
  const auto* info = testing::UnitTest::GetInstance()->current_test_info();
  fs::path d = fs::path(testing::TempDir()) / "gi_gltf_errors" / info->name();
  fs::create_directories(d);
  return d;
}

fs::path write(const std::string& name, const std::string& text) {
  const fs::path p = dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p;
}

fs::path write_bytes(const std::string& name, const std::vector<std::uint8_t>& bytes) {
  const fs::path p = dir() / name;
  std::ofstream(p, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return p;
}

/// Loads `path`, expects an error naming the file and containing every `needles` entry.
void expect_error(const fs::path& path, std::initializer_list<const char*> needles,
                  const engine::GltfLoadOptions& options = {}) {
  auto r = engine::load_gltf(path, options);
  ASSERT_FALSE(r.ok()) << path << " loaded but should not";
  const std::string msg = r.error().to_string();
  EXPECT_EQ(r.error().file, path.string());
  EXPECT_NE(msg.find(path.string()), std::string::npos) << msg;
  for (const char* n : needles) EXPECT_NE(msg.find(n), std::string::npos) << "missing '" << n << "' in: " << msg;
}

TEST(GltfErrors, ValidBaselineLoads) {
  auto r = engine::load_gltf(write("ok.gltf", valid_doc().dump()));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  EXPECT_EQ(r->meshes.at(0).primitives.at(0).indices.size(), 3u);
}

// Found by fuzz_gltf: two indices made no triangle, and the primitive was kept with empty
// indices, which engine::Primitive reads as non-indexed: write_gltf then refused the scene
// ("non-indexed vertex count is not a multiple of 3"). Such a primitive is now skipped like
// points and lines, and the scene writes and loads back.
TEST(GltfErrors, IndicesThatMakeNoTriangleLeaveThePrimitiveOut) {
  for (const std::vector<std::uint16_t>& indices : {std::vector<std::uint16_t>{0, 1}, std::vector<std::uint16_t>{0}}) {
    json d = valid_doc(indices);
    d["accessors"][1]["count"] = indices.size();
    auto r = engine::load_gltf(write("two.gltf", d.dump()));
    ASSERT_TRUE(r.ok()) << r.error().to_string();
    ASSERT_EQ(r->meshes.size(), 1u);
    EXPECT_TRUE(r->meshes[0].primitives.empty());
    const fs::path again = dir() / "again.glb";
    const engine::Status st = engine::write_gltf(*r, again, {.binary = true});
    ASSERT_TRUE(st) << st.error().to_string();
    auto back = engine::load_gltf(again);
    ASSERT_TRUE(back.ok()) << back.error().to_string();
    EXPECT_EQ(back->nodes.size(), r->nodes.size());
  }
}

TEST(GltfErrors, NonExistentPathEmptyFileAndDirectory) {
  expect_error(dir() / "missing.gltf", {"does not exist"});
  expect_error(write("empty.gltf", ""), {"empty file"});
  fs::create_directories(dir() / "folder.gltf");
  expect_error(dir() / "folder.gltf", {"is a directory"});
}

TEST(GltfErrors, BadJson) {
  expect_error(write("bad.gltf", R"({"asset": {"version": "2.0"}, "nodes": [)"), {"bad JSON"});
  expect_error(write("array.gltf", "[1, 2]"), {"root is not a JSON object"});
  expect_error(write("noasset.gltf", R"({"nodes": []})"), {"asset.version"});
}

// A crafted file nesting 300,000 arrays in extras used to overflow the stack of the
// recursive walks; real files nest a few levels, and 256 still load.
TEST(GltfErrors, AbsurdlyDeepJsonIsRefusedNotACrash) {
  const auto nested = [](int levels) {
    json d = valid_doc();
    std::string text = d.dump();
    text.pop_back();  // the closing brace
    text += ",\"extras\":" + std::string(static_cast<std::size_t>(levels), '[') +
            std::string(static_cast<std::size_t>(levels), ']') + "}";
    return text;
  };
  expect_error(write("deep.gltf", nested(300000)), {"nested deeper than 256 levels"});
  auto ok = engine::load_gltf(write("deep_enough.gltf", nested(250)));
  EXPECT_TRUE(ok.ok()) << ok.error().to_string();
}

TEST(GltfErrors, MissingBufferFile) {
  json d = valid_doc();
  d["buffers"][0]["uri"] = "nowhere.bin";
  expect_error(write("nobin.gltf", d.dump()), {"nowhere.bin"});
}

TEST(GltfErrors, MissingImageFileUsedByAMaterial) {
  json d = valid_doc();
  d["images"] = json::parse(R"([{"uri": "gone.png"}])");
  d["textures"] = json::parse(R"([{"source": 0}])");
  d["materials"] = json::parse(R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])");
  expect_error(write("noimage.gltf", d.dump()), {"image 0 'gone.png'", "missing"});
  // An undecodable image is an error too.
  std::ofstream(dir() / "garbage.png") << "this is not a PNG";
  d["images"][0]["uri"] = "garbage.png";
  expect_error(write("badimage.gltf", d.dump()), {"image 0 'garbage.png'", "cannot decode"});
}

TEST(GltfErrors, AccessorOutOfRangeOfItsBufferView) {
  json d = valid_doc();
  d["accessors"][1]["count"] = 30;  // 60 bytes in a 6-byte view
  expect_error(write("acc.gltf", d.dump()), {"accessor 1", "out of range of bufferView 1"});
  d = valid_doc();
  d["accessors"][0]["byteOffset"] = 4;  // the last element runs past the view
  expect_error(write("acc_offset.gltf", d.dump()), {"accessor 0", "out of range"});
}

TEST(GltfErrors, BufferViewOutOfRangeOfItsBuffer) {
  json d = valid_doc();
  d["bufferViews"][1]["byteLength"] = 400;
  expect_error(write("view.gltf", d.dump()), {"bufferView 1", "out of range of buffer 0"});
}

TEST(GltfErrors, IndexValueBeyondVertexCount) {
  expect_error(write("index.gltf", valid_doc({0, 1, 7}).dump()), {"accessor 1", "index value 7", "vertex count 3"});
}

TEST(GltfErrors, ReferencesOutOfRange) {
  json d = valid_doc();
  d["nodes"][0]["mesh"] = 5;
  expect_error(write("mesh_ref.gltf", d.dump()), {"node 0", "mesh"});
  d = valid_doc();
  d["meshes"][0]["primitives"][0]["material"] = 2;
  expect_error(write("material_ref.gltf", d.dump()), {"mesh 0 primitive 0", "material 2"});
  d = valid_doc();
  d["nodes"][0]["camera"] = 0;
  expect_error(write("camera_ref.gltf", d.dump()), {"node 0", "camera"});
  d = valid_doc();
  d["textures"] = json::parse(R"([{"source": 3}])");
  expect_error(write("texture_ref.gltf", d.dump()), {"texture 0", "missing image"});
  d = valid_doc();
  d["nodes"][0]["children"] = json::array({4});
  expect_error(write("child_ref.gltf", d.dump()), {"node 0", "missing node"});
  d = valid_doc();
  d["scene"] = 3;
  expect_error(write("scene_ref.gltf", d.dump()), {"'scene'"});
}

TEST(GltfErrors, TwoParentsAndCycles) {
  json d = valid_doc();
  d["nodes"] = json::parse(R"([{"children": [2]}, {"children": [2]}, {"mesh": 0}])");
  d["scenes"] = json::parse(R"([{"nodes": [0, 1]}])");
  expect_error(write("parents.gltf", d.dump()), {"node 2", "two parents"});
  d["nodes"] = json::parse(R"([{"children": [1]}, {"children": [2]}, {"children": [1]}])");
  d["scenes"] = json::parse(R"([{"nodes": [0]}])");
  expect_error(write("cycle.gltf", d.dump()), {"cycle"});
}

TEST(GltfErrors, NonFiniteAndDegenerateTransforms) {
  json d = valid_doc();
  d["nodes"][0]["translation"] = json::array({1e300, 0, 0});  // finite in JSON, Inf as a float
  expect_error(write("inf.gltf", d.dump()), {"node 0", "NaN or Inf"});
  d = valid_doc();
  d["nodes"][0]["matrix"] = json::array({0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1});  // zero scale
  expect_error(write("degenerate.gltf", d.dump()), {"node 0", "degenerate", "NaN or Inf"});
  d = valid_doc();
  d["nodes"][0]["rotation"] = json::array({0, 0, 0, 0});
  expect_error(write("rotation.gltf", d.dump()), {"node 0", "unit quaternion"});
}

/// A GLB holding valid_doc()'s JSON (with its data URI) and no BIN chunk.
std::vector<std::uint8_t> glb() {
  std::string text = valid_doc().dump();
  while (text.size() % 4 != 0) text += ' ';
  std::vector<std::uint8_t> out;
  auto u32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<std::uint8_t>(v >> (8 * i)));
  };
  u32(0x46546C67);
  u32(2);
  u32(static_cast<std::uint32_t>(20 + text.size()));
  u32(static_cast<std::uint32_t>(text.size()));
  u32(0x4E4F534A);
  out.insert(out.end(), text.begin(), text.end());
  return out;
}

TEST(GltfErrors, TruncatedGlb) {
  ASSERT_TRUE(engine::load_gltf(write_bytes("ok.glb", glb())).ok());
  const auto full = glb();
  expect_error(write_bytes("header.glb", {full.begin(), full.begin() + 8}), {"GLB header", "truncated"});
  expect_error(write_bytes("body.glb", {full.begin(), full.end() - 8}), {"GLB header", "truncated"});
  // Header length patched to match the cut file: now the chunk itself is cut.
  auto cut = std::vector<std::uint8_t>(full.begin(), full.end() - 8);
  const auto n = static_cast<std::uint32_t>(cut.size());
  std::memcpy(cut.data() + 8, &n, 4);
  expect_error(write_bytes("chunk.glb", cut), {"GLB chunk 0", "truncated chunk data"});
  auto bad_version = full;
  bad_version[4] = 1;
  expect_error(write_bytes("version.glb", bad_version), {"GLB version 1"});
}

TEST(GltfErrors, CorruptDracoData) {
  json d = valid_doc();
  // Buffer view 0 now holds garbage "compressed" data for the primitive.
  d["meshes"][0]["primitives"][0]["extensions"] = {
      {"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
  d["accessors"][0].erase("bufferView");
  d["accessors"][1].erase("bufferView");
  expect_error(write("draco.gltf", d.dump()), {"KHR_draco_mesh_compression", "corrupt or truncated Draco data"});
  d["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = 9;
  expect_error(write("draco_view.gltf", d.dump()), {"KHR_draco_mesh_compression", "out of range"});
}

/// A Draco mesh (one triangle) whose TEXCOORD_0 is stored as raw floats, `bad` at vertex 1.
std::vector<std::uint8_t> draco_triangle_with_uv(float bad) {
  draco::Mesh mesh;
  mesh.set_num_points(3);
  mesh.SetNumFaces(1);
  mesh.SetFace(draco::FaceIndex(0), {draco::PointIndex(0), draco::PointIndex(1), draco::PointIndex(2)});
  const auto add = [&mesh](draco::GeometryAttribute::Type type, int ncomp, const std::vector<float>& v) {
    draco::GeometryAttribute ga;
    ga.Init(type, nullptr, static_cast<std::uint8_t>(ncomp), draco::DT_FLOAT32, false,
            static_cast<std::int64_t>(sizeof(float)) * ncomp, 0);
    const int id = mesh.AddAttribute(ga, true, 3);
    for (std::uint32_t i = 0; i < 3; ++i)
      mesh.attribute(id)->SetAttributeValue(draco::AttributeValueIndex(i),
                                            v.data() + i * static_cast<std::uint32_t>(ncomp));
    return id;
  };
  add(draco::GeometryAttribute::POSITION, 3, {0, 0, 0, 1, 0, 0, 0, 1, 0});
  add(draco::GeometryAttribute::TEX_COORD, 2, {0, 0, bad, 0, 0, 1});
  draco::Encoder encoder;  // no quantization: the floats are stored as they are
  encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  draco::EncoderBuffer buffer;
  EXPECT_TRUE(encoder.EncodeMeshToBuffer(mesh, &buffer).ok());
  return {reinterpret_cast<const std::uint8_t*>(buffer.data()),
          reinterpret_cast<const std::uint8_t*>(buffer.data()) + buffer.size()};
}

// Found by fuzz_gltf's write-back check: a Draco attribute other than POSITION decoded to
// NaN was loaded as it was, write_gltf wrote it into a plain accessor, and the loader then
// refused its own output ("accessor 6: element 0 is not finite"). A Draco attribute is now
// checked like an accessor.
TEST(GltfErrors, DracoAttributeThatIsNotFinite) {
  const auto doc_for = [](const std::vector<std::uint8_t>& compressed) {
    json d = json::parse(R"({"asset": {"version": "2.0"},
      "extensionsUsed": ["KHR_draco_mesh_compression"], "extensionsRequired": ["KHR_draco_mesh_compression"],
      "accessors": [{"componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 0]},
                    {"componentType": 5126, "count": 3, "type": "VEC2"},
                    {"componentType": 5123, "count": 3, "type": "SCALAR"}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1}, "indices": 2,
        "extensions": {"KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0, "TEXCOORD_0": 1}}}}]}],
      "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0})");
    d["bufferViews"] = json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", compressed.size()}}});
    d["buffers"] = json::array(
        {{{"byteLength", compressed.size()}, {"uri", "data:application/octet-stream;base64," + base64(compressed)}}});
    return d.dump();
  };
  auto fine = engine::load_gltf(write("fine.gltf", doc_for(draco_triangle_with_uv(1.0f))));
  ASSERT_TRUE(fine.ok()) << fine.error().to_string();
  ASSERT_EQ(fine->meshes.at(0).primitives.at(0).uv0.size(), 3u);
  expect_error(write("nan.gltf", doc_for(draco_triangle_with_uv(std::numeric_limits<float>::quiet_NaN()))),
               {"KHR_draco_mesh_compression", "TEXCOORD_0", "element 1", "not finite"});
  expect_error(write("inf.gltf", doc_for(draco_triangle_with_uv(std::numeric_limits<float>::infinity()))),
               {"TEXCOORD_0", "element 1", "not finite"});
}

TEST(GltfErrors, AbsurdCountsHitTheLimits) {
  engine::GltfLoadOptions small;
  small.limits.max_vertices_per_primitive = 2;
  expect_error(write("limit.gltf", valid_doc().dump()), {"accessor 0", "exceeds the limit"}, small);
  small = {};
  small.limits.max_nodes = 0;
  expect_error(write("nodes.gltf", valid_doc().dump()), {"nodes", "exceed the limit"}, small);
  json d = valid_doc();
  d["accessors"][0]["count"] = 4000000000LL;
  expect_error(write("count.gltf", d.dump()), {"accessor 0"});
}

TEST(GltfErrors, InvalidLights) {
  json d = valid_doc();
  d["extensionsUsed"] = json::array({"KHR_lights_punctual"});
  d["extensions"] =
      json::parse(R"({"KHR_lights_punctual": {"lights": [{"type": "point"}, {"type": "point", "intensity": -1}]}})");
  expect_error(write("negative.gltf", d.dump()), {"light 1", "negative"});
  // Finite in the file, infinite as a float (the headless demo once wrote NaN/Inf frames).
  d["extensions"]["KHR_lights_punctual"]["lights"][1] = json::parse(R"({"type": "point", "intensity": 1e39})");
  expect_error(write("huge.gltf", d.dump()), {"light 1", "beyond any real light"});
  d["extensions"]["KHR_lights_punctual"]["lights"][1] =
      json::parse(R"({"type": "spot", "spot": {"innerConeAngle": 0.6, "outerConeAngle": 0.3}})");
  expect_error(write("cone.gltf", d.dump()), {"light 1", "innerConeAngle"});
  d["extensions"]["KHR_lights_punctual"]["lights"][1] = json::parse(R"({"type": "sphere"})");
  expect_error(write("type.gltf", d.dump()), {"light 1", "unknown light type 'sphere'"});
  d["extensions"]["KHR_lights_punctual"]["lights"][1] = json::parse(R"({"type": "point"})");
  d["nodes"][0]["extensions"] = {{"KHR_lights_punctual", {{"light", 0}}}};
  d["nodes"][0]["extras"] = json::parse(R"({"gi": {"area_light": {"size_m": [1, 1], "radiance": [1, 1, 1]}}})");
  expect_error(write("both.gltf", d.dump()), {"node 0", "both a KHR_lights_punctual light and a gi area_light"});
}

TEST(GltfErrors, GiExtrasWithWrongTypes) {
  json d = valid_doc();
  d["nodes"][0]["extras"] = json::parse(R"({"gi": {"mobility": "sometimes"}})");
  expect_error(write("mobility.gltf", d.dump()), {"node 0 extras.gi", "mobility"});
  d["nodes"][0]["extras"] = json::parse(R"({"gi": {"light_moves": "yes"}})");
  expect_error(write("moves.gltf", d.dump()), {"node 0 extras.gi", "light_moves"});
  d["nodes"][0]["extras"] = json::parse(R"({"gi": {"area_light": {"size_m": [1], "radiance": [1, 1, 1]}}})");
  expect_error(write("size.gltf", d.dump()), {"area_light", "size_m"});
  d["nodes"][0]["extras"] = json::parse(R"({"gi": {"area_light": {"size_m": [1, 1], "radiance": [1, -1, 1]}}})");
  expect_error(write("radiance.gltf", d.dump()), {"area_light", "negative"});
  d["nodes"][0]["extras"] = json::parse(R"({"gi": 3})");
  expect_error(write("gi.gltf", d.dump()), {"extras.gi", "must be an object"});
}

TEST(GltfErrors, WrongAccessorLayouts) {
  json d = valid_doc();
  d["accessors"][0]["componentType"] = 5121;  // unsigned byte POSITION without KHR_mesh_quantization
  d["accessors"][0]["count"] = 3;
  expect_error(write("layout.gltf", d.dump()), {"accessor 0", "not allowed for POSITION"});
  d = valid_doc();
  d["accessors"][1]["componentType"] = 5126;  // float indices
  expect_error(write("float_indices.gltf", d.dump()), {"accessor 1", "not a valid index accessor"});
  d = valid_doc();
  d["accessors"][0]["type"] = "VEC7";
  expect_error(write("type.gltf", d.dump()), {"accessor 0", "unknown or missing accessor type"});
}

TEST(GltfErrors, MaterialFactorsOutOfRange) {
  json d = valid_doc();
  d["materials"] = json::parse(R"([{"pbrMetallicRoughness": {"roughnessFactor": 2}}])");
  expect_error(write("rough.gltf", d.dump()), {"material 0", "roughnessFactor"});
  d["materials"] = json::parse(R"([{"extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": -2}}}])");
  expect_error(write("strength.gltf", d.dump()), {"material 0", "emissiveStrength"});
}

TEST(GltfErrors, TruncatedAndBitFlippedFilesNeverCrash) {
  // Deterministic corruption of a valid .glb and .gltf: every outcome must be a value or an
  // Error naming the file; a crash or an exception fails the whole test binary.
  std::mt19937 rng(12345);
  const std::vector<std::uint8_t> good_glb = glb();
  const std::string good_json = valid_doc().dump();
  int errors = 0;
  for (int i = 0; i < 300; ++i) {
    const bool binary = i % 2 == 0;
    std::vector<std::uint8_t> bytes = binary ? good_glb : std::vector<std::uint8_t>(good_json.begin(), good_json.end());
    if (i % 3 == 0) {
      bytes.resize(std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng));
    } else {
      for (int k = 0; k < 1 + i % 4; ++k) {
        const std::size_t at = std::uniform_int_distribution<std::size_t>(0, bytes.size() - 1)(rng);
        bytes[at] = static_cast<std::uint8_t>(rng());
      }
    }
    const fs::path p = write_bytes(binary ? "fuzz.glb" : "fuzz.gltf", bytes);
    auto r = engine::load_gltf(p);
    if (!r.ok()) {
      ++errors;
      EXPECT_EQ(r.error().file, p.string());
      EXPECT_FALSE(r.error().message.empty());
    }
  }
  EXPECT_GT(errors, 100);  // most corruptions are detected
}

}  // namespace

// Budgets across the whole file, not only per primitive: 64 primitives of 131070 zero
// vertices each (no bufferView, glTF §3.6.2.3) are 8.4 M elements no byte of the file pays for.
TEST(GltfErrors, AccessorBudgetsHoldAcrossPrimitives) {
  json d = valid_doc();
  d["accessors"].push_back({{"componentType", 5126}, {"count", 131070}, {"type", "VEC3"}});
  json prims = json::array();
  for (int i = 0; i < 64; ++i) prims.push_back({{"attributes", {{"POSITION", 2}}}});
  d["meshes"][0]["primitives"] = prims;
  expect_error(write("zeros.gltf", d.dump()), {"accessor 2", "without a bufferView", "budget"});

  // Every element counts towards the file's budget: 6 per primitive here, so 8 stops the second.
  engine::GltfLoadOptions small;
  small.limits.max_scene_elements = 8;
  json twice = valid_doc();
  twice["meshes"][0]["primitives"].push_back(twice["meshes"][0]["primitives"][0]);
  expect_error(write("twice.gltf", twice.dump()), {"budget of 8 elements"}, small);
  small.limits.max_scene_elements = 12;
  EXPECT_TRUE(engine::load_gltf(write("twice_ok.gltf", twice.dump()), small).ok());
}

// Images no material samples are not decoded: a broken one is no error and costs nothing.
TEST(GltfErrors, ImagesNoMaterialUsesAreNotDecoded) {
  json d = valid_doc();
  std::ofstream(dir() / "garbage.png") << "this is not a PNG";
  d["images"] = json::parse(R"([{"uri": "garbage.png"}])");
  d["textures"] = json::parse(R"([{"source": 0}])");
  auto r = engine::load_gltf(write("unused.gltf", d.dump()));
  ASSERT_TRUE(r.ok()) << r.error().to_string();
  ASSERT_EQ(r->images.size(), 1u);
  EXPECT_EQ(r->images[0].width, 0);
  EXPECT_TRUE(r->images[0].rgba8.empty());
}
