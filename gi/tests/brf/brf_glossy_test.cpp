// The glossy side of basis radiance fields (Iwasaki et al. §4.1, §5.1): SH rotation, the
// separable approximation of the GGX lobe, and glossy objects against the path tracer.
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include <unistd.h>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "brf/brdf_separation.h"
#include "brf/brf_bake.h"
#include "brf/brf_io.h"
#include "brf/brf_runtime.h"
#include "brf/spherical_harmonics.h"
#include "brf_scenes.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/reference_brdf.h"
#include "raytrace/reference_render.h"
#include "reference_scenes.h"
#include "transport/point_emitters.h"

namespace {

glm::vec3 random_direction(std::mt19937& rng) {
  std::normal_distribution<float> n;
  return glm::normalize(glm::vec3(n(rng), n(rng), n(rng)));
}

float evaluate(std::span<const float> c, const glm::vec3& w, int bands) {
  const auto y = gi::sh_basis(w);
  float s = 0.0f;
  for (int i = 0; i < bands * bands; ++i) s += c[static_cast<std::size_t>(i)] * y[static_cast<std::size_t>(i)];
  return s;
}

TEST(BrfShRotation, RotatedCoefficientsEvaluateTheRotatedFunction) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  float worst = 0.0f;
  for (int trial = 0; trial < 20; ++trial) {
    const glm::mat3 r = glm::mat3(glm::rotate(glm::mat4(1.0f), 3.0f * u(rng), random_direction(rng)));
    std::array<float, gi::kMaxShCoefficients> in{}, out{};
    for (float& c : in) c = u(rng);
    gi::ShRotation(r).apply(in, out, 4);
    for (int k = 0; k < 20; ++k) {
      const glm::vec3 w = random_direction(rng);
      worst = std::max(worst, std::abs(evaluate(out, w, 4) - evaluate(in, glm::transpose(r) * w, 4)));
    }
  }
  std::printf("worst pointwise difference %.2e\n", static_cast<double>(worst));
  EXPECT_LT(worst, 2e-5f);
}

TEST(BrfShRotation, TurnsTheClampedCosineOntoTheRotatedNormal) {
  const glm::vec3 n = glm::normalize(glm::vec3(0.2f, -0.5f, 0.8f));
  const glm::mat3 r = glm::mat3(glm::rotate(glm::mat4(1.0f), 1.1f, glm::normalize(glm::vec3(1.0f, 2.0f, -0.5f))));
  const auto lobe = gi::sh_clamped_cosine(n, 4);
  std::array<float, gi::kMaxShCoefficients> out{};
  gi::ShRotation(r).apply(lobe, out, 4);
  const auto expected = gi::sh_clamped_cosine(r * n, 4);
  for (std::size_t i = 0; i < out.size(); ++i) EXPECT_NEAR(out[i], expected[i], 1e-5f) << i;
}

TEST(BrfGlossySeparation, ErrorFallsWithTermsAndTheTableReproducesTheLobe) {
  float previous = 1.0f;
  for (int k : {1, 2, 4, 8, 15}) {
    const gi::BrdfSeparation s =
        gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.5f}, {.terms = k, .resolution = 16}).value();
    std::printf("alpha 0.5: K asked %2d -> %2d terms, weighted L2 error %.3f\n", k, s.terms,
                static_cast<double>(s.relative_error));
    EXPECT_GE(s.terms, k);
    EXPECT_LE(s.relative_error, previous);
    previous = s.relative_error;
  }
  EXPECT_LT(previous, 0.35f);
  // The reported error is the table's: evaluating g and h reproduces the lobe to about it.
  const gi::BrdfSeparation s =
      gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.8f}, {.terms = 15, .resolution = 16}).value();
  std::mt19937 rng(3);
  double err = 0.0, norm = 0.0;
  for (int i = 0; i < 4000; ++i) {
    glm::vec3 wi = random_direction(rng), wo = random_direction(rng);
    wi.z = std::abs(wi.z);
    wo.z = std::abs(wo.z);
    const double truth = static_cast<double>(gi::glossy_lobe_brdf(s.lobe, wi, wo) * wi.z * wo.z);
    const double ours = static_cast<double>(s.eval(wi, wo) * wi.z * wo.z);
    err += (ours - truth) * (ours - truth);
    norm += truth * truth;
  }
  std::printf("alpha 0.8, %d terms: table error %.3f at random directions (SVD's %.3f)\n", s.terms,
              std::sqrt(err / norm), static_cast<double>(s.relative_error));
  EXPECT_LT(std::sqrt(err / norm), 2.0 * static_cast<double>(s.relative_error) + 0.05);
}

