// Specular reflection of per-bin directional radiance (engine/directional_radiance.h): the
// GLSL twin (engine/shaders/directional_radiance.glsl) evaluated on the GPU agrees with the C++
// on a grid of materials, views and random radiance, the data in the packed layout the
// renderer reads (RGB halves with a per-bin scale); with global bins and with tangent-frame
// bins (a hemisphere set in the frame directional_tangent_frame of the normal).
#define GL_GLEXT_PROTOTYPES
#include <GL/glcorearb.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>
#include <glm/gtc/packing.hpp>

#include <engine/directional_radiance.h>
#include <engine/gltf_brdf.h>
#include <engine/gpu/context.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/gltf_brdf_texture.h>
#include <engine/gpu/shader_program.h>

namespace {

struct Case {
  glm::vec4 base_metallic;  // rgb base colour, a metallic
  glm::vec4 n_roughness;    // xyz normal, w roughness
  glm::vec4 v;              // xyz view, w = element index (as float)
};
static_assert(sizeof(Case) == 48);

constexpr const char* kTwinShader = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "gltf_brdf.glsl"
#include "directional_radiance.glsl"
struct Case { vec4 base_metallic; vec4 n_roughness; vec4 v; };
layout(std430, binding = 0) readonly buffer Cases { Case cases[]; };
layout(std430, binding = 1) writeonly buffer Outs { vec4 outs[]; };
layout(location = 0) uniform uint u_count;
layout(location = 1) uniform int u_bins;
layout(location = 2) uniform int u_elements;
layout(location = 3) uniform int u_tangent;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  Case c = cases[i];
  GltfBrdf m = gltf_brdf(c.base_metallic.rgb, c.base_metallic.w, c.n_roughness.w, 1.0, vec3(1.0));
  outs[i] = vec4(directional_specular(m, c.n_roughness.xyz, c.v.xyz, int(c.v.w), u_bins, u_elements, u_tangent != 0,
                                      c.n_roughness.xyz),
                 0.0);
}
)glsl";

// A Fibonacci set of n directions.
std::vector<glm::vec3> fibonacci(int n) {
  std::vector<glm::vec3> d;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
    d.emplace_back(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
  }
  return d;
}

// n directions on the hemisphere z > 0, equal areas (as gi::dlm_hemisphere_directions).
std::vector<glm::vec3> hemisphere(int n) {
  std::vector<glm::vec3> d;
  const double golden = std::numbers::pi * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (i + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
    d.emplace_back(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z));
  }
  return d;
}

