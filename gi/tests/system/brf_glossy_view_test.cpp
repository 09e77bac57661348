// A metal crate beside the crates room's wall, drawn by the engine's forward renderer with the
// GI system's basis radiance fields: its view-dependent indirect light (the glossy terms
// sum_k h_k E_k, IndirectLightFrame::vertex_radiance_lobes) on screen from two view angles,
// against the reference path tracer's indirect light at the same points seen from the same
// eyes. llvmpipe through EGL; never skipped.
#define GL_GLEXT_PROTOTYPES 1
#include <unistd.h>
#include <GL/glcorearb.h>
#include <gtest/gtest.h>
#include <engine/components.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/image.h>
#include <engine/renderer.h>
#include <engine/scene.h>
#include <gi/gi_system.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "brf/brdf_separation.h"
#include "brf/brf_bake.h"
#include "brf/brf_io.h"
#include "brf/brf_mesh.h"
#include "core/random.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/path_tracer.h"
#include "raytrace/reference_scene.h"
#include "raytrace/scene_adapter.h"
#include "transport/static_scene.h"

namespace {

constexpr int kWidth = 256, kHeight = 192;
// The metal crate (silver, roughness 0.5) stands 20 cm from the white wall x = 3; its -z face
// (z = -0.55), perpendicular to the wall, is looked at.
constexpr glm::vec3 kCratePosition{2.55f, 0.0f, -0.3f};
constexpr float kFaceZ = -0.55f;

engine::Scene metal_crate_room() {
  auto asset = engine::load_gltf(GI_SOURCE_DIR "/assets/crates_room.gltf").value();
  for (engine::Material& m : asset.materials)
    if (m.name == "crate_red") m.base_color = glm::vec4(0.9f, 0.9f, 0.9f, 1.0f), m.metallic = 1.0f, m.roughness = 0.5f;
  engine::Scene scene = engine::instantiate(std::move(asset));
  const engine::Entity crate = engine::find_by_name(scene.registry, "crate_red");
  scene.registry.write<engine::Transform>(crate).position = kCratePosition;
  engine::update_world_transforms(scene.registry);
  return scene;
}

void place_camera(engine::Scene& scene, const glm::vec3& eye, const glm::vec3& target) {
  const engine::Entity camera = engine::find_camera(scene.registry);
  const glm::mat4 to_world = glm::inverse(glm::lookAt(eye, target, glm::vec3(0.0f, 1.0f, 0.0f)));
  engine::Transform& t = scene.registry.write<engine::Transform>(camera);
  t.position = eye;
  t.rotation = glm::quat_cast(glm::mat3(to_world));
  engine::update_world_transforms(scene.registry);
}

// The GI system's frame with every member but the per-vertex radiance lobes: what the
// renderer drew before they existed (the specular lobe's share of the irradiance).
struct WithoutLobes final : engine::IndirectLightProvider {
  struct Frame final : engine::IndirectLightFrame {
    const engine::IndirectLightFrame* inner = nullptr;
    engine::SsboHandle<engine::VertexIrradiance> vertex_irradiance_buffer(engine::Entity e) const override {
      return inner->vertex_irradiance_buffer(e);
    }
  };
  engine::IndirectLightProvider* gi = nullptr;
  Frame frame_;
  const engine::IndirectLightFrame& frame() override {
    const engine::IndirectLightFrame& f = gi->frame();
    static_cast<engine::IndirectLightFrame&>(frame_) = f;
    frame_.inner = &f;
    return frame_;
  }
  const char* label() const override { return "without lobes"; }
  std::span<const engine::AtlasMesh> atlas_meshes() const override { return gi->atlas_meshes(); }
};

glm::vec3 pixel(const engine::ImageRgbaF& img, int x, int y) {
  const std::size_t i =
      4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x));
  return {img.pixels[i], img.pixels[i + 1], img.pixels[i + 2]};
}

struct View {
  const char* name;
  glm::vec3 eye;
};

struct ViewResult {
  glm::dvec3 drawn{0.0}, without_lobes{0.0}, reference{0.0};  // sums over the face's points
  double rel_rmse = 0.0;                                      // drawn vs reference, per point
};