TEST(BrfGlossySeparation, BadSettingsAreErrors) {
  EXPECT_FALSE(gi::separate_glossy_brdf({.f0 = 0.04f, .alpha = 0.0f}, {}).ok());
  EXPECT_FALSE(gi::separate_glossy_brdf({.f0 = 2.0f, .alpha = 0.5f}, {}).ok());
  EXPECT_FALSE(gi::separate_glossy_brdf({.f0 = 0.04f, .alpha = 0.5f}, {.terms = 0}).ok());
  EXPECT_FALSE(gi::separate_glossy_brdf({.f0 = 0.04f, .alpha = 0.5f}, {.terms = 16}).ok());
  EXPECT_FALSE(gi::separate_glossy_brdf({.f0 = 0.04f, .alpha = 0.5f}, {.resolution = 2}).ok());
}

// A glossy object baked with its separated lobe (or as diffuse when lobe is null).
struct Baked {
  gi::BrfMesh mesh;
  gi::BrfBasis basis;
  gi::BasisRadianceField field;
  Baked(gi::BrfMesh m, const gi::BrdfSeparation* glossy) : mesh(std::move(m)) {
    basis = gi::compute_pca_basis(mesh, {.lights = 256, .basis = 24}, glossy).value();
    field = gi::compute_basis_radiance_field(
                mesh, basis, {.spheres = 12, .face_resolution = 12, .sh_bands = 3, .directions = 512}, glossy)
                .value();
  }
};

gi::PointEmitter point_light(glm::vec3 p, float intensity) {
  gi::PointEmitter e;
  e.position = p;
  e.radiant = glm::vec3(intensity);
  return e;
}

double rel_rmse(std::span<const glm::vec3> ours, std::span<const glm::vec3> truth) {
  double err = 0.0, norm = 0.0;
  for (std::size_t j = 0; j < truth.size(); ++j) {
    const glm::dvec3 d = glm::dvec3(ours[j]) - glm::dvec3(truth[j]);
    err += glm::dot(d, d);
    norm += glm::dot(glm::dvec3(truth[j]), glm::dvec3(truth[j]));
  }
  return std::sqrt(err / norm);
}