// The GPU against the C++ on every case; `tangent`: 64 tangent-frame bins, else 32 global ones.
void twin_agrees(bool tangent) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx.ok()) << ctx.error().to_string();
  const int bins = tangent ? 64 : 32, elements = 5;
  const std::vector<glm::vec3> dirs = tangent ? hemisphere(bins) : fibonacci(bins);
  // Radiance per (bin, element): random over four decades, some bins empty; stored as the
  // renderer reads it (halves / a power-of-two scale per bin), and the C++ gets the decoded values.
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<glm::uvec2> packed(static_cast<std::size_t>(bins * elements));
  std::vector<glm::vec4> dir_buffer(static_cast<std::size_t>(bins));
  std::vector<std::vector<glm::vec3>> decoded(static_cast<std::size_t>(elements), std::vector<glm::vec3>(bins));
  for (int k = 0; k < bins; ++k) {
    const float scale = std::ldexp(1.0f, -4 + k % 5);
    dir_buffer[static_cast<std::size_t>(k)] = glm::vec4(dirs[static_cast<std::size_t>(k)], scale);
    for (int e = 0; e < elements; ++e) {
      glm::vec3 l(std::pow(10.0f, 4.0f * u(rng) - 2.0f), std::pow(10.0f, 4.0f * u(rng) - 2.0f),
                  std::pow(10.0f, 4.0f * u(rng) - 2.0f));
      if ((k + e) % 7 == 0) l = glm::vec3(0.0f);
      const glm::vec3 h = l / scale;
      packed[static_cast<std::size_t>(k * elements + e)] =
          glm::uvec2(glm::packHalf2x16(glm::vec2(h.x, h.y)), glm::packHalf2x16(glm::vec2(h.z, 0.0f)));
      const glm::vec2 rg = glm::unpackHalf2x16(packed[static_cast<std::size_t>(k * elements + e)].x);
      const float b = glm::unpackHalf2x16(packed[static_cast<std::size_t>(k * elements + e)].y).x;
      decoded[static_cast<std::size_t>(e)][static_cast<std::size_t>(k)] = glm::vec3(rg, b) * scale;
    }
  }
  std::vector<Case> cases;
  const glm::vec3 normals[] = {{0, 1, 0}, glm::normalize(glm::vec3(0.3f, 0.9f, -0.2f)), {1, 0, 0}};
  for (const glm::vec3& n : normals)
    for (float roughness : {0.045f, 0.15f, 0.3f, 0.6f})
      for (float metallic : {0.0f, 1.0f})
        for (float cos_v : {1.0f, 0.7f, 0.3f, 0.05f})
          for (float phi : {0.0f, 2.0f})
            for (int e = 0; e < elements; ++e) {
              glm::vec3 t =
                  glm::normalize(glm::cross(n, std::fabs(n.x) > 0.9f ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0)));
              const glm::vec3 b = glm::cross(n, t);
              const float s = std::sqrt(1.0f - cos_v * cos_v);
              const glm::vec3 v = glm::normalize(cos_v * n + s * (std::cos(phi) * t + std::sin(phi) * b));
              cases.push_back({glm::vec4(0.8f, 0.5f, 0.2f, metallic), glm::vec4(n, roughness),
                               glm::vec4(v, static_cast<float>(e))});
            }

  const engine::ShaderFile twin{"directional_twin.comp.glsl", "tests/engine/directional_radiance_test.cpp",
                                kTwinShader};
  auto program = engine::ShaderProgramBuilder(std::span<const engine::ShaderFile>(&twin, 1))
                     .add_files(engine::engine_shader_files())
                     .stage(engine::ShaderStage::Compute, "directional_twin.comp.glsl")
                     .build();
  ASSERT_TRUE(program.ok()) << program.error().to_string();
  engine::GlBuffer in = engine::GlBuffer::create(cases.size() * sizeof(Case), cases.data());
  engine::GlBuffer out = engine::GlBuffer::create(cases.size() * sizeof(glm::vec4), nullptr);
  engine::GlBuffer radiance = engine::GlBuffer::create(packed.size() * sizeof(glm::uvec2), packed.data());
  engine::GlBuffer directions = engine::GlBuffer::create(dir_buffer.size() * sizeof(glm::vec4), dir_buffer.data());
  engine::GlTexture table = engine::upload_gltf_albedo_table();
  program->use();
  glUniform1ui(0, static_cast<GLuint>(cases.size()));
  glUniform1i(1, bins);
  glUniform1i(2, elements);
  glUniform1i(3, tangent ? 1 : 0);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, radiance.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, directions.id());
  glBindTextureUnit(engine::kGltfAlbedoTableUnit, table.id());
  glDispatchCompute(static_cast<GLuint>((cases.size() + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<glm::vec4> gpu(cases.size());
  glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(gpu.size() * sizeof(glm::vec4)), gpu.data());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  float worst = 0.0f;
  std::size_t nonzero = 0, on_boundary = 0;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    const engine::GltfBrdf m =
        engine::gltf_brdf(glm::vec3(c.base_metallic), c.base_metallic.w, c.n_roughness.w, 1.0f, glm::vec3(1.0f));
    const auto e = static_cast<std::size_t>(c.v.w);
    const glm::vec3 n(c.n_roughness);
    const glm::vec3* bin_normal = tangent ? &n : nullptr;
    const glm::vec3 cpu = engine::directional_specular(m, n, glm::vec3(c.v), dirs, decoded[e], bin_normal);
    const glm::vec3 g(gpu[i]);
    const float scale = std::max({cpu.x, cpu.y, cpu.z, 1e-6f});
    const float d = std::max({std::fabs(g.x - cpu.x), std::fabs(g.y - cpu.y), std::fabs(g.z - cpu.z)}) / scale;
    worst = std::max(worst, d);
    nonzero += scale > 1e-6f;
    ASSERT_TRUE(std::isfinite(g.x) && std::isfinite(g.y) && std::isfinite(g.z)) << i;
    // A lobe sample within float rounding of a boundary between two bins may fall on either
    // side in the GPU's arithmetic: such cases (the C++ changes under a 1e-4 move of v) are
    // counted, not compared.
    bool boundary = false;
    for (const glm::vec3 dv : {glm::vec3(1e-4f, 0, 0), glm::vec3(0, 0, 1e-4f), glm::vec3(0, 1e-4f, 0)}) {
      const glm::vec3 moved =
          engine::directional_specular(m, n, glm::normalize(glm::vec3(c.v) + dv), dirs, decoded[e], bin_normal);
      for (int ch = 0; ch < 3; ++ch) boundary = boundary || std::fabs(moved[ch] - cpu[ch]) > 1e-2f * scale;
    }
    if (boundary) {
      ++on_boundary;
      continue;
    }
    if (d > 1e-3f) {
      ADD_FAILURE() << "case " << i << " (roughness " << c.n_roughness.w << ", cos_v "
                    << glm::dot(glm::vec3(c.v), glm::vec3(c.n_roughness)) << "): GPU (" << g.x << ", " << g.y << ", "
                    << g.z << ") vs C++ (" << cpu.x << ", " << cpu.y << ", " << cpu.z << ")";
      break;
    }
  }
  EXPECT_GT(nonzero, cases.size() / 2);
  // 32 lobe samples (engine::kDirectionalLobeSamples): twice the chances of 16 that one lies on a boundary.
  EXPECT_LT(on_boundary, cases.size() / 25);
  std::printf("%s bins: %zu cases (%zu on a bin boundary skipped): worst relative difference GLSL vs C++ %.2e\n",
              tangent ? "tangent-frame" : "global", cases.size(), on_boundary, static_cast<double>(worst));
}

