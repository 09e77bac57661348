#include "light_atlas/final_shooting.h"

#include <algorithm>
#include <atomic>

namespace gi {

engine::Result<FinalShootingResult> shoot_into_atlas(const VplSet& vpls, const std::vector<std::uint32_t>& shooters,
                                                     const std::vector<glm::vec3>& power, const AtlasTexels& texels,
                                                     float texel_area_m2, const RayCaster& caster, ThreadPool& pool,
                                                     const FinalShootingSettings& settings) {
  FinalShootingResult out;
  out.irradiance.assign(texels.valid.size(), glm::vec3(0.0f));
  std::vector<std::uint32_t> work;
  for (std::size_t t = 0; t < texels.valid.size(); ++t)
    if (texels.valid[t]) work.push_back(static_cast<std::uint32_t>(t));

  std::atomic<std::uint64_t> rays{0};
  // Batches between progress reports; each batch runs its texels in parallel.
  const std::size_t batches = std::clamp<std::size_t>(work.size() / 256, 1, 100);
  for (std::size_t b = 0; b < batches; ++b) {
    const std::size_t begin = work.size() * b / batches;
    const std::size_t end = work.size() * (b + 1) / batches;
    pool.parallel_for(
        end - begin,
        [&](std::size_t w) {
          const std::uint32_t t = work[begin + w];
          const glm::vec3 p = texels.position[t];
          const glm::vec3 n = texels.normal[t];
          glm::dvec3 sum(0.0);
          std::uint64_t local = 0;
          for (std::size_t s = 0; s < shooters.size(); ++s) {
            const std::uint32_t i = shooters[s];
            const float f = patch_kernel(vpls, i, p, n, texel_area_m2);
            if (f <= 0.0f) continue;
            const std::uint32_t k = pick_sample(vpls, i, (std::uint64_t{t} << 32) | i, settings.seed);
            ++local;
            if (segment_visible(caster, p, n, vpls.sample_position[k], vpls.sample_normal[k]))
              sum += glm::dvec3(power[s]) * static_cast<double>(f);
          }
          out.irradiance[t] = glm::vec3(sum);
          rays += local;
        },
        8);
    if (settings.progress && !settings.progress(static_cast<double>(b + 1) / static_cast<double>(batches)))
      return engine::cancelled_error("light-atlas bake");
  }
  out.rays = rays.load();
  return out;
}

std::vector<glm::vec3> direct_into_atlas(const std::vector<PointEmitter>& emitters, const AtlasTexels& texels,
                                         float texel_area_m2, const RayCaster& caster, ThreadPool& pool,
                                         std::uint64_t* rays) {
  std::vector<glm::vec3> out(texels.valid.size(), glm::vec3(0.0f));
  std::atomic<std::uint64_t> count{0};
  pool.parallel_for(
      texels.valid.size(),
      [&](std::size_t t) {
        if (!texels.valid[t]) return;
        glm::dvec3 sum(0.0);
        std::uint64_t local = 0;
        for (const PointEmitter& e : emitters) {
          const glm::vec3 irr = emitter_irradiance(e, texels.position[t], texels.normal[t], texel_area_m2);
          if (irr == glm::vec3(0.0f)) continue;
          ++local;
          if (emitter_visible(caster, e, texels.position[t], texels.normal[t])) sum += glm::dvec3(irr);
        }
        out[t] = glm::vec3(sum);
        count += local;
      },
      64);
  if (rays) *rays += count.load();
  return out;
}

}  // namespace gi