// A glossy metal box under a low light beside a tall white box 25 cm away: the top face's
// glossy reflection lands on the white box's facing side. The white box's interreflected
// irradiance against the path tracer, with the lobe separated into K terms, against
// leaving the lobe out and against a diffuse stand-in of the same reflectance.
TEST(BrfGlossy, GlossySourceLightsItsNeighbourAsThePathTracerDoes) {
  const gi::GlossyLobe lobe{.f0 = 0.9f, .alpha = 0.5f};
  // glTF's metal (metallic 1): no diffuse lobe, a conductor lobe of reflectance f0.
  const glm::vec3 source_diffuse(0.0f), white(0.8f);
  const glm::mat4 m_source(1.0f);
  const glm::mat4 m_receiver = glm::translate(glm::mat4(1.0f), {0.75f, 0.0f, 0.0f});
  const gi::PointEmitter light = point_light({-1.0f, 0.9f, 0.0f}, 4.0f);
  const gi::BrfMesh source_mesh = brftest::box({0.3f, 0.3f, 0.3f}, 6),
                    receiver_mesh = brftest::box({0.2f, 0.8f, 0.4f}, 6);
  const Baked receiver(receiver_mesh, nullptr), diffuse_source(source_mesh, nullptr);

  gi::ReferenceScene ref;
  const auto add = [&](const gi::BrfMesh& mesh, const glm::mat4& m, const gi::ReferenceMaterial& mat) {
    reftest::add_geometry(ref, gi::RtGeometry{mesh.positions, mesh.indices}, mat);
    ref.geometry.instances.back().object_to_world = m;
  };
  gi::ReferenceMaterial metal;
  metal.brdf = engine::gltf_brdf(glm::vec3(lobe.f0), 1.0f, std::sqrt(lobe.alpha));
  add(source_mesh, m_source, metal);
  add(receiver_mesh, m_receiver, reftest::lambert(0.8f));
  gi::ReferenceLight l;
  l.position = light.position;
  l.radiant = light.radiant;
  ref.lights.push_back(l);
  std::vector<gi::SurfacePoint> points;
  for (std::size_t j = 0; j < receiver_mesh.positions.size(); ++j)
    points.push_back({glm::vec3(m_receiver * glm::vec4(receiver_mesh.positions[j], 1.0f)), receiver_mesh.normals[j]});
  gi::ReferenceSettings rs;
  rs.samples_per_pixel = 8192;
  const auto truth = gi::estimate_irradiance(ref, points, rs).value();

  const auto run = [&](const Baked& source, const gi::BrdfSeparation* glossy, glm::vec3 albedo) {
    gi::BrfObject objects[] = {{&source.mesh, &source.basis, &source.field, m_source, albedo},
                               {&receiver.mesh, &receiver.basis, &receiver.field, m_receiver, white}};
    objects[0].glossy = glossy;
    const gi::BrfResult r = gi::update_brf(objects, std::span<const gi::PointEmitter>(&light, 1), {.bounces = 3});
    return rel_rmse(std::span<const glm::vec3>(r.indirect[1]).first(receiver_mesh.positions.size()), truth.indirect);
  };
  // Diffuse stand-in: the lobe's hemispherical albedo added to the diffuse albedo.
  const double albedo = static_cast<double>(engine::gltf_hemispherical_albedo(metal.brdf).specular.x);
  const double none = run(diffuse_source, nullptr, source_diffuse);
  const double stand_in = run(diffuse_source, nullptr, source_diffuse + glm::vec3(static_cast<float>(albedo)));
  std::printf("receiver rel RMSE: glossy lobe left out %.3f, diffuse stand-in (albedo +%.2f) %.3f\n", none, albedo,
              stand_in);
  double k1 = 0.0, k4 = 0.0;
  for (int k : {1, 4}) {
    const gi::BrdfSeparation sep = gi::separate_glossy_brdf(lobe, {.terms = k, .resolution = 32}).value();
    const Baked source(source_mesh, &sep);
    const double e = run(source, &sep, source_diffuse);
    std::printf("receiver rel RMSE: %d glossy terms (BRDF error %.2f) %.3f\n", sep.terms,
                static_cast<double>(sep.relative_error), e);
    (k == 1 ? k1 : k4) = e;
  }
  EXPECT_LT(k4, 0.6 * k1);
  EXPECT_LT(k4, 0.6 * stand_in);
  EXPECT_LT(k4, 0.25);
}

