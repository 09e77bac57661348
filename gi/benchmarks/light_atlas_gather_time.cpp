// Where a light-atlas gather's seconds go on a level, with a yardstick from the same run
// (issue 35: the medium preset's Sponza bake, faster at the same output). The scene is baked
// untextured under docs/real_level.md's sun and gradient sky, as light_atlas_breakdown bakes it;
// the program times the setup (layout, static scene with its BVH), the gather's four steps, and
// raw Embree rtcIntersect1 calls over 16 M incoherent rays (cosine rays from random texels)
// before and after the gathers, so a speed-up can be read against the machine's load at the
// time; wall and CPU seconds both (the CPU seconds suffer less from other processes).
// A timing program, not a benchmark of Google Benchmark's kind: one bake is tens of seconds.
//   light_atlas_gather_time SCENE.gltf [texels_per_metre=8] [preset=medium] [runs=1] [dump.bin] [compare.bin]
// dump.bin: the gather's direct, baked_direct and indirect fields are written there;
// compare.bin: read back and compared texel by texel with this run's (the largest and the rms
// difference of the total, relative to the mean total): a speed-up must leave them equal up
// to float reassociation.
// Environment: GI_GATHER_ADAPTIVE=share:passes (adaptive passes), GI_GATHER_NEAR_DEPTH=depth[:deep_rays]
// (the near regather's levels and the rays of each regather below the first).
#include <embree3/rtcore.h>
#include <engine/gltf.h>
#include <engine/sun.h>
#include <gi/bake_input.h>
#include <gi/frame_truth.h>

#include <sys/resource.h>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "core/random.h"
#include "core/stopwatch.h"
#include "core/thread_pool.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/texel_gather.h"
#include "light_atlas/texel_sampling.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/ray_offset.h"
#include "real_level_lighting.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace {

using Clock = std::chrono::steady_clock;

// The process's CPU seconds so far (user + system, all threads): less inflated by other
// processes' load than the wall clock.
double cpu_seconds() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

// The gather's three output fields, one after the other.
std::vector<glm::vec3> fields_of(const gi::TexelGatherResult& g) {
  std::vector<glm::vec3> all(g.direct);
  all.insert(all.end(), g.baked_direct.begin(), g.baked_direct.end());
  all.insert(all.end(), g.indirect.begin(), g.indirect.end());
  return all;
}

void compare_with(const std::string& path, const gi::TexelGatherResult& g) {
  const std::vector<glm::vec3> now = fields_of(g);
  std::vector<glm::vec3> before(now.size());
  std::ifstream f(path, std::ios::binary);
  if (!f.read(reinterpret_cast<char*>(before.data()), static_cast<std::streamsize>(before.size() * sizeof(glm::vec3))))
    return (void)std::printf("compare: %s does not hold this atlas's fields\n", path.c_str());
  const std::size_t n = g.direct.size();
  double sum = 0.0, diff2 = 0.0, worst = 0.0;
  std::size_t differ = 0, valid = 0;
  for (std::size_t i = 0; i < n; ++i) {
    glm::dvec3 a(0.0), b(0.0);
    for (std::size_t k = 0; k < 3; ++k) a += glm::dvec3(now[k * n + i]), b += glm::dvec3(before[k * n + i]);
    const double la = a.x + a.y + a.z, lb = b.x + b.y + b.z;
    if (lb == 0.0 && la == 0.0) continue;
    ++valid;
    sum += lb;
    diff2 += (la - lb) * (la - lb);
    worst = std::max(worst, std::fabs(la - lb));
    differ += la != lb ? 1 : 0;
  }
  const double mean = valid > 0 ? sum / static_cast<double>(valid) : 1.0;
  std::printf("compare with %s: %zu of %zu lit texels differ; rms diff %.3g, largest %.3g (of the mean total %.4g)\n",
              path.c_str(), differ, valid, std::sqrt(diff2 / std::max<double>(1.0, static_cast<double>(valid))) / mean,
              worst / mean, mean);
}