TEST(BrfGlossyView, TheMetalCratesViewDependentBounceIsDrawnAsThePathTracerSeesIt) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx) << "no headless GL context: " << ctx.error().to_string();
  engine::Scene scene = metal_crate_room();

  // Bundle: light atlas (preview) for the world probes + BRF (preview; the metal crate glossy).
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("brf_glossy_view_" + std::to_string(::getpid()) + ".gibake");
  std::filesystem::remove_all(dir);
  std::optional<gi::BrdfSeparation> separation;  // the metal crate's lobe, for the CPU twin below
  {
    const gi::LightAtlasBake atlas =
        gi::bake_light_atlas(gi::bake_input_from(scene), gi::light_atlas_preset("preview").value()).value();
    ASSERT_TRUE(gi::save_light_atlas(dir, atlas, gi::bake_input_from(scene.assets)));
    gi::BrfBake brf;
    brf.settings = gi::brf_preset("preview").value();
    const std::vector<gi::BrfSource> sources = gi::dynamic_brf_meshes(gi::bake_input_from(scene)).value();
    for (const gi::BrfSource& src : sources) {
      brf.meshes.push_back(gi::bake_brf_mesh(src, brf.settings).value());
      EXPECT_EQ(brf.meshes.back().model.glossy.has_value(), src.name == "crate_red") << src.name;
      if (src.name == "crate_red") {
        separation = brf.meshes.back().model.glossy;
        separation->h = separation->albedo_corrected_h();  // the table the renderer draws with
      }
    }
    ASSERT_TRUE(gi::save_brf(dir, brf, gi::bake_input_from(scene.assets)));
  }
  auto loaded = gi::GISystem::load(dir, scene);
  std::filesystem::remove_all(dir);
  ASSERT_TRUE(loaded) << loaded.error().to_string();
  gi::GISystem& gi = **loaded;
  const engine::Entity crate = engine::find_by_name(scene.registry, "crate_red");
  (void)gi.frame();
  const engine::IndirectLightFrame::VertexRadianceLobes lobes = gi.frame().vertex_radiance_lobes(crate);
  ASSERT_GT(lobes.terms, 0);
  EXPECT_NE(lobes.coefficient_buffer.gl_name, 0u);
  EXPECT_EQ(gi.frame().vertex_radiance_lobes(engine::find_by_name(scene.registry, "crate_2")).terms, 0);

  auto renderer = engine::Renderer::create(scene.assets, {.width = kWidth, .height = kHeight});
  ASSERT_TRUE(renderer) << renderer.error().to_string();
  engine::Renderer& r = **renderer;
  r.settings().stand_in_ambient = 0.0f;
  WithoutLobes without;
  without.gi = &gi;

  // The reference: radiance along the camera ray to each point, all bounces minus direct.
  const gi::ReferenceScene ref = gi::reference_scene_from(gi::bake_input_from(scene));
  const gi::ReferenceSceneIndex index = gi::index_reference_scene(ref).value();
  const auto caster = gi::make_embree_ray_caster(ref.geometry).value();
  const gi::PathTracer full(ref, index, *caster, {.max_bounces = -1});
  const gi::PathTracer direct(ref, index, *caster, {.max_bounces = 0});
  constexpr int kSamples = 2048;

  // The irradiance under the drawn term: the face centre's vertex against the path tracer.
  ASSERT_TRUE(separation.has_value());
  const engine::MeshRenderer& mr = scene.registry.get<engine::MeshRenderer>(crate);
  const gi::BrfMesh mesh = gi::brf_mesh_from_input(gi::bake_input_from(scene.assets), mr.mesh).value();
  std::size_t centre = 0;
  for (std::size_t j = 0; j < mesh.positions.size(); ++j)
    if (glm::length(mesh.positions[j] - glm::vec3(0, 0.25f, -0.25f)) <
        glm::length(mesh.positions[centre] - glm::vec3(0, 0.25f, -0.25f)))
      centre = j;
  const std::size_t nv = mesh.positions.size();
  std::vector<glm::vec4> terms(nv * static_cast<std::size_t>(1 + lobes.terms));
  glGetNamedBufferSubData(lobes.coefficient_buffer.gl_name, 0,
                          static_cast<GLsizeiptr>(terms.size() * sizeof(glm::vec4)), terms.data());
  {
    std::vector<glm::vec4> v(mesh.positions.size() * 2);
    glGetNamedBufferSubData(gi.frame().vertex_irradiance_buffer(crate).gl_name, 0,
                            static_cast<GLsizeiptr>(v.size() * sizeof(glm::vec4)), v.data());
    glm::dvec3 e(0.0);
    for (int s = 0; s < 4096; ++s) {
      gi::Pcg32 rng = gi::Pcg32::for_item(3, static_cast<std::uint64_t>(s));
      e += glm::dvec3(full.irradiance(glm::vec3(kCratePosition.x, 0.25f, kFaceZ - 1e-3f), {0, 0, -1}, rng).indirect);
    }
    e /= 4096.0;
    const glm::dvec3 at(mesh.positions[centre]), brf(v[centre]);
    std::printf(
        "metal face centre (vertex %zu at %.2f %.2f %.2f): indirect irradiance BRF (%.3f, %.3f, %.3f), path "
        "tracer (%.3f, %.3f, %.3f) W/m^2\n",
        centre, at.x, at.y, at.z, brf.x, brf.y, brf.z, e.x, e.y, e.z);
  }

  // Two eyes at the face's height: 49 degrees off its normal away from the wall (the mirror
  // direction runs into the wall beside the crate) and 16 degrees off it from beside the wall
  // (the mirror direction runs along the room).
  const std::vector<View> views = {{"view A", {1.0f, 0.3f, -1.9f}}, {"view B", {2.9f, 0.3f, -1.6f}}};
  std::vector<ViewResult> results;
  for (const View& view : views) {
    const glm::vec3 face_centre(kCratePosition.x, 0.25f, kFaceZ);
    place_camera(scene, view.eye, face_centre);
    r.set_indirect_light(nullptr);
    r.render(scene.registry, engine::find_camera(scene.registry));
    const engine::ImageRgbaF direct_img = r.read_hdr();
    r.set_indirect_light(&gi);
    r.render(scene.registry, engine::find_camera(scene.registry));
    const engine::ImageRgbaF drawn_img = r.read_hdr();
    if (const char* out = std::getenv("GI_TEST_IMAGE_DIR")) {
      (void)engine::save_png(std::string(out) + "/brf_glossy_view_" + std::to_string(results.size()) + ".png",
                             r.read_ldr());
    }
    r.set_indirect_light(&without);
    r.render(scene.registry, engine::find_camera(scene.registry));
    const engine::ImageRgbaF without_img = r.read_hdr();

    const engine::Camera& cam = scene.registry.get<engine::Camera>(engine::find_camera(scene.registry));
    const float aspect = cam.aspect > 0.0f ? cam.aspect : static_cast<float>(kWidth) / static_cast<float>(kHeight);
    const glm::mat4 view_proj = glm::perspective(cam.yfov_rad, aspect, cam.znear_m, cam.zfar_m) *
                                glm::lookAt(view.eye, face_centre, glm::vec3(0.0f, 1.0f, 0.0f));
    // The engine's evaluation against its CPU twin at the face centre's vertex (the crate is
    // not turned: its frame is brf_tangent_frame of the object-space normal).
    {
      const glm::vec3 at = kCratePosition + mesh.positions[centre];
      const glm::vec3 local =
          glm::transpose(gi::brf_tangent_frame(mesh.normals[centre])) * glm::normalize(view.eye - at);
      glm::vec3 expected(0.0f);
      for (int k = 0; k < lobes.terms; ++k)
        expected += glm::vec3(terms[static_cast<std::size_t>(k + 1) * nv + centre]) * separation->h_at(k, local);
      const glm::vec4 clip = view_proj * glm::vec4(at, 1.0f);
      const int x = static_cast<int>(std::floor((clip.x / clip.w * 0.5f + 0.5f) * kWidth));
      const int y = static_cast<int>(std::floor((0.5f - 0.5f * clip.y / clip.w) * kHeight));
      const glm::vec3 got = pixel(drawn_img, x, y) - pixel(direct_img, x, y);
      std::printf("%s: face centre, lobes toward the eye: CPU twin (%.4f, %.4f, %.4f), drawn (%.4f, %.4f, %.4f)\n",
                  view.name, double{expected.x}, double{expected.y}, double{expected.z}, double{got.x}, double{got.y},
                  double{got.z});
      // The metal has no diffuse lobe: what is drawn is the lobes' radiance (measured 0.5%).
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 0.02f * expected[c] + 1e-4f) << view.name;
      EXPECT_GT(expected.x, 0.0f);
    }
    ViewResult res;
    double err2 = 0.0, ref2 = 0.0;
    int points = 0;
    for (int a = -2; a <= 2; ++a)
      for (int b = -2; b <= 2; ++b) {
        const glm::vec3 p(kCratePosition.x + 0.075f * static_cast<float>(a), 0.25f + 0.075f * static_cast<float>(b),
                          kFaceZ);
        const glm::vec4 clip = view_proj * glm::vec4(p, 1.0f);
        const glm::vec2 ndc = glm::vec2(clip) / clip.w;
        const int x = static_cast<int>(std::floor((ndc.x * 0.5f + 0.5f) * kWidth));
        const int y = static_cast<int>(std::floor((0.5f - 0.5f * ndc.y) * kHeight));
        ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight) << view.name;
        // The pixel centre's ray, as the rasterizer shades it.
        const float px = 2.0f * (static_cast<float>(x) + 0.5f) / kWidth - 1.0f;
        const float py = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / kHeight;
        const glm::mat4 cam_to_world = glm::inverse(glm::lookAt(view.eye, face_centre, glm::vec3(0.0f, 1.0f, 0.0f)));
        const float th = std::tan(0.5f * cam.yfov_rad);
        const glm::vec3 ray_dir = glm::normalize(glm::mat3(cam_to_world) * glm::vec3(px * th * aspect, py * th, -1.0f));
        glm::dvec3 indirect(0.0);
        for (int s = 0; s < kSamples; ++s) {
          gi::Pcg32 rng = gi::Pcg32::for_item(7, static_cast<std::uint64_t>(points * kSamples + s));
          indirect += glm::dvec3(full.radiance(gi::Ray{view.eye, 0.0f, ray_dir}, rng));
          gi::Pcg32 rng_d = gi::Pcg32::for_item(7, static_cast<std::uint64_t>(points * kSamples + s));
          indirect -= glm::dvec3(direct.radiance(gi::Ray{view.eye, 0.0f, ray_dir}, rng_d));
        }
        indirect /= static_cast<double>(kSamples);
        const glm::dvec3 drawn = glm::dvec3(pixel(drawn_img, x, y) - pixel(direct_img, x, y));
        const glm::dvec3 old = glm::dvec3(pixel(without_img, x, y) - pixel(direct_img, x, y));
        for (int c = 0; c < 3; ++c) {
          EXPECT_TRUE(std::isfinite(drawn[c]) && drawn[c] >= -1e-4) << view.name << " point " << points;
          err2 += (drawn[c] - indirect[c]) * (drawn[c] - indirect[c]);
          ref2 += indirect[c] * indirect[c];
        }
        res.drawn += drawn;
        res.without_lobes += old;
        res.reference += indirect;
        ++points;
      }
    res.rel_rmse = std::sqrt(err2 / std::max(ref2, 1e-30));
    std::printf(
        "%s: indirect radiance summed over %d points of the metal face (W/(m^2 sr)): path tracer (%.4f, %.4f, "
        "%.4f), drawn with lobes (%.4f, %.4f, %.4f), without (%.4f, %.4f, %.4f); per-point rel RMSE %.3f\n",
        view.name, points, res.reference.x, res.reference.y, res.reference.z, res.drawn.x, res.drawn.y, res.drawn.z,
        res.without_lobes.x, res.without_lobes.y, res.without_lobes.z, res.rel_rmse);
    results.push_back(res);
  }
  const auto sum = [](const glm::dvec3& v) { return v.x + v.y + v.z; };
  const double ref_ratio = sum(results[0].reference) / sum(results[1].reference);
  const double drawn_ratio = sum(results[0].drawn) / sum(results[1].drawn);
  const double old_ratio = sum(results[0].without_lobes) / sum(results[1].without_lobes);
  std::printf("view A / view B: path tracer %.3f, drawn %.3f, without lobes %.3f\n", ref_ratio, drawn_ratio, old_ratio);
  // Against the path tracer (measured: face sums 0.87x / 1.23x, per-point rel RMSE 0.14 / 0.23,
  // view ratio 0.76 against 1.07; the direction-less specular share of E: 0.99x / 1.05x, 0.97;
  // with the separation's own h instead of the albedo-corrected table 0.71x / 1.42x, 0.54).
  // The rest is the truncated separation's shape and the probes' 3-band E_k (docs/brf.md).
  // Bounds: each view's face within 0.75-1.35x the path tracer, per point below 0.3 rel RMSE,
  // the A / B change within 35% of the path tracer's, and the drawn term changing with the
  // view where the direction-less share does not.
  for (const ViewResult& res : results) {
    EXPECT_GT(sum(res.drawn) / sum(res.reference), 0.75);
    EXPECT_LT(sum(res.drawn) / sum(res.reference), 1.35);
    EXPECT_LT(res.rel_rmse, 0.3);
  }
  EXPECT_NEAR(drawn_ratio / ref_ratio, 1.0, 0.35);
  EXPECT_GT(std::abs(drawn_ratio - old_ratio), 0.1);
}

}  // namespace