TEST(DirectionalRadiance, GlslTwinAgreesWithTheCpp) { twin_agrees(false); }

// Tangent-frame bins: the lobe samples turned into the frame of the normal, on the GPU as in
// the C++ (one frame function, engine::directional_tangent_frame and its GLSL twin), also at
// the normal (1, 0, 0) where the frame's first axis switches.
TEST(DirectionalRadiance, GlslTwinAgreesWithTheCppForTangentFrameBins) { twin_agrees(true); }

constexpr const char* kSearchShader = R"glsl(#version 450 core
layout(local_size_x = 64) in;
#include "gltf_brdf.glsl"
#include "directional_radiance.glsl"
layout(std430, binding = 0) readonly buffer Probes { vec4 probes[]; };
layout(std430, binding = 1) writeonly buffer Bins { ivec2 bins[]; };
layout(location = 0) uniform uint u_count;
layout(location = 1) uniform int u_bins;
void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_count) return;
  vec3 l = probes[i].xyz;
  int best = -1;
  float best_dot = -2.0;
  for (int k = 0; k < u_bins; ++k) {  // the linear search the renderer had
    float d = dot(l, dr_directions[k].direction);
    if (d > best_dot) {
      best_dot = d;
      best = k;
    }
  }
  bins[i] = ivec2(directional_bin_of(l, u_bins), best);
}
)glsl";

