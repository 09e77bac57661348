#include "light_atlas/atlas_denoise.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/color.h"
#include "light_atlas/local_linear.h"
#include "light_atlas/texel_cells.h"

namespace gi {
namespace {

// The cubic B-spline kernel of the a-trous wavelet (1/16, 1/4, 3/8, 1/4, 1/16 on the
// lattice), radial: r in units of the pass's step, support 2.
float b3_spline(float r) {
  if (r < 1.0f) return 2.0f / 3.0f - r * r + 0.5f * r * r * r;
  if (r < 2.0f) return (2.0f - r) * (2.0f - r) * (2.0f - r) / 6.0f;
  return 0.0f;
}

// What one pass reads: the fields, their summed luminance and its variance.
struct PassInput {
  std::span<const std::vector<glm::vec3>> fields;
  const std::vector<float>& lum;
  const std::vector<float>& variance;
};

// One a-trous pass with step `step_texels`: every texel of `visible` takes the weighted mean
// of itself and of the lattice texels (atlas pixel coordinates multiples of the step) within
// two steps, written to `out_fields` and `out_variance`.
void atrous_pass(const AtlasTexels& tx, const std::vector<std::uint32_t>& visible, int step_texels, float texel_m,
                 const DenoiseSettings& s, ThreadPool& pool, const PassInput& in,
                 std::vector<std::vector<glm::vec3>>& out_fields, std::vector<float>& out_variance) {
  const auto step = static_cast<std::uint32_t>(step_texels);
  const auto width = static_cast<std::uint32_t>(tx.width);
  std::vector<std::uint32_t> lattice;
  for (std::uint32_t j : visible)
    if ((j % width) % step == 0 && (j / width) % step == 0) lattice.push_back(j);
  const float step_m = static_cast<float>(step_texels) * texel_m;
  const TexelCells all(tx, visible, 2.0f * step_m), on_lattice(tx, lattice, 2.0f * step_m);
  const float plane_m = 0.5f * texel_m, min_cos = std::pow(1e-4f, 1.0f / s.normal_power);
  const std::size_t nf = in.fields.size();
  const bool linear = s.slope_ridge >= 0.0f;
  pool.parallel_for(
      all.cell_count(),
      [&](std::size_t c) {
        std::vector<std::uint32_t> near;
        std::vector<Neighbour> taken;
        on_lattice.for_around(all.cell(c), [&](std::uint32_t j) { near.push_back(j); });
        all.for_cell(c, [&](std::uint32_t i) {
          const glm::vec3 p = tx.position[i], n = tx.normal[i];
          const float li = in.lum[i], vi = in.variance[i];
          taken.assign(1, Neighbour{i, b3_spline(0.0f), glm::vec2(0.0f)});
          const glm::mat3 frame = tangent_frame(n);
          for (std::uint32_t j : near) {
            if (j == i) continue;
            const glm::vec3 d = tx.position[j] - p;
            const float ks = b3_spline(std::sqrt(glm::dot(d, d)) / step_m);
            const float cos_n = glm::dot(tx.normal[j], n);
            if (ks <= 0.0f || cos_n < min_cos) continue;
            const float off_plane = glm::dot(d, n) / plane_m;
            // The difference in units of its standard deviation (a floor of 1e-3 of the
            // values where both are exact).
            const float dl = li - in.lum[j];
            const float floor = 1e-3f * (std::fabs(li) + std::fabs(in.lum[j]));
            const float z2 = dl * dl / (s.value_sigma * s.value_sigma * (vi + in.variance[j]) + floor * floor + 1e-30f);
            const float w = ks * std::pow(cos_n, s.normal_power) * std::exp(-off_plane * off_plane - 0.5f * z2);
            if (!(w > 0.0f)) continue;
            taken.push_back({j, w, glm::vec2(glm::dot(d, frame[0]), glm::dot(d, frame[1])) / step_m});
          }
          if (linear) to_linear_weights(s.slope_ridge, taken);
          float weight = 0.0f, var = 0.0f;
          glm::vec3 sum[2] = {glm::vec3(0.0f), glm::vec3(0.0f)};
          for (const Neighbour& t : taken) {
            weight += t.w;
            var += t.w * t.w * in.variance[t.j];
            for (std::size_t f = 0; f < nf; ++f) sum[f] += t.w * in.fields[f][t.j];
          }
          for (std::size_t f = 0; f < nf; ++f) out_fields[f][i] = glm::max(sum[f] / weight, glm::vec3(0.0f));
          out_variance[i] = var / (weight * weight);
        });
      },
      4);
}

// The clamp's neighbourhood: co-planar texels (normals within ~26 degrees, centres within
// half a texel of the plane) within 2.5 texels, 20 on a flat wall; fewer than 5 (a sliver of
// a chart alone in its plane): no clamp.
constexpr float kClampRadiusTexels = 2.5f;
constexpr float kClampMinCos = 0.9f;
constexpr int kClampMinNeighbours = 5;

// The clamp before the passes (DenoiseSettings::outlier_sigmas): per texel, the factor that
// brings its luminance down to the mean + k standard deviations of its neighbours' (their
// brightest left out, so that two outliers side by side do not shelter each other), 1 if it
// is not above. A step the gather resolves keeps: a texel on its bright side has at least a
// third of its neighbours as bright, whose spread then reaches it.
std::vector<float> outlier_scale(const AtlasTexels& tx, const std::vector<std::uint32_t>& visible, float texel_m,
                                 float k, ThreadPool& pool, const std::vector<float>& lum) {
  const float radius_m = kClampRadiusTexels * texel_m, plane_m = 0.5f * texel_m;
  const TexelCells cells(tx, visible, radius_m);
  std::vector<float> scale(lum.size(), 1.0f);
  pool.parallel_for(
      cells.cell_count(),
      [&](std::size_t c) {
        std::vector<std::uint32_t> near;
        cells.for_around(cells.cell(c), [&](std::uint32_t j) { near.push_back(j); });
        cells.for_cell(c, [&](std::uint32_t i) {
          const glm::vec3 p = tx.position[i], n = tx.normal[i];
          double sum = 0.0, squares = 0.0, brightest = -std::numeric_limits<double>::infinity();
          int count = 0;
          for (std::uint32_t j : near) {
            const glm::vec3 d = tx.position[j] - p;
            if (j == i || glm::dot(d, d) > radius_m * radius_m || glm::dot(tx.normal[j], n) < kClampMinCos ||
                std::fabs(glm::dot(d, n)) > plane_m)
              continue;
            const double l = lum[j];
            sum += l, squares += l * l, brightest = std::max(brightest, l), ++count;
          }
          if (count < kClampMinNeighbours) return;
          sum -= brightest, squares -= brightest * brightest, --count;
          const double mean = sum / count;
          const double spread = std::sqrt(std::max(0.0, (squares - sum * mean) / (count - 1)));
          const double limit = std::max(0.0, mean + static_cast<double>(k) * spread), li = lum[i];
          if (li > limit) scale[i] = static_cast<float>(limit / li);
        });
      },
      4);
  return scale;
}

}  // namespace

void denoise_world(const AtlasTexels& tx, std::span<const std::uint32_t> work, const std::vector<std::uint8_t>& hidden,
                   float texel_m, const DenoiseSettings& s, ThreadPool& pool, std::vector<float>& variance,
                   std::span<std::vector<glm::vec3>* const> fields) {
  if (s.passes <= 0 || fields.empty() || !(texel_m > 0.0f)) return;
  std::vector<std::uint32_t> visible;
  for (std::uint32_t i : work)
    if (!hidden[i]) visible.push_back(i);
  std::vector<std::vector<glm::vec3>> cur, next;
  for (std::size_t f = 0; f < fields.size() && f < 2; ++f) cur.push_back(*fields[f]);
  next = cur;
  std::vector<float> lum(variance.size(), 0.0f), next_variance = variance;
  const auto sum_luminance = [&] {
    for (std::uint32_t i : visible) {
      glm::vec3 total(0.0f);
      for (const auto& f : cur) total += f[i];
      lum[i] = luminance(total);
    }
  };
  if (s.outlier_sigmas > 0.0f) {
    sum_luminance();
    const std::vector<float> scale = outlier_scale(tx, visible, texel_m, s.outlier_sigmas, pool, lum);
    for (std::uint32_t i : visible)
      for (auto& f : cur) f[i] *= scale[i];
  }
  for (int pass = 0; pass < s.passes; ++pass) {
    sum_luminance();
    atrous_pass(tx, visible, 1 << pass, texel_m, s, pool, PassInput{cur, lum, variance}, next, next_variance);
    std::swap(cur, next);
    std::swap(variance, next_variance);
  }
  for (std::size_t f = 0; f < cur.size(); ++f) *fields[f] = std::move(cur[f]);
}

}  // namespace gi