// The yardstick: `count` raw rtcIntersect1 calls, 16 cosine rays from each of random valid
// texels, on the pool's threads.
void raw_embree_rays(const gi::StaticBakeScene& b, std::uint64_t count, gi::ThreadPool& pool) {
  const RTCScene scene = static_cast<RTCScene>(gi::embree_scene_handle(*b.caster));
  const gi::AtlasTexels& tx = b.texels;
  std::vector<std::uint32_t> valid_texels;
  for (std::size_t i = 0; i < tx.valid.size(); ++i)
    if (tx.valid[i]) valid_texels.push_back(static_cast<std::uint32_t>(i));
  constexpr std::size_t kPerItem = 4096;
  const std::size_t items = static_cast<std::size_t>((count + kPerItem - 1) / kPerItem);
  std::atomic<std::uint64_t> hits{0};
  const auto t0 = Clock::now();
  const double c0 = cpu_seconds();
  pool.parallel_for(items, [&](std::size_t item) {
    gi::Pcg32 rng = gi::Pcg32::for_item(77, item);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    std::uint64_t mine = 0;
    std::uint32_t i = 0;
    glm::vec3 o(0.0f);
    for (std::size_t r = 0; r < kPerItem; ++r) {
      if (r % 16 == 0) {  // 16 rays from each texel
        i = valid_texels[std::min(
            valid_texels.size() - 1,
            static_cast<std::size_t>(rng.next_float() * static_cast<float>(valid_texels.size())))];
        o = gi::offset_ray_origin(tx.position[i], tx.normal[i]);
      }
      const float u = rng.next_float(), v = rng.next_float();
      const glm::vec3 d = gi::sample_cosine_hemisphere(tx.normal[i], u, v);
      RTCRayHit rh{};
      rh.ray.org_x = o.x, rh.ray.org_y = o.y, rh.ray.org_z = o.z;
      rh.ray.dir_x = d.x, rh.ray.dir_y = d.y, rh.ray.dir_z = d.z;
      rh.ray.tnear = 0.0f, rh.ray.tfar = INFINITY, rh.ray.mask = 0xffffffffu;
      rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene, &ctx, &rh);
      mine += rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
    }
    hits += mine;
  });
  double s = gi::seconds_since(t0), cpu = cpu_seconds() - c0;
  const double m = static_cast<double>(items * kPerItem) * 1e-6;
  std::printf(
      "yardstick: %.1f M raw rtcIntersect1 (cosine rays from random texels, %.0f%% hit) in %.2f s, %.2f cpu s: %.2f "
      "Mrays/s, %.2f Mrays per cpu s\n",
      m, 100.0 * static_cast<double>(hits.load()) / static_cast<double>(items * kPerItem), s, cpu, m / s, m / cpu);
  // The same kind of rays 16 at a time from one texel, as rtcIntersect16 packets with the
  // coherent flag: what tracing a texel's gather rays together would make of the rays' cost.
  hits = 0;
  const auto t1 = Clock::now();
  const double c1 = cpu_seconds();
  pool.parallel_for(items, [&](std::size_t item) {
    gi::Pcg32 rng = gi::Pcg32::for_item(78, item);
    RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    alignas(64) RTCRayHit16 packet;
    alignas(64) int valid[16];
    std::uint64_t mine = 0;
    for (std::size_t first = 0; first < kPerItem; first += 16) {
      const std::uint32_t i =
          valid_texels[std::min(valid_texels.size() - 1,
                                static_cast<std::size_t>(rng.next_float() * static_cast<float>(valid_texels.size())))];
      const glm::vec3 o = gi::offset_ray_origin(tx.position[i], tx.normal[i]);
      for (int j = 0; j < 16; ++j) {
        const float u = rng.next_float(), v = rng.next_float();
        const glm::vec3 d = gi::sample_cosine_hemisphere(tx.normal[i], u, v);
        valid[j] = -1;
        packet.ray.org_x[j] = o.x, packet.ray.org_y[j] = o.y, packet.ray.org_z[j] = o.z;
        packet.ray.dir_x[j] = d.x, packet.ray.dir_y[j] = d.y, packet.ray.dir_z[j] = d.z;
        packet.ray.tnear[j] = 0.0f, packet.ray.tfar[j] = INFINITY, packet.ray.time[j] = 0.0f;
        packet.ray.mask[j] = 0xffffffffu, packet.ray.id[j] = static_cast<unsigned>(j), packet.ray.flags[j] = 0;
        packet.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
        packet.hit.instID[0][j] = RTC_INVALID_GEOMETRY_ID;
      }
      rtcIntersect16(valid, scene, &ctx, &packet);
      for (int j = 0; j < 16; ++j) mine += packet.hit.geomID[j] != RTC_INVALID_GEOMETRY_ID ? 1 : 0;
    }
    hits += mine;
  });
  s = gi::seconds_since(t1), cpu = cpu_seconds() - c1;
  std::printf(
      "  the same as 16-ray packets from one texel: %.0f%% hit, %.2f s, %.2f cpu s: %.2f Mrays/s, %.2f Mrays per "
      "cpu s\n",
      100.0 * static_cast<double>(hits.load()) / static_cast<double>(items * kPerItem), s, cpu, m / s, m / cpu);
}

}  // namespace

