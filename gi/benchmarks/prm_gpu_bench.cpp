// The PRM pane sum on the GPU (PrmGpuPass::run): milliseconds per run for T pane texels and K
// selected clusters, with glFinish inside the timed region (DESIGN.md §4: on llvmpipe these
// are CPU timings; compare them as ratios). The yardstick is measured in the same loop,
// interleaved with the pane sum (one of each per iteration, so machine load hits both
// alike): a plain compute kernel streaming the same bytes (the K half-float panes, T x K x 6
// bytes) as vec4 loads into a vec4 buffer of the same size (read + write), in two forms timed
// alike: through SSBOs, and through a buffer texture read with texelFetch and an image buffer
// written with imageStore (llvmpipe runs an SSBO load as a loop over the SIMD lanes, a texel
// fetch as one gather: the pane sum reads its panes the second way, so the yardstick must
// too). The faster of the two is the device's streaming bandwidth. Counters:
//   pane_GB/s     pane bytes read per second by the pane sum (median iteration);
//   stream_GB/s   the same bytes read per second by the faster yardstick (median iteration);
//   ssbo_stream_GB/s, texture_stream_GB/s  each yardstick's own figure;
//   vs_stream     pane_GB/s / stream_GB/s: the share of the device's streaming bandwidth
//                 (issue 23 target >= 0.5);
//   Mtexel_clusters/s  pane texel x cluster products per second.
//   ./build/gi/benchmarks/prm_gpu_bench --benchmark_counters_tabular=true
#include <GL/glcorearb.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <map>
#include <memory>
#include <vector>

#include <benchmark/benchmark.h>
#include <engine/gpu/context.h>
#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>

#include "bench_gl.h"

#include "core/random.h"
#include "prm/prm.h"
#include "prm/prm_gpu_pass.h"
#include "prm/prm_runtime.h"

namespace {

constexpr int kClusters = 128;  // the largest K benchmarked
constexpr int kAtlasWidth = 1024;

// T pane texels: every other texel of a 1024-wide atlas; 128 clusters of pane values in (0, 10).
gi::Prm synthetic_prm(std::size_t texels) {
  gi::Prm prm;
  prm.width = kAtlasWidth;
  prm.height = static_cast<int>((2 * texels + kAtlasWidth - 1) / kAtlasWidth);
  prm.cluster_count = kClusters;
  prm.texels.resize(texels);
  for (std::size_t i = 0; i < texels; ++i) prm.texels[i] = static_cast<std::uint32_t>(2 * i);
  std::vector<float> dense(static_cast<std::size_t>(kClusters) * texels * 3);
  gi::Pcg32 rng(5, 1);
  for (float& v : dense) v = 10.0f * rng.next_float();
  gi::set_dense_panes(prm, dense);
  return prm;
}

gi::PrmGpuPass& pass_for(std::size_t texels) {
  static std::map<std::size_t, std::unique_ptr<gi::PrmGpuPass>> passes;
  bench::gl_context();
  auto& p = passes[texels];
  if (!p) {
    auto created = gi::PrmGpuPass::create(synthetic_prm(texels));
    if (!created) {
      std::fprintf(stderr, "%s\n", created.error().to_string().c_str());
      std::exit(1);
    }
    p = std::make_unique<gi::PrmGpuPass>(std::move(created).value());
  }
  return *p;
}

// The yardstick: dst[i] = src[i] * scale over vec4s, one vec4 per invocation (the simplest
// streaming kernel; the multiply keeps the copy from being a plain memcpy).
constexpr const char* kStreamShader = R"(#version 450 core
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Src { vec4 src[]; };
layout(std430, binding = 1) writeonly buffer Dst { vec4 dst[]; };
uniform uint u_count;
uniform float u_scale;
void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
  if (i < u_count) dst[i] = src[i] * u_scale;
}
)";

