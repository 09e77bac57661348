// The one BRDF (engine/gltf_brdf.h): its GLSL twin evaluated on the GPU agrees with the C++
// on a grid of materials and angles; its albedo table against independent integration; its
// energy behaviour, including where glTF's fresnel_mix reflects more than it receives.
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <engine/gltf_brdf.h>
#include <engine/gpu/context.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gltf_brdf_texture.h>
#include <engine/gpu/shader_program.h>

namespace {

constexpr float kPi = std::numbers::pi_v<float>;

glm::vec3 direction(float theta_deg, float phi_deg) {
  const float t = glm::radians(theta_deg), p = glm::radians(phi_deg);
  return {std::sin(t) * std::cos(p), std::sin(t) * std::sin(p), std::cos(t)};
}

// One evaluation: the material's factors, a frame and two directions (std430, 96 bytes).
struct Case {
  glm::vec4 base_metallic;   // rgb base colour, a metallic
  glm::vec4 specular_color;  // rgb specularColorFactor, a specularFactor
  glm::vec4 n_roughness;     // xyz normal, w roughness
  glm::vec4 v;
  glm::vec4 l;
  glm::vec4 pad;
};
static_assert(sizeof(Case) == 96);

// What the shader writes per case (std430, 64 bytes).
struct Out {
  glm::vec4 diffuse;  // xyz, w = gltf_diffuse_weight(v.h)
  glm::vec4 specular;
  glm::vec4 albedo_diffuse;  // gltf_directional_albedo at n.v
  glm::vec4 albedo_specular;
};
static_assert(sizeof(Out) == 64);

constexpr const char* kTwinShader = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "gltf_brdf.glsl"
struct Case { vec4 base_metallic; vec4 specular_color; vec4 n_roughness; vec4 v; vec4 l; vec4 pad; };
struct Out { vec4 diffuse; vec4 specular; vec4 albedo_diffuse; vec4 albedo_specular; };
layout(std430, binding = 0) readonly buffer Cases { Case cases[]; };
layout(std430, binding = 1) writeonly buffer Outs { Out outs[]; };
layout(location = 0) uniform uint u_count;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  Case c = cases[i];
  GltfBrdf m = gltf_brdf(c.base_metallic.rgb, c.base_metallic.w, c.n_roughness.w, c.specular_color.w, c.specular_color.rgb);
  vec3 n = c.n_roughness.xyz;
  GltfBrdfValue f = gltf_eval_cos(m, n, c.v.xyz, c.l.xyz);
  vec3 h = normalize(c.v.xyz + c.l.xyz);
  GltfBrdfValue a = gltf_directional_albedo(m, dot(n, c.v.xyz));
  outs[i].diffuse = vec4(f.diffuse, gltf_diffuse_weight(m, dot(c.v.xyz, h)));
  outs[i].specular = vec4(f.specular, 0.0);
  outs[i].albedo_diffuse = vec4(a.diffuse, 0.0);
  outs[i].albedo_specular = vec4(a.specular, 0.0);
}
)glsl";

float rel_diff(const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 d = glm::abs(a - b);
  const float scale = std::max({std::fabs(b.x), std::fabs(b.y), std::fabs(b.z), 1e-3f});
  return std::max({d.x, d.y, d.z}) / scale;
}

