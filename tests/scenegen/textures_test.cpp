// The generated textures (tools/gi-scenegen/textures.h): deterministic, tileable sizes,
// plausible albedos, alpha holes in the wire mesh, and the demo level's materials use them.
#include "textures.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <nlohmann/json.hpp>

#include "scenes.h"
#include "world_triangles.h"

namespace {

struct Named {
  const char* name;
  engine::Image (*make)();
};
const Named kTextures[] = {{"brick", scenegen::brick_texture},
                           {"wood_planks", scenegen::wood_planks_texture},
                           {"tartan_fabric", scenegen::tartan_fabric_texture},
                           {"wire_mesh", scenegen::wire_mesh_texture}};

float luminance(glm::vec3 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

TEST(SceneTextures, SrgbEncodingIsTheStandardOneAndRoundTrips) {
  // IEC 61966-2-1: code 128 is 0.21586 linear, code 10 is 10/255/12.92 (linear segment).
  EXPECT_NEAR(scenegen::srgb8_to_linear(128), 0.2158605f, 1e-6f);
  EXPECT_FLOAT_EQ(scenegen::srgb8_to_linear(10), 10.0f / 255.0f / 12.92f);
  EXPECT_EQ(scenegen::srgb8_to_linear(255), 1.0f);
  for (int c = 0; c < 256; ++c)
    EXPECT_EQ(scenegen::linear_to_srgb8(scenegen::srgb8_to_linear(static_cast<std::uint8_t>(c))), c);
}

TEST(SceneTextures, SameBytesEveryTimeInPowerOfTwoRgba) {
  for (const Named& t : kTextures) {
    const engine::Image a = t.make(), b = t.make();
    EXPECT_EQ(a.name, t.name);
    EXPECT_TRUE(a.rgba8 == b.rgba8) << t.name;
    EXPECT_EQ(a.width, a.height) << t.name;
    EXPECT_TRUE(a.width >= 64 && a.width <= 256 && (a.width & (a.width - 1)) == 0) << t.name << " " << a.width;
    EXPECT_EQ(a.rgba8.size(), static_cast<std::size_t>(a.width) * static_cast<std::size_t>(a.height) * 4) << t.name;
  }
}

TEST(SceneTextures, MeanAlbedosArePhysicallyPlausible) {
  // Real brick, wood and dyed cloth reflect 10-60% of light; no surface here is darker than
  // 0.1 or brighter than 0.8 on average (luminance), and no channel's mean exceeds 0.8.
  for (const Named& t : kTextures) {
    const glm::vec3 mean = scenegen::mean_linear_rgb(t.make(), 128);  // the opaque texels
    EXPECT_GE(luminance(mean), 0.1f) << t.name;
    EXPECT_LE(luminance(mean), 0.8f) << t.name;
    for (int c = 0; c < 3; ++c) EXPECT_LE(mean[c], 0.8f) << t.name << " channel " << c;
  }
  // The brick is strongly red: what it reflects onto a light floor must look red.
  const glm::vec3 brick = scenegen::mean_linear_rgb(scenegen::brick_texture());
  EXPECT_GT(brick.x, 2.0f * brick.y) << brick.x << " " << brick.y;
  EXPECT_GT(brick.x, 3.0f * brick.z) << brick.x << " " << brick.z;
  EXPECT_GT(brick.x, 0.3f);
}

TEST(SceneTextures, OnlyTheWireMeshHasHoles) {
  const engine::Image mesh = scenegen::wire_mesh_texture();
  const float holes = scenegen::transparent_fraction(mesh, 0.5f);
  EXPECT_GE(holes, 0.3f);
  EXPECT_LE(holes, 0.6f);
  // Mostly fully open or fully closed; partial alpha only along the wires' edges.
  std::size_t partial = 0;
  for (std::size_t i = 3; i < mesh.rgba8.size(); i += 4) partial += (mesh.rgba8[i] != 0 && mesh.rgba8[i] != 255);
  EXPECT_LT(static_cast<float>(partial) / static_cast<float>(mesh.rgba8.size() / 4), 0.35f);
  for (const Named& t : kTextures) {
    if (std::string(t.name) != "wire_mesh") {
      EXPECT_EQ(scenegen::transparent_fraction(t.make(), 0.999f), 0.0f) << t.name;
    }
  }
}

TEST(SceneTextures, TilesWithoutASeam) {
  // Across the wrap (last column to first, last row to first) the texture changes no more
  // than somewhere between neighbours inside it (a joint, a thread's edge): REPEAT shows
  // no seam of its own.
  for (const Named& t : kTextures) {
    const engine::Image img = t.make();
    const int n = img.width;
    auto at = [&](int x, int y, int c) {
      return static_cast<int>(img.rgba8[static_cast<std::size_t>((y * n + x) * 4 + c)]);
    };
    auto step = [&](int x0, int x1, bool columns) {
      double sum = 0.0;
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
          sum += std::abs(columns ? at(x0, i, c) - at(x1, i, c) : at(i, x0, c) - at(i, x1, c));
      return sum / (3.0 * n);
    };
    double max_cols = 0.0, max_rows = 0.0;
    for (int x = 0; x + 1 < n; ++x) {
      max_cols = std::max(max_cols, step(x, x + 1, true));
      max_rows = std::max(max_rows, step(x, x + 1, false));
    }
    EXPECT_LE(step(n - 1, 0, true), max_cols + 1.0) << t.name;
    EXPECT_LE(step(n - 1, 0, false), max_rows + 1.0) << t.name;
  }
}

// The material of the first primitive of the mesh drawn by node `name`.
const engine::Material& material_of(const engine::SceneAsset& s, const std::string& name, int primitive = 0) {
  const int node = scenegen_test::find_node(s, name);
  GI_EXPECTS(node >= 0, "the scene has the node");
  const engine::Mesh& mesh = s.meshes[static_cast<std::size_t>(s.nodes[static_cast<std::size_t>(node)].mesh)];
  return s.materials[static_cast<std::size_t>(mesh.primitives[static_cast<std::size_t>(primitive)].material)];
}

TEST(SceneTextures, TheDemoLevelUsesThem) {
  const engine::SceneAsset demo = scenegen::demo_level();
  auto image_of = [&](const engine::Material& m) -> const engine::Image& {
    EXPECT_TRUE(m.base_color_texture.present()) << m.name;
    return demo.images.at(static_cast<std::size_t>(m.base_color_texture.image));
  };
  // The hub's west wall is brick (its own primitive in the hub mesh), white factor.
  const int hub = scenegen_test::find_node(demo, "hub");
  ASSERT_GE(hub, 0);
  bool brick_wall = false;
  for (const engine::Primitive& p :
       demo.meshes[static_cast<std::size_t>(demo.nodes[static_cast<std::size_t>(hub)].mesh)].primitives) {
    const engine::Material& m = demo.materials[static_cast<std::size_t>(p.material)];
    if (!m.base_color_texture.present()) continue;
    EXPECT_EQ(image_of(m).name, "brick");
    EXPECT_EQ(m.base_color, glm::vec4(1.0f)) << "the texture carries the colour";
    for (const glm::vec3& pos : p.positions) EXPECT_EQ(pos.x, 0.0f) << "only the west wall (x = 0)";
    brick_wall = true;
  }
  EXPECT_TRUE(brick_wall);
  EXPECT_EQ(image_of(material_of(demo, "lamp_room_floor")).name, "wood_planks");
  EXPECT_EQ(image_of(material_of(demo, "hub_rug")).name, "tartan_fabric");
  const engine::Material& grille = material_of(demo, "crate_room_grille");
  EXPECT_EQ(image_of(grille).name, "wire_mesh");
  EXPECT_EQ(grille.alpha_mode, engine::AlphaMode::Mask);
  EXPECT_FLOAT_EQ(grille.alpha_cutoff, 0.5f);
  EXPECT_TRUE(grille.double_sided);
  // Every textured primitive has TEXCOORD_0 at 1 texture repeat per metre: a 1 m edge spans 1 in uv.
  for (const engine::Mesh& m : demo.meshes)
    for (const engine::Primitive& p : m.primitives) {
      if (p.material < 0 || !demo.materials[static_cast<std::size_t>(p.material)].base_color_texture.present())
        continue;
      ASSERT_EQ(p.uv0.size(), p.positions.size()) << m.name;
      for (std::size_t i = 0; i + 2 < p.indices.size(); i += 3) {
        const std::uint32_t a = p.indices[i], b = p.indices[i + 1];
        EXPECT_NEAR(glm::length(p.uv0[b] - p.uv0[a]),
                    glm::length(p.positions[b] - p.positions[a]) / scenegen::kTextureTileM, 1e-4f)
            << m.name;
      }
    }
}

TEST(SceneTextures, TheNewSurfacesNeverBlockWalking) {
  // The collision world keeps wall-like triangles (|n.y| < 0.7) of static meshes; the rug
  // and the grille must be horizontal so the recorded play sessions replay unchanged.
  const engine::SceneAsset demo = scenegen::demo_level();
  for (const char* name : {"hub_rug", "crate_room_grille"}) {
    const int node = scenegen_test::find_node(demo, name);
    ASSERT_GE(node, 0) << name;
    for (const engine::Primitive& p :
         demo.meshes[static_cast<std::size_t>(demo.nodes[static_cast<std::size_t>(node)].mesh)].primitives)
      for (const glm::vec3& n : p.normals) EXPECT_GE(std::abs(n.y), 0.99f) << name;
  }
}

TEST(SceneTextures, CommittedImagesStaySmall) {
  // The PNGs are embedded twice (demo_level.bin and demo_level.draco.glb); they must not
  // bloat the repository: at most 300 KB per copy (about 210 KB today).
  std::ifstream in(std::filesystem::path(GI_SOURCE_DIR) / "assets" / "demo_level.gltf");
  const nlohmann::json doc = nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
  std::size_t bytes = 0;
  for (const nlohmann::json& image : doc.at("images"))
    bytes += doc.at("bufferViews").at(image.at("bufferView").get<std::size_t>()).at("byteLength").get<std::size_t>();
  EXPECT_EQ(doc.at("images").size(), 4u);
  EXPECT_LE(bytes, 300u * 1024u);
}

}  // namespace