// Long because it is one measurement read top to bottom: load, setup, the runs, the yardstick.
int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE.gltf [texels_per_metre] [preset] [runs] [dump.bin] [compare.bin]\n", argv[0]);
    return 2;
  }
  const float density = argc > 2 ? std::strtof(argv[2], nullptr) : 8.0f;
  const std::string preset = argc > 3 ? argv[3] : "medium";
  const int runs = argc > 4 ? std::max(1, std::atoi(argv[4])) : 1;
  const std::string dump = argc > 5 ? argv[5] : "", compare = argc > 6 ? argv[6] : "";
  auto loaded = gi_bench::load_untextured_under_sun_and_sky(argv[1]);
  if (!loaded) return std::fprintf(stderr, "%s\n", loaded.error().to_string().c_str()), 1;
  const engine::SceneAsset& asset = *loaded;
  const gi::BakeInput input = gi::bake_input_from(asset);
  auto preset_settings = gi::light_atlas_preset(preset);
  if (!preset_settings) return std::fprintf(stderr, "%s\n", preset_settings.error().to_string().c_str()), 1;
  gi::LightAtlasSettings s = *preset_settings;
  s.texels_per_metre = density;

  auto t0 = Clock::now();
  auto layout = gi::static_world_layout(input, density);
  if (!layout) return std::fprintf(stderr, "%s\n", layout.error().to_string().c_str()), 1;
  const double layout_s = gi::seconds_since(t0);
  t0 = Clock::now();
  auto scene = gi::prepare_static_scene(input, *layout, gi::BakeLights::Static, gi::texel_placement(s));
  if (!scene) return std::fprintf(stderr, "%s\n", scene.error().to_string().c_str()), 1;
  std::printf("%s at %.1f texels/m, preset %s: %zu texels; layout %.2f s, static scene (BVH, texels) %.2f s\n", argv[1],
              static_cast<double>(density), preset.c_str(), scene->texels.valid.size(), layout_s,
              gi::seconds_since(t0));
  gi::ThreadPool pool(2);
  gi::TexelGatherSettings g = s.gather;
  g.seed = s.seed;
  // GI_GATHER_ADAPTIVE=share:passes: the preset's gather with adaptive passes (TexelGatherSettings::adaptive_share).
  if (const char* a = std::getenv("GI_GATHER_ADAPTIVE")) {
    char* rest = nullptr;
    g.adaptive_share = std::strtof(a, &rest);
    if (*rest == ':') g.adaptive_passes = static_cast<int>(std::strtol(rest + 1, nullptr, 10));
  }
  // GI_GATHER_NEAR_DEPTH=depth[:deep_rays]: the regather's levels (TexelGatherSettings::near_regather_depth).
  if (const char* d = std::getenv("GI_GATHER_NEAR_DEPTH")) {
    char* rest = nullptr;
    g.near_regather_depth = static_cast<int>(std::strtol(d, &rest, 10));
    if (*rest == ':') g.near_regather_deep_rays = static_cast<int>(std::strtol(rest + 1, nullptr, 10));
  }
  constexpr std::uint64_t kYardstickRays = 16u << 20;
  raw_embree_rays(*scene, kYardstickRays, pool);
  for (int run = 0; run < runs; ++run) {
    t0 = Clock::now();
    const double c0 = cpu_seconds();
    auto gathered = gi::gather_atlas(*scene, *layout, g, pool);
    if (!gathered) return std::fprintf(stderr, "%s\n", gathered.error().to_string().c_str()), 1;
    const double wall = gi::seconds_since(t0), cpu = cpu_seconds() - c0;
    std::printf(
        "gather %d: %.2f s, %.2f cpu s (direct %.2f, solve %.2f, final gather %.2f, filter %.2f), %.1f M rays, %.2f "
        "Mrays/s\n",
        run, wall, cpu, gathered->direct_seconds, gathered->solve_seconds, gathered->gather_seconds,
        gathered->filter_seconds, static_cast<double>(gathered->rays) * 1e-6,
        static_cast<double>(gathered->rays) / wall * 1e-6);
    if (run > 0) continue;
    if (!dump.empty()) {
      const std::vector<glm::vec3> all = fields_of(*gathered);
      std::ofstream f(dump, std::ios::binary);
      f.write(reinterpret_cast<const char*>(all.data()), static_cast<std::streamsize>(all.size() * sizeof(glm::vec3)));
    }
    if (!compare.empty()) compare_with(compare, *gathered);
  }
  raw_embree_rays(*scene, kYardstickRays, pool);
  return 0;
}