TEST(GltfBrdf, GlslTwinAgreesWithTheCppOnAGridOfMaterialsAndAngles) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx.ok()) << ctx.error().to_string();

  std::vector<Case> cases;
  const glm::vec3 bases[] = {{0.9f, 0.5f, 0.1f}, {1.0f, 1.0f, 1.0f}};
  const glm::vec3 spec_colors[] = {{1.0f, 1.0f, 1.0f}, {2.0f, 0.5f, 0.1f}};
  for (float roughness : {0.0f, 0.05f, 0.2f, 0.5f, 0.8f, 1.0f})
    for (float metallic : {0.0f, 0.3f, 1.0f})
      for (float weight : {0.0f, 0.5f, 1.0f})
        for (const glm::vec3& sc : spec_colors)
          for (const glm::vec3& base : bases)
            for (float tv : {0.0f, 30.0f, 60.0f, 85.0f, 89.9f})
              for (float tl : {0.0f, 20.0f, 45.0f, 80.0f, 95.0f})
                for (float pl : {0.0f, 90.0f, 180.0f}) {
                  Case c{};
                  c.base_metallic = glm::vec4(base, metallic);
                  c.specular_color = glm::vec4(sc, weight);
                  c.n_roughness = glm::vec4(0.0f, 0.0f, 1.0f, roughness);
                  c.v = glm::vec4(direction(tv, 0.0f), 0.0f);
                  c.l = glm::vec4(direction(tl, pl), 0.0f);
                  cases.push_back(c);
                }

  const engine::ShaderFile twin{"gltf_brdf_twin.comp.glsl", "tests/engine/gltf_brdf_test.cpp", kTwinShader};
  auto program = engine::ShaderProgramBuilder(std::span<const engine::ShaderFile>(&twin, 1))
                     .add_files(engine::engine_shader_files())
                     .stage(engine::ShaderStage::Compute, "gltf_brdf_twin.comp.glsl")
                     .build();
  ASSERT_TRUE(program.ok()) << program.error().to_string();
  engine::GlBuffer in = engine::GlBuffer::create(cases.size() * sizeof(Case), cases.data());
  engine::GlBuffer out = engine::GlBuffer::create(cases.size() * sizeof(Out), nullptr);
  engine::GlTexture table = engine::upload_gltf_albedo_table();
  program->use();
  glUniform1ui(0, static_cast<GLuint>(cases.size()));
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
  glBindTextureUnit(engine::kGltfAlbedoTableUnit, table.id());
  glDispatchCompute(static_cast<GLuint>((cases.size() + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<Out> gpu(cases.size());
  glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(gpu.size() * sizeof(Out)), gpu.data());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  float worst_eval = 0.0f, worst_eval_mirror = 0.0f, worst_albedo = 0.0f;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const engine::GltfBrdf m = engine::gltf_brdf(glm::vec3(c.base_metallic), c.base_metallic.w, c.n_roughness.w,
                                                 c.specular_color.w, glm::vec3(c.specular_color));
    const glm::vec3 n(c.n_roughness), v(c.v), l(c.l);
    const engine::GltfBrdfValue f = engine::gltf_eval_cos(m, n, v, l);
    const engine::GltfBrdfValue a = engine::gltf_directional_albedo(m, glm::dot(n, v));
    const float w = engine::gltf_diffuse_weight(m, glm::dot(v, glm::normalize(v + l)));
    const float e = std::max({rel_diff(glm::vec3(gpu[i].diffuse), f.diffuse),
                              rel_diff(glm::vec3(gpu[i].specular), f.specular), std::fabs(gpu[i].diffuse.w - w)});
    const float ea = std::max(rel_diff(glm::vec3(gpu[i].albedo_diffuse), a.diffuse),
                              rel_diff(glm::vec3(gpu[i].albedo_specular), a.specular));
    // Near-mirror lobes (roughness at the clamp) are ill-conditioned in float: D's peak
    // a^-2 / pi turns one ulp of n.h into a percent.
    const bool mirror = c.n_roughness.w < 0.1f;
    (mirror ? worst_eval_mirror : worst_eval) = std::max(mirror ? worst_eval_mirror : worst_eval, e);
    worst_albedo = std::max(worst_albedo, ea);
    const float tolerance = mirror ? 1e-2f : 2e-4f;
    if (e > tolerance || ea > 2e-4f) {
      ADD_FAILURE() << "case " << i << " (roughness " << c.n_roughness.w << ", metallic " << c.base_metallic.w
                    << ", specular " << c.specular_color.w << "): eval differs by " << e << ", albedo by " << ea;
      break;
    }
  }
  std::printf(
      "%zu cases: worst relative difference GLSL vs C++: BRDF %.2e (roughness < 0.1: %.2e), directional albedo %.2e\n",
      cases.size(), static_cast<double>(worst_eval), static_cast<double>(worst_eval_mirror),
      static_cast<double>(worst_albedo));
}

TEST(GltfBrdf, IsReciprocal) {
  for (float roughness : {0.05f, 0.3f, 1.0f})
    for (float metallic : {0.0f, 0.5f, 1.0f}) {
      const engine::GltfBrdf m = engine::gltf_brdf({0.8f, 0.4f, 0.2f}, metallic, roughness);
      for (float ta : {10.0f, 40.0f, 75.0f})
        for (float tb : {0.0f, 35.0f, 80.0f}) {
          const glm::vec3 n(0, 0, 1), a = direction(ta, 0.0f), b = direction(tb, 130.0f);
          const glm::vec3 fab = engine::gltf_eval_cos(m, n, a, b).sum() / b.z;
          const glm::vec3 fba = engine::gltf_eval_cos(m, n, b, a).sum() / a.z;
          EXPECT_LT(rel_diff(fab, fba), 1e-4f) << "roughness " << roughness << " metallic " << metallic;
        }
    }
}