// The same stream through a buffer texture (read) and an image buffer (write).
constexpr const char* kTextureStreamShader = R"(#version 450 core
layout(local_size_x = 64) in;
layout(binding = 0) uniform samplerBuffer u_src;
layout(binding = 1, rgba32f) uniform writeonly imageBuffer u_dst;
uniform uint u_count;
uniform float u_scale;
void main() {
  const uint i = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * 64u + gl_LocalInvocationIndex;
  if (i < u_count) imageStore(u_dst, int(i), texelFetch(u_src, int(i)) * u_scale);
}
)";

struct StreamKernel {
  engine::ShaderProgram program;
  engine::GlBuffer src, dst;
  GLuint src_texture = 0, dst_texture = 0;  // the texture form only
  bool textures = false;
  std::uint32_t count = 0;  // vec4s
  int count_location = -1, scale_location = -1;

  StreamKernel(std::size_t bytes, bool through_textures) : textures(through_textures) {
    const engine::ShaderFile file{textures ? "texture_stream_yardstick.comp.glsl" : "stream_yardstick.comp.glsl",
                                  "gi/benchmarks/prm_gpu_bench.cpp", textures ? kTextureStreamShader : kStreamShader};
    auto built =
        engine::ShaderProgramBuilder(std::span(&file, 1)).stage(engine::ShaderStage::Compute, file.name).build();
    if (!built) {
      std::fprintf(stderr, "%s\n", built.error().to_string().c_str());
      std::exit(1);
    }
    program = std::move(built).value();
    count = static_cast<std::uint32_t>((bytes + 15) / 16);
    std::vector<float> data(std::size_t{count} * 4);
    gi::Pcg32 rng(9, 1);
    for (float& v : data) v = rng.next_float();
    src = engine::GlBuffer::create(data.size() * sizeof(float), data.data());
    dst = engine::GlBuffer::create(data.size() * sizeof(float), nullptr);
    if (textures) {
      glCreateTextures(GL_TEXTURE_BUFFER, 1, &src_texture);
      glTextureBuffer(src_texture, GL_RGBA32F, src.id());
      glCreateTextures(GL_TEXTURE_BUFFER, 1, &dst_texture);
      glTextureBuffer(dst_texture, GL_RGBA32F, dst.id());
    }
    count_location = glGetUniformLocation(program.id(), "u_count");
    scale_location = glGetUniformLocation(program.id(), "u_scale");
  }
  StreamKernel(const StreamKernel&) = delete;
  StreamKernel& operator=(const StreamKernel&) = delete;
  ~StreamKernel() {
    if (src_texture) glDeleteTextures(1, &src_texture);
    if (dst_texture) glDeleteTextures(1, &dst_texture);
  }
  void run() const {
    program.use();
    glProgramUniform1ui(program.id(), count_location, count);
    glProgramUniform1f(program.id(), scale_location, 0.5f);
    if (textures) {
      glBindTextureUnit(0, src_texture);
      glBindImageTexture(1, dst_texture, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_RGBA32F);
    } else {
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, src.id());
      glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, dst.id());
    }
    const std::uint32_t groups = (count + 63) / 64;
    const std::uint32_t gx = std::min<std::uint32_t>(groups, 65535);
    glDispatchCompute(gx, (groups + gx - 1) / gx, 1);
    glMemoryBarrier(textures ? GL_SHADER_IMAGE_ACCESS_BARRIER_BIT : GL_SHADER_STORAGE_BARRIER_BIT);
  }
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

