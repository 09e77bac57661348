// Material inputs of the renderer: sRGB base-colour textures, metallic-roughness channels,
// emission, double-sided materials.
#include <cmath>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

engine::Image solid_image(std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  engine::Image img;
  img.width = 2;
  img.height = 2;
  for (int i = 0; i < 4; ++i) img.rgba8.insert(img.rgba8.end(), {r, g, b, 255});
  return img;
}

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

struct TexturedPlane {
  engine::SceneAsset assets;
  engine::Registry reg;
  TestCamera cam{{0.0f, 3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};

  engine::ImageRgbaF render(const engine::Material& m, bool point_light) {
    assets.materials.push_back(m);
    assets.meshes.push_back(plane_mesh(10.0f, 0));
    add_mesh(reg, 0, glm::mat4(1.0f));
    if (point_light)
      add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = 10.0f}, {0, 2, 0}, {0, 0, 0});
    engine::Entity camera = cam.add_to(reg);
    auto r = make_renderer(assets, cam.size, 0.0f);
    if (!r) return {};
    r->render(reg, camera);
    return r->read_hdr();
  }
};

TEST(RendererMaterials, BaseColorTextureIsDecodedFromSrgb) {
  engine::GpuContext ctx = headless_context();
  TexturedPlane s;
  s.assets.images.push_back(solid_image(188, 188, 188));
  engine::Material m = diffuse_material(1.0f);
  m.base_color = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  m.base_color_texture.image = 0;
  const engine::ImageRgbaF img = s.render(m, true);
  const float albedo = 0.8f * srgb_to_linear(188.0f / 255.0f);  // ~0.40
  const int c = s.cam.size / 2;
  const float expected = reference_point_light(albedo, 1.0f, {0, 0, 0}, s.cam.eye, {0, 2, 0}, 10.0f);
  EXPECT_NEAR(red(img, c, c), expected, 0.015f * expected);
}

TEST(RendererMaterials, MetallicRoughnessTextureUsesBlueAndGreen) {
  engine::GpuContext ctx = headless_context();
  TexturedPlane s;
  // G = roughness 0.5 (x factor 1), B = metallic 1 (x factor 1): a rough metal of base 0.9.
  s.assets.images.push_back(solid_image(0, 128, 255));
  engine::Material m = diffuse_material(0.9f, 1.0f, 1.0f);
  m.metallic_roughness_texture.image = 0;
  const engine::ImageRgbaF img = s.render(m, true);
  const int c = s.cam.size / 2;
  const float roughness = 128.0f / 255.0f;
  const float expected = 10.0f / 4.0f * reference_brdf_cos(0.9f, 1.0f, roughness, {0, 1, 0}, {0, 1, 0}, {0, 1, 0});
  EXPECT_NEAR(red(img, c, c), expected, 0.02f * expected);
}

TEST(RendererMaterials, EmissionIsAddedAsRadiance) {
  engine::GpuContext ctx = headless_context();
  TexturedPlane s;
  engine::Material m = diffuse_material(0.5f);
  m.emissive = glm::vec3(2.0f, 1.0f, 0.5f);
  const engine::ImageRgbaF img = s.render(m, false);
  const int c = s.cam.size / 2;
  const std::size_t i =
      (static_cast<std::size_t>(c) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(c)) * 4;
  EXPECT_NEAR(img.pixels[i + 0], 2.0f, 2e-3f);
  EXPECT_NEAR(img.pixels[i + 1], 1.0f, 1e-3f);
  EXPECT_NEAR(img.pixels[i + 2], 0.5f, 1e-3f);
}

TEST(RendererMaterials, SingleSidedBackFacesAreCulledDoubleSidedAreShaded) {
  engine::GpuContext ctx = headless_context();
  for (bool double_sided : {false, true}) {
    engine::SceneAsset assets;
    engine::Material m = diffuse_material(0.5f);
    m.emissive = glm::vec3(1.0f);
    m.double_sided = double_sided;
    assets.materials.push_back(m);
    assets.meshes.push_back(plane_mesh(10.0f, 0));
    engine::Registry reg;
    add_mesh(reg, 0, glm::mat4(1.0f));
    TestCamera cam{{0.0f, -3.0f, 0.0f}, {0.0f, 0.0f, 0.0f}};  // below the plane: sees its back
    engine::Entity camera = cam.add_to(reg);
    auto r = make_renderer(assets, cam.size, 0.0f);
    ASSERT_NE(r, nullptr);
    r->render(reg, camera);
    const engine::ImageRgbaF img = r->read_hdr();
    EXPECT_NEAR(red(img, cam.size / 2, cam.size / 2), double_sided ? 1.0f : 0.0f, 1e-3f)
        << "double_sided " << double_sided;
  }
}

TEST(RendererCreate, MalformedMeshIsAnErrorNotACrash) {
  engine::GpuContext ctx = headless_context();
  engine::SceneAsset assets;
  assets.source = "bad.gltf";
  assets.meshes.push_back(plane_mesh(1.0f, -1));
  assets.meshes[0].primitives[0].indices.push_back(99);  // out of range, and count not a multiple of 3
  assets.meshes[0].primitives[0].indices.push_back(0);
  assets.meshes[0].primitives[0].indices.push_back(1);
  engine::RenderSettings settings;
  settings.width = 16;
  settings.height = 16;
  auto r = engine::Renderer::create(assets, settings);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().file, "bad.gltf");
  EXPECT_EQ(r.error().location, "meshes[0].primitives[0]");
  EXPECT_NE(r.error().message.find("99"), std::string::npos) << r.error().to_string();

  engine::SceneAsset bad_image;
  bad_image.materials.push_back(diffuse_material(0.5f));
  bad_image.materials[0].base_color_texture.image = 3;  // no images
  bad_image.meshes.push_back(plane_mesh(1.0f, 0));
  auto r2 = engine::Renderer::create(bad_image, settings);
  ASSERT_FALSE(r2.ok());
  EXPECT_EQ(r2.error().location, "materials[0].baseColorTexture");
}

}  // namespace