// A white glossy box beside a red diffuse one, one bounce: the radiance the glossy box's
// facing side sends toward a viewer, against a brute-force integration over its hemisphere
// with the exact lobe (rays against the red box, whose radiance is its direct light's).
TEST(BrfGlossy, GlossyReceiverReflectsTowardTheViewerLikeTheExactLobe) {
  const gi::GlossyLobe lobe{.f0 = 0.9f, .alpha = 0.5f};
  const gi::BrdfSeparation sep = gi::separate_glossy_brdf(lobe, {.terms = 4, .resolution = 16}).value();
  const glm::vec3 red(0.8f, 0.1f, 0.1f), receiver_diffuse(0.1f);
  const glm::mat4 m_source = glm::translate(glm::mat4(1.0f), {-0.45f, 0.0f, 0.0f});
  // Turned, so the receiver's frames are not the world's.
  const glm::mat4 m_receiver =
      glm::rotate(glm::translate(glm::mat4(1.0f), {0.4f, 0.1f, 0.05f}), 0.3f, glm::vec3(0, 1, 0));
  const gi::PointEmitter light = point_light({-1.2f, 1.0f, 0.6f}, 4.0f);
  const Baked source(brftest::box({0.3f, 0.3f, 0.3f}, 6), nullptr),
      receiver(brftest::box({0.25f, 0.4f, 0.25f}, 6), &sep);
  gi::BrfObject objects[] = {{&source.mesh, &source.basis, &source.field, m_source, red},
                             {&receiver.mesh, &receiver.basis, &receiver.field, m_receiver, receiver_diffuse}};
  objects[1].glossy = &sep;
  const gi::BrfResult r = gi::update_brf(objects, std::span<const gi::PointEmitter>(&light, 1), {.bounces = 1});
  const gi::BrfWorldVertices v = gi::brf_world_vertices(objects[1]);

  gi::RtSceneData data;
  data.geometries.push_back({source.mesh.positions, source.mesh.indices});
  data.geometries.push_back({receiver.mesh.positions, receiver.mesh.indices});
  data.instances.push_back({0, m_source, false, 0});
  data.instances.push_back({1, m_receiver, false, 1});
  const auto caster = gi::make_embree_ray_caster(data).value();
  const glm::vec3 view = glm::normalize(glm::vec3(-0.2f, 0.6f, 1.0f));
  std::vector<glm::vec3> ours, truth, diffuse_only;
  constexpr int kRays = 4096;
  for (std::size_t j = 0; j < v.positions.size(); ++j) {
    if (glm::dot(v.normals[j], view) <= 0.1f || glm::dot(v.normals[j], glm::vec3(-1, 0, 0)) < 0.5f)
      continue;  // facing the red box
    const glm::mat3 to_local = glm::transpose(v.frames[j]);
    const glm::vec3 wo = to_local * view;
    glm::dvec3 sum(0.0);
    for (int i = 0; i < kRays; ++i) {
      const glm::vec3 w = gi::sample_cosine_hemisphere(v.normals[j], (static_cast<float>(i % 64) + 0.5f) / 64.0f,
                                                       (static_cast<float>(i / 64) + 0.5f) / 64.0f);
      const gi::Hit h = caster->intersect(gi::Ray{v.positions[j] + 1e-4f * v.normals[j], 0.0f, w});
      if (!h.valid() || h.instance != 0 || glm::dot(h.geometric_normal, w) >= 0.0f) continue;
      const glm::vec3 p = v.positions[j] + 1e-4f * v.normals[j] + h.t * w;
      const glm::vec3 n = glm::normalize(h.geometric_normal);
      if (!gi::emitter_visible(*caster, light, p, n)) continue;
      const glm::vec3 radiance = red * gi::emitter_irradiance(light, p, n, 0.0f) / std::numbers::pi_v<float>;
      const float f = receiver_diffuse.x / std::numbers::pi_v<float> + gi::glossy_lobe_brdf(lobe, to_local * w, wo);
      sum += glm::dvec3(radiance * f * std::numbers::pi_v<float>);  // f cos / pdf, pdf = cos / pi
    }
    truth.push_back(glm::vec3(sum / static_cast<double>(kRays)));
    const std::size_t nv = v.positions.size();
    std::vector<glm::vec3> e(nv * static_cast<std::size_t>(sep.terms + 1));
    for (std::size_t i = 0; i < e.size(); ++i) e[i] = r.indirect[1][i];
    ours.push_back(gi::brf_outgoing_radiance(objects[1], v, e, j, view));
    diffuse_only.push_back(receiver_diffuse * r.indirect[1][j] / std::numbers::pi_v<float>);
  }
  ASSERT_GT(truth.size(), 20u);
  const double err = rel_rmse(ours, truth), err_diffuse = rel_rmse(diffuse_only, truth);
  std::printf(
      "glossy receiver, %zu vertices: rel RMSE of the radiance toward the viewer %.3f (%d terms), %.3f with the "
      "diffuse part only\n",
      truth.size(), err, sep.terms, err_diffuse);
  EXPECT_LT(err, 0.5 * err_diffuse);
  EXPECT_LT(err, 0.3);
}