// The directional albedo of the table against a fine midpoint integration of
// gltf_eval_cos over the hemisphere (uniform in theta_l and phi, weight sin(theta_l)), at
// table nodes so that interpolation does not enter: the table's quadrature is checked, not
// assumed. At grazing views the lobe is narrow in phi, hence the many azimuths.
TEST(GltfBrdf, AlbedoTableMatchesIndependentIntegration) {
  const int n_theta = 400, n_phi = 4800;
  for (int j : {8, 31}) {  // roughness 0.29, 1
    const float r = engine::kGltfMinRoughness + (1.0f - engine::kGltfMinRoughness) * static_cast<float>(j) / 31.0f;
    for (int i : {3, 12, 22, 31}) {
      const float x = static_cast<float>(i) / 31.0f;
      const float mu_v = x * x;
      const glm::vec3 v(std::sqrt(1.0f - mu_v * mu_v), 0.0f, mu_v);
      for (float metallic : {0.0f, 1.0f}) {
        const engine::GltfBrdf m = engine::gltf_brdf(glm::vec3(0.7f), metallic, r);
        double sum = 0.0;
        for (int a = 0; a < n_theta; ++a) {
          const float theta = 0.5f * kPi * (static_cast<float>(a) + 0.5f) / n_theta;
          const float s = std::sin(theta), c = std::cos(theta);
          for (int b = 0; b < n_phi; ++b) {
            const float phi = 2.0f * kPi * (static_cast<float>(b) + 0.5f) / n_phi;
            const glm::vec3 l(s * std::cos(phi), s * std::sin(phi), c);
            sum += static_cast<double>(engine::gltf_eval_cos(m, {0, 0, 1}, v, l).sum().x * s);
          }
        }
        const double integral = sum * std::numbers::pi * std::numbers::pi / (n_theta * n_phi);
        const double table = engine::gltf_directional_albedo(m, mu_v).sum().x;
        EXPECT_NEAR(table, integral, 2e-3) << "roughness " << r << " cos_v " << mu_v << " metallic " << metallic;
      }
    }
  }
}

// Smooth limit: a near-mirror's specular albedo is Schlick's F at the view angle.
TEST(GltfBrdf, SmoothLimitIsSchlicksFresnelAtTheViewAngle) {
  for (float mu : {0.3f, 0.6f, 1.0f}) {
    const glm::vec4 abp = engine::gltf_albedo_integrals(mu, engine::kGltfMinRoughness * engine::kGltfMinRoughness);
    EXPECT_NEAR(abp.x, 1.0f, 1e-3f);
    EXPECT_NEAR(abp.y, std::pow(1.0f - mu, 5.0f), 1e-3f);
  }
}

// A white Lambertian reflects all; a metal never reflects more than it receives, at any
// roughness and angle (single-scattering GGX loses energy, most at roughness 1).
TEST(GltfBrdf, LambertianIsExactAndMetalsNeverGainEnergy) {
  EXPECT_NEAR(engine::gltf_hemispherical_albedo(engine::gltf_lambertian(glm::vec3(1.0f))).sum().x, 1.0f, 1e-6f);
  for (int j = 0; j <= 20; ++j) {
    const float r = 0.05f + 0.95f * static_cast<float>(j) / 20.0f;
    const engine::GltfBrdf metal = engine::gltf_brdf(glm::vec3(1.0f), 1.0f, r);
    for (int i = 0; i <= 40; ++i) {
      const float mu = std::max(static_cast<float>(i) / 40.0f, 1e-3f);
      EXPECT_LE(engine::gltf_directional_albedo(metal, mu).sum().x, 1.0f + 2e-3f) << "roughness " << r << " cos " << mu;
    }
    EXPECT_LE(engine::gltf_hemispherical_albedo(metal).sum().x, 1.0f + 1e-3f);
  }
}

// glTF's fresnel_mix weights the diffuse lobe by 1 - F(v.h) for every l, which does not
// account for what the specular lobe reflects at grazing views: a white dielectric
// reflects up to 1.8x what it receives there when smooth (the specification says its
// coupling "breaks energy conservation", Appendix B "Coupling Diffuse and Specular
// Reflection"). The model is kept as specified (docs/brdf.md); this test pins where it
// holds: within 0.5% of 1 up to 45 degrees at any roughness, and a gain below 4% at every
// angle when rough.
TEST(GltfBrdf, FresnelMixConservesEnergyExceptAtGrazingViewsOfSmoothDielectrics) {
  for (int j = 0; j <= 20; ++j) {
    const float r = 0.05f + 0.95f * static_cast<float>(j) / 20.0f;
    const engine::GltfBrdf white = engine::gltf_brdf(glm::vec3(1.0f), 0.0f, r);
    for (int i = 0; i <= 40; ++i) {
      const float mu = std::max(static_cast<float>(i) / 40.0f, 1e-3f);
      const float albedo = engine::gltf_directional_albedo(white, mu).sum().x;
      if (mu >= std::cos(glm::radians(45.0f))) {
        EXPECT_LE(albedo, 1.005f) << "roughness " << r << " cos " << mu;
      }
      if (r >= 0.85f) {
        EXPECT_LE(albedo, 1.04f) << "roughness " << r << " cos " << mu;
      }
    }
  }
  const engine::GltfBrdf smooth = engine::gltf_brdf(glm::vec3(1.0f), 0.0f, 0.1f);
  EXPECT_GT(engine::gltf_directional_albedo(smooth, std::cos(glm::radians(85.0f))).sum().x, 1.4f);
  EXPECT_NEAR(engine::gltf_hemispherical_albedo(smooth).sum().x, 1.042f, 0.003f);
}

}  // namespace
