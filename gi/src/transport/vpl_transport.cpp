#include "transport/vpl_transport.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "core/random.h"
#include "raytrace/ray_offset.h"
#include "raytrace/reference_brdf.h"

namespace gi {

std::vector<glm::vec3> direct_to_vpls(const VplSet& vpls, const std::vector<PointEmitter>& emitters,
                                      const RayCaster& caster, ThreadPool& pool, std::uint64_t* rays) {
  const std::size_t n = vpls.size();
  std::vector<std::size_t> punctual;
  for (std::size_t e = 0; e < emitters.size(); ++e)
    if (emitters[e].kind == PointEmitter::Kind::Punctual) punctual.push_back(e);
  std::vector<glm::vec3> out(n, glm::vec3(0.0f));
  // Per punctual light, the irradiance it gives each VPL, kept apart for its flux check.
  std::vector<std::vector<glm::vec3>> from_punctual(punctual.size(), std::vector<glm::vec3>(n, glm::vec3(0.0f)));
  std::atomic<std::uint64_t> ray_count{0};
  pool.parallel_for(
      n,
      [&](std::size_t j) {
        glm::dvec3 sum(0.0);
        std::vector<glm::dvec3> by_light(punctual.size(), glm::dvec3(0.0));
        std::uint64_t local_rays = 0;
        for (std::uint32_t k = vpls.sample_first[j]; k < vpls.sample_first[j + 1]; ++k) {
          const glm::vec3& p = vpls.sample_position[k];
          const glm::vec3& nk = vpls.sample_normal[k];
          const float a = vpls.sample_area_m2[k];
          std::size_t next_punctual = 0;
          for (std::size_t e = 0; e < emitters.size(); ++e) {
            const bool is_punctual = emitters[e].kind == PointEmitter::Kind::Punctual;
            const std::size_t slot = is_punctual ? next_punctual++ : 0;
            const glm::vec3 irr = emitter_irradiance(emitters[e], p, nk, a);
            if (irr == glm::vec3(0.0f)) continue;
            ++local_rays;
            if (!emitter_visible(caster, emitters[e], p, nk)) continue;
            (is_punctual ? by_light[slot] : sum) += glm::dvec3(irr) * static_cast<double>(a);
          }
        }
        const double area = static_cast<double>(vpls.area_m2[j]);
        out[j] = glm::vec3(sum / area);
        for (std::size_t l = 0; l < punctual.size(); ++l) from_punctual[l][j] = glm::vec3(by_light[l] / area);
        ray_count += local_rays;
      },
      16);
  // Flux check of each punctual light: the patches' sampled irradiance must account for the
  // light's flux onto the scene, I x (lit solid angle). Sample points miss the flux a light
  // very close to a surface concentrates between them (a light 1 mm from a wall puts half its
  // power within millimetres), so the light's VPL irradiance is rescaled to the traced flux.
  constexpr int kFluxSide = 64;  // 4096 directions
  for (std::size_t l = 0; l < punctual.size(); ++l) {
    const PointEmitter& e = emitters[punctual[l]];
    const float lum_i = luminance(e.radiant);
    double sampled = 0.0;
    for (std::size_t j = 0; j < n; ++j)
      sampled += static_cast<double>(vpls.area_m2[j]) * static_cast<double>(luminance(from_punctual[l][j]));
    const double traced = static_cast<double>(lum_i) * punctual_lit_solid_angle(e, caster, kFluxSide);
    ray_count += kFluxSide * kFluxSide;
    const double scale = sampled > 0.0 ? std::clamp(traced / sampled, 0.25, 4.0) : 1.0;
    for (std::size_t j = 0; j < n; ++j) out[j] += from_punctual[l][j] * static_cast<float>(scale);
  }
  if (rays) *rays += ray_count.load();
  return out;
}

namespace {

// Scaled form factors F'_ij from shooter i to every receiver j (eq. 8's F'), one row per
// shooter, cached within a byte budget.
class FormFactorRows {
 public:
  FormFactorRows(const VplSet& vpls, const RayCaster& caster, ThreadPool& pool, const PropagationSettings& settings)
      : vpls_(vpls),
        caster_(caster),
        pool_(pool),
        budget_rows_(settings.row_cache_bytes / (sizeof(float) * std::max<std::size_t>(1, vpls.size()))),
        reach_rays_(settings.reach_rays),
        seed_(settings.seed) {}

  const std::vector<float>& row(std::uint32_t i) {
    if (auto it = cache_.find(i); it != cache_.end()) return it->second;
    std::vector<float> r(vpls_.size(), 0.0f);
    std::atomic<std::uint64_t> count{0};
    pool_.parallel_for(
        vpls_.size(),
        [&](std::size_t j) {
          if (j == i) return;
          double sum = 0.0;
          std::uint64_t local = 0;
          for (std::uint32_t k = vpls_.sample_first[j]; k < vpls_.sample_first[j + 1]; ++k) {
            const float a = vpls_.sample_area_m2[k];
            // The receiver's samples are point samples of its irradiance (their mean is the
            // patch's); the shooter's sample areas bound the near field.
            const float f = patch_kernel(vpls_, i, vpls_.sample_position[k], vpls_.sample_normal[k], 0.0f);
            if (f <= 0.0f) continue;
            // Visibility towards one of the shooter's sample points, picked by hash.
            const std::uint32_t l = pick_sample(vpls_, i, (std::uint64_t{k} << 32) | i);
            ++local;
            if (segment_visible(caster_, vpls_.sample_position[k], vpls_.sample_normal[k], vpls_.sample_position[l],
                                vpls_.sample_normal[l]))
              sum += static_cast<double>(f) * static_cast<double>(a);
          }
          r[j] = static_cast<float>(sum / static_cast<double>(vpls_.area_m2[j]));
          count += local;
        },
        16);
    rays_ += count.load();
    normalize(i, r);
    if (cache_.size() < budget_rows_) return cache_.emplace(i, std::move(r)).first->second;
    scratch_ = std::move(r);
    return scratch_;
  }