// Turning both glossy objects and the light together changes no term: the tangent frames
// come from object-space normals and turn with the objects.
TEST(BrfGlossy, RotatingEverythingTogetherChangesNoTerm) {
  const gi::BrdfSeparation sep =
      gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.5f}, {.terms = 4, .resolution = 16}).value();
  gi::BrfMesh a_mesh = brftest::box({0.3f, 0.3f, 0.3f}, 4), b_mesh = brftest::box({0.25f, 0.4f, 0.25f}, 4);
  const auto bake = [&](const gi::BrfMesh& m, gi::BrfBasis& basis, gi::BasisRadianceField& field) {
    basis = gi::compute_pca_basis(m, {.lights = 128, .basis = 12}, &sep).value();
    field = gi::compute_basis_radiance_field(m, basis, {.spheres = 6, .face_resolution = 6, .directions = 128}, &sep)
                .value();
  };
  gi::BrfBasis a_basis, b_basis;
  gi::BasisRadianceField a_field, b_field;
  bake(a_mesh, a_basis, a_field);
  bake(b_mesh, b_basis, b_field);
  const auto run = [&](const glm::mat4& world) {
    gi::BrfObject objects[] = {
        {&a_mesh, &a_basis, &a_field, world * glm::translate(glm::mat4(1.0f), {-0.45f, 0.0f, 0.0f}),
         glm::vec3(0.3f, 0.05f, 0.05f)},
        {&b_mesh, &b_basis, &b_field, world * glm::translate(glm::mat4(1.0f), {0.4f, 0.1f, 0.05f}), glm::vec3(0.2f)}};
    objects[0].glossy = objects[1].glossy = &sep;
    const gi::PointEmitter light = point_light(glm::vec3(world * glm::vec4(-1.2f, 1.0f, 0.6f, 1.0f)), 4.0f);
    return gi::update_brf(objects, std::span<const gi::PointEmitter>(&light, 1), {.bounces = 2});
  };
  const gi::BrfResult a = run(glm::mat4(1.0f));
  const gi::BrfResult b = run(glm::rotate(glm::mat4(1.0f), 0.9f, glm::normalize(glm::vec3(0.3f, 1.0f, -0.2f))));
  ASSERT_EQ(a.indirect[1].size(), b_mesh.positions.size() * static_cast<std::size_t>(sep.terms + 1));
  const double d = rel_rmse(b.indirect[1], a.indirect[1]), d0 = rel_rmse(b.indirect[0], a.indirect[0]);
  std::printf("rotation: relative difference over all terms %.2e / %.2e\n", d, d0);
  EXPECT_LT(d, 1e-3);
  EXPECT_LT(d0, 1e-3);
}