void BM_PrmGpuSum(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  const auto texels = static_cast<std::size_t>(state.range(0));
  const auto k = static_cast<int>(state.range(1));
  gi::PrmGpuPass& pass = pass_for(texels);
  const double pane_bytes = double(texels) * double(k) * 6.0;
  const StreamKernel stream(static_cast<std::size_t>(pane_bytes), false);
  const StreamKernel texture_stream(static_cast<std::size_t>(pane_bytes), true);
  std::vector<gi::ClusterWeight> selected;
  for (int i = 0; i < k; ++i)
    selected.push_back({static_cast<std::uint32_t>(i * (kClusters / k)), glm::vec3(0.5f, 0.25f, 1.0f)});
  (void)pass.run(selected);  // warm-up: first-dispatch shader compilation in llvmpipe
  stream.run();
  texture_stream.run();
  glFinish();
  std::vector<double> sum_s, stream_s, texture_stream_s;
  for (auto _ : state) {
    const auto tt = Clock::now();
    texture_stream.run();
    glFinish();
    const auto t0 = Clock::now();
    stream.run();
    glFinish();
    const auto t1 = Clock::now();
    if (!pass.run(selected)) state.SkipWithError("PrmGpuPass::run failed");
    glFinish();
    const auto t2 = Clock::now();
    texture_stream_s.push_back(std::chrono::duration<double>(t0 - tt).count());
    stream_s.push_back(std::chrono::duration<double>(t1 - t0).count());
    sum_s.push_back(std::chrono::duration<double>(t2 - t1).count());
    state.SetIterationTime(sum_s.back());
  }
  const double sum_median = median(sum_s), ssbo_median = median(stream_s), texture_median = median(texture_stream_s);
  const double stream_median = std::min(ssbo_median, texture_median);
  state.counters["ssbo_stream_GB/s"] = pane_bytes * 1e-9 / ssbo_median;
  state.counters["texture_stream_GB/s"] = pane_bytes * 1e-9 / texture_median;
  state.counters["Mtexel_clusters/s"] = double(texels) * double(k) * 1e-6 / sum_median;
  state.counters["pane_GB/s"] = pane_bytes * 1e-9 / sum_median;
  state.counters["stream_GB/s"] = pane_bytes * 1e-9 / stream_median;
  state.counters["vs_stream"] = stream_median / sum_median;
}
BENCHMARK(BM_PrmGpuSum)
    ->ArgNames({"T", "K"})
    ->ArgsProduct({{64 << 10, 256 << 10}, {8, 16, 32, 128}})
    ->Unit(benchmark::kMillisecond)
    ->UseManualTime();

// The pass's fixed part (no cluster: the texel list read, every pane texel written) against T:
// what a dispatch costs by itself (T = 8: one invocation) and per texel. Counters: run_ms
// (PrmGpuPass::run: the dispatch, synchronous on llvmpipe), finish_ms (the glFinish after it)
// and cpu_time_ms (both in process CPU time, every thread), medians.
void BM_PrmGpuFixed(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  gi::PrmGpuPass& pass = pass_for(static_cast<std::size_t>(state.range(0)));
  (void)pass.run({});
  glFinish();
  const auto process_cpu_ms = [] {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
  };
  std::vector<double> run_ms, finish_ms, cpu_ms;
  for (auto _ : state) {
    const double c0 = process_cpu_ms();
    const auto t0 = Clock::now();
    if (!pass.run({})) state.SkipWithError("PrmGpuPass::run failed");
    const auto t1 = Clock::now();
    glFinish();
    const auto t2 = Clock::now();
    cpu_ms.push_back(process_cpu_ms() - c0);
    run_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    finish_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    state.SetIterationTime(std::chrono::duration<double>(t2 - t0).count());
  }
  state.counters["run_ms"] = median(run_ms);
  state.counters["finish_ms"] = median(finish_ms);
  state.counters["cpu_time_ms"] = median(cpu_ms);  // process CPU time (llvmpipe's threads too): steadier under load
}
BENCHMARK(BM_PrmGpuFixed)
    ->ArgName("T")
    ->Arg(8)
    ->Arg(4096)
    ->Arg(64 << 10)
    ->Unit(benchmark::kMicrosecond)
    ->UseManualTime();

}  // namespace

BENCHMARK_MAIN();