  std::uint64_t rays() const { return rays_; }

 private:
  // Rescales row i so that sum_j A_j F'_ij equals the fraction of cosine rays from the
  // shooter's sample points that hit the scene.
  void normalize(std::uint32_t i, std::vector<float>& r) {
    if (reach_rays_ <= 0) return;
    double sum = 0.0;
    for (std::size_t j = 0; j < r.size(); ++j) sum += static_cast<double>(vpls_.area_m2[j]) * static_cast<double>(r[j]);
    if (!(sum > 0.0)) return;
    Pcg32 rng = Pcg32::for_item(seed_ ^ 0x7265616368ULL, i);
    int hits = 0;
    const std::uint32_t m = vpls_.sample_count(i);
    for (int k = 0; k < reach_rays_; ++k) {
      const std::uint32_t l = vpls_.sample_first[i] + static_cast<std::uint32_t>(k) % m;
      const float u1 = rng.next_float(), u2 = rng.next_float();
      const glm::vec3 d = sample_cosine_hemisphere(vpls_.sample_normal[l], u1, u2);
      hits +=
          caster_.occluded(Ray{offset_ray_origin(vpls_.sample_position[l], vpls_.sample_normal[l]), 0.0f, d}) ? 1 : 0;
    }
    rays_ += static_cast<std::uint64_t>(reach_rays_);
    const double scale = std::clamp(static_cast<double>(hits) / reach_rays_ / sum, 0.5, 2.0);
    for (float& f : r) f = static_cast<float>(static_cast<double>(f) * scale);
  }

  const VplSet& vpls_;
  const RayCaster& caster_;
  ThreadPool& pool_;
  std::size_t budget_rows_;
  int reach_rays_;
  std::uint64_t seed_;
  std::unordered_map<std::uint32_t, std::vector<float>> cache_;
  std::vector<float> scratch_;
  std::uint64_t rays_ = 0;
};

}  // namespace

engine::Result<VplSolution> propagate(const VplSet& vpls, const std::vector<glm::vec3>& direct, const RayCaster& caster,
                                      ThreadPool& pool, const PropagationSettings& settings) {
  const std::size_t n = vpls.size();
  VplSolution out;
  out.irradiance = direct;
  std::vector<glm::vec3> unshot = direct;
  const auto power = [&](std::size_t i, const glm::vec3& irradiance) {
    return vpls.albedo[i] * vpls.area_m2[i] * irradiance;  // eq. 7 with A_i = m_i C
  };
  float largest = 0.0f;
  for (std::size_t i = 0; i < n; ++i) largest = std::max(largest, luminance(power(i, direct[i])));
  const float cutoff = settings.unshot_threshold * largest;

  FormFactorRows rows(vpls, caster, pool, settings);
  for (int generation = 1; generation < settings.bounces && largest > 0.0f; ++generation) {
    // The priority queue of this generation: shooters by unshot power, largest first (ties
    // by index, so the order is deterministic).
    std::vector<std::uint32_t> queue(n);
    std::iota(queue.begin(), queue.end(), 0u);
    std::vector<float> key(n);
    for (std::size_t i = 0; i < n; ++i) key[i] = luminance(power(i, unshot[i]));
    std::stable_sort(queue.begin(), queue.end(), [&](std::uint32_t a, std::uint32_t b) { return key[a] > key[b]; });
    const auto active = static_cast<std::size_t>(
        std::find_if(queue.begin(), queue.end(), [&](std::uint32_t i) { return !(key[i] > cutoff); }) - queue.begin());

    std::vector<glm::vec3> next(n, glm::vec3(0.0f));
    for (std::size_t s = 0; s < active; ++s) {
      const std::uint32_t i = queue[s];
      const glm::vec3 shot = power(i, unshot[i]);
      const std::vector<float>& f = rows.row(i);
      for (std::size_t j = 0; j < n; ++j) next[j] += shot * f[j];  // eq. 8: R = F'_ij dE_i
      ++out.shots;
      if (settings.progress && (s % 64 == 63 || s + 1 == active)) {
        const double done =
            (static_cast<double>(generation - 1) + static_cast<double>(s + 1) / static_cast<double>(active)) /
            static_cast<double>(settings.bounces - 1);
        if (!settings.progress(done)) return engine::cancelled_error("light-atlas bake");
      }
    }
    for (std::size_t j = 0; j < n; ++j) out.irradiance[j] += next[j];
    unshot = std::move(next);
  }
  out.rays = rows.rays();
  return out;
}

}  // namespace gi