// A glossy mesh's bake file keeps the separation bit for bit, and a damaged table is
// rejected naming the problem.
TEST(BrfGlossy, BakeFileKeepsTheSeparationAndRejectsDamage) {
  gi::BrfSource source;
  source.name = "shade";
  source.mesh = brftest::box({0.2f, 0.1f, 0.2f}, 3);
  source.glossy = gi::GlossyLobe{.f0 = 0.3f, .alpha = 0.16f};
  source.mesh_hash = gi::brf_mesh_hash(source.mesh, source.glossy);
  EXPECT_NE(source.mesh_hash, gi::brf_mesh_hash(source.mesh));  // the lobe is part of what a bake depends on
  gi::BrfSettings settings = gi::brf_preset("preview").value();
  settings.field.spheres = 4;
  settings.field.face_resolution = 4;
  const gi::BrfMeshBake bake = gi::bake_brf_mesh(source, settings).value();
  ASSERT_TRUE(bake.model.glossy.has_value());
  EXPECT_GE(bake.model.glossy->terms, 4);
  EXPECT_EQ(bake.model.field.terms, bake.model.glossy->terms + 1);
  const std::filesystem::path dir =
      std::filesystem::path(GI_BINARY_DIR) / "test_output" / ("brf_glossy_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "brf_shade.bin";
  ASSERT_TRUE(gi::write_brf_mesh(file, bake).ok());
  const gi::BrfMeshBake back = gi::read_brf_mesh(file).value();
  ASSERT_TRUE(back.model.glossy.has_value());
  EXPECT_EQ(back.model.glossy->terms, bake.model.glossy->terms);
  EXPECT_EQ(back.model.glossy->g, bake.model.glossy->g);
  EXPECT_EQ(back.model.glossy->h, bake.model.glossy->h);
  EXPECT_EQ(back.model.glossy->lobe_sh, bake.model.glossy->lobe_sh);
  EXPECT_EQ(back.model.field.coefficients, bake.model.field.coefficients);
  EXPECT_EQ(back.model.basis.terms, bake.model.basis.terms);

  gi::BrfMeshBake bad = bake;
  bad.model.glossy->h[3] = std::numeric_limits<float>::quiet_NaN();
  const auto written = gi::write_brf_mesh(dir / "brf_bad.bin", bad);
  ASSERT_FALSE(written.ok());
  EXPECT_NE(written.error().message.find("glossy separation value"), std::string::npos) << written.error().to_string();
  EXPECT_FALSE(std::filesystem::exists(dir / "brf_bad.bin"));
  bad = bake;
  bad.model.glossy.reset();  // a field of 1 + K terms without its separation
  const auto mismatch = gi::write_brf_mesh(dir / "brf_bad.bin", bad);
  ASSERT_FALSE(mismatch.ok());
  EXPECT_NE(mismatch.error().message.find("BRDF terms disagree"), std::string::npos) << mismatch.error().to_string();
  std::filesystem::remove_all(dir);
}

}  // namespace

namespace {

// The truncated separation does not keep the lobe's directional albedo (what a uniform
// environment reflects toward w_o); albedo_corrected_h rescales h per outgoing direction.
TEST(BrfGlossySeparation, AlbedoCorrectedLobesReflectAUniformEnvironmentExactly) {
  const gi::BrdfSeparation sep =
      gi::separate_glossy_brdf({.f0 = 0.9f, .alpha = 0.25f}, {.terms = 4, .resolution = 16}).value();
  gi::BrdfSeparation corrected = sep;
  corrected.h = sep.albedo_corrected_h();
  ASSERT_EQ(corrected.h.size(), sep.h.size());
  constexpr int kN = 200;  // a different rule from the correction's (64 x 64)
  for (float deg : {5.0f, 18.0f, 30.0f, 49.0f, 65.0f}) {
    const float t = deg * std::numbers::pi_v<float> / 180.0f;
    // Rotated about z so that w_o lies off the table's cell centres.
    const glm::vec3 wo(std::sin(t) * 0.8f, std::sin(t) * 0.6f, std::cos(t));
    double exact = 0.0, separated = 0.0, fixed = 0.0;
    for (int a = 0; a < kN; ++a)
      for (int b = 0; b < kN; ++b) {
        const float z = (static_cast<float>(a) + 0.5f) / kN, r = std::sqrt(1.0f - z * z);
        const float phi = 2.0f * std::numbers::pi_v<float> * (static_cast<float>(b) + 0.5f) / kN;
        const glm::vec3 wi(r * std::cos(phi), r * std::sin(phi), z);
        const double w = 2.0 * std::numbers::pi / (kN * kN) * double{z};
        exact += w * double{gi::glossy_lobe_brdf(sep.lobe, wi, wo)};
        separated += w * double{sep.eval(wi, wo)};
        fixed += w * double{corrected.eval(wi, wo)};
      }
    std::printf("%.0f deg: directional albedo exact %.4f, separated %.4f, corrected %.4f\n", double{deg}, exact,
                separated, fixed);
    EXPECT_NEAR(fixed / exact, 1.0, 0.04) << deg;
    if (deg == 18.0f || deg == 49.0f) {
      EXPECT_GT(std::abs(separated / exact - 1.0), 0.1) << deg;  // what it fixes
    }
  }
}

}  // namespace