// The GLSL search against the linear one on the GPU (bit for bit: the same dot products), and
// against the C++ search (equal except where two bins' dots are within float rounding).
void search_agrees(bool tangent, int bin_count) {
  auto ctx = engine::GpuContext::create_headless();
  ASSERT_TRUE(ctx.ok()) << ctx.error().to_string();
  const std::vector<glm::vec3> dirs = tangent ? hemisphere(bin_count) : fibonacci(bin_count);
  std::vector<glm::vec4> dir_buffer;
  for (const glm::vec3& d : dirs) dir_buffer.emplace_back(d, 1.0f);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<glm::vec4> probes;
  for (const glm::vec3& d : dirs) probes.emplace_back(d, 0.0f);
  for (std::size_t k = 0; k + 1 < dirs.size(); ++k) probes.emplace_back(glm::normalize(dirs[k] + dirs[k + 1]), 0.0f);
  while (probes.size() < 20000) {
    const glm::vec3 w(u(rng), u(rng), u(rng));
    if (glm::dot(w, w) > 1e-4f) probes.emplace_back(glm::normalize(w), 0.0f);
  }
  const engine::ShaderFile file{"directional_search.comp.glsl", "tests/engine/directional_radiance_test.cpp",
                                kSearchShader};
  auto program = engine::ShaderProgramBuilder(std::span<const engine::ShaderFile>(&file, 1))
                     .add_files(engine::engine_shader_files())
                     .stage(engine::ShaderStage::Compute, "directional_search.comp.glsl")
                     .build();
  ASSERT_TRUE(program.ok()) << program.error().to_string();
  engine::GlBuffer in = engine::GlBuffer::create(probes.size() * sizeof(glm::vec4), probes.data());
  engine::GlBuffer out = engine::GlBuffer::create(probes.size() * sizeof(glm::ivec2), nullptr);
  engine::GlBuffer directions = engine::GlBuffer::create(dir_buffer.size() * sizeof(glm::vec4), dir_buffer.data());
  program->use();
  glUniform1ui(0, static_cast<GLuint>(probes.size()));
  glUniform1i(1, bin_count);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, in.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, out.id());
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, directions.id());
  glDispatchCompute(static_cast<GLuint>((probes.size() + 63) / 64), 1, 1);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
  std::vector<glm::ivec2> gpu(probes.size());
  glGetNamedBufferSubData(out.id(), 0, static_cast<GLsizeiptr>(gpu.size() * sizeof(glm::ivec2)), gpu.data());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  std::size_t near_tie = 0;
  for (std::size_t i = 0; i < probes.size(); ++i) {
    ASSERT_EQ(gpu[i].x, gpu[i].y) << "probe " << i << ": the GLSL search differs from the GLSL linear search";
    const glm::vec3 l(probes[i]);
    const int cpu = engine::directional_bin_of(dirs, l);
    if (gpu[i].x == cpu) continue;
    // Only where the two bins' dots are equal to float rounding may the GPU's arithmetic pick the other.
    ASSERT_GE(gpu[i].x, 0);
    const float gap = std::fabs(glm::dot(l, dirs[static_cast<std::size_t>(cpu)]) -
                                glm::dot(l, dirs[static_cast<std::size_t>(gpu[i].x)]));
    EXPECT_LT(gap, 1e-6f) << "probe " << i;
    ++near_tie;
  }
  EXPECT_LT(near_tie, probes.size() / 100);
  std::printf("%s %d bins: %zu directions, GLSL search = GLSL linear search at all, = C++ at all but %zu near-ties\n",
              tangent ? "tangent-frame" : "global", bin_count, probes.size(), near_tie);
}

// The nearest-bin search (engine::directional_bin_of's GLSL twin) finds the linear search's bin.
TEST(DirectionalRadiance, GlslSearchFindsTheLinearSearchesBin) {
  search_agrees(false, 32);
  search_agrees(true, 64);
  search_agrees(true, 128);
}

}  // namespace
