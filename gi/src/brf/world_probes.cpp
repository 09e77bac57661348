#include "brf/world_probes.h"

#include <engine/finite.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "brf/spherical_harmonics.h"
#include "core/thread_pool.h"
#include "raytrace/ray.h"
#include "raytrace/ray_caster.h"
#include "raytrace/ray_offset.h"

namespace gi {

namespace {}  // namespace

bool WorldProbeGrid::radiance(const glm::vec3& p, std::array<glm::vec3, 9>& out) const {
  out.fill(glm::vec3(0.0f));
  if (radiance_sh.empty() || !engine::all_finite(p)) return false;
  const glm::vec3 g = (p - origin) / spacing;
  const glm::ivec3 last = dims - 1;
  const glm::vec3 clamped = glm::clamp(g, glm::vec3(0.0f), glm::vec3(last));
  const glm::ivec3 i0 = glm::min(glm::ivec3(glm::floor(clamped)), glm::max(last - 1, glm::ivec3(0)));
  const glm::vec3 f = glm::clamp(clamped - glm::vec3(i0), glm::vec3(0.0f), glm::vec3(1.0f));
  float weight = 0.0f;
  for (int c = 0; c < 8; ++c) {
    const glm::ivec3 o(c & 1, (c >> 1) & 1, (c >> 2) & 1);
    const glm::ivec3 q = glm::min(i0 + o, last);
    const std::size_t k =
        static_cast<std::size_t>(q.x) +
        static_cast<std::size_t>(dims.x) *
            (static_cast<std::size_t>(q.y) + static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(q.z));
    if (valid[k] == 0) continue;
    const float w = (o.x != 0 ? f.x : 1.0f - f.x) * (o.y != 0 ? f.y : 1.0f - f.y) * (o.z != 0 ? f.z : 1.0f - f.z);
    if (w <= 0.0f) continue;
    for (std::size_t j = 0; j < 9; ++j) out[j] += w * radiance_sh[k][j];
    weight += w;
  }
  if (weight <= 0.0f) return false;
  for (glm::vec3& v : out) v /= weight;
  return true;
}

glm::vec3 WorldProbeGrid::irradiance(const glm::vec3& p, const glm::vec3& n) const {
  const float nl = glm::length(n);
  if (!engine::all_finite(n) || !(nl > 0.0f)) return glm::vec3(0.0f);
  std::array<glm::vec3, 9> l;
  if (!radiance(p, l)) return glm::vec3(0.0f);
  const auto lobe = sh_clamped_cosine(n / nl, 3);
  glm::vec3 e(0.0f);
  for (std::size_t j = 0; j < 9; ++j) e += lobe[j] * l[j];
  return glm::max(e, glm::vec3(0.0f));  // 3-band ringing must not make light negative
}

// Long because it is one bake: bound the VPLs, size and centre the grid, then one parallel
// loop per probe (the inside test, the VPLs gathered into SH) that reads the grid set up before it.
engine::Result<WorldProbeGrid> bake_world_probes(const RayCaster& static_world, const VplSet& vpls,
                                                 std::span<const glm::vec3> vpl_power,
                                                 const WorldProbeSettings& settings) {
  const std::size_t n = vpls.size();
  if (vpl_power.size() != n || vpls.normal.size() != n || vpls.area_m2.size() != n)
    return engine::Error{.message = "world probes: VPL arrays of different sizes (" + std::to_string(n) + " VPLs, " +
                                    std::to_string(vpl_power.size()) + " powers)"};
  if (!(settings.spacing_m > 0.0f) || !std::isfinite(settings.spacing_m) || settings.max_probes < 8)
    return engine::Error{.message = "world probes: spacing must be positive and finite, max_probes >= 8"};
  WorldProbeGrid grid;
  if (n == 0) return grid;
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (std::size_t i = 0; i < n; ++i) {
    if (!engine::all_finite(vpls.position[i]) || !engine::all_finite(vpls.normal[i]) ||
        !engine::all_finite(vpl_power[i]) || !std::isfinite(vpls.area_m2[i]))
      return engine::Error{.message = "world probes: VPL " + std::to_string(i) + " has a non-finite value"};
    lo = glm::min(lo, vpls.position[i]);
    hi = glm::max(hi, vpls.position[i]);
  }
  // VPLs on one plane (an open floor, flat terrain) made a grid one probe thick lying in that
  // plane, where every probe sees the VPLs edge-on: objects standing on the floor got no world
  // light at all. Every axis spans at least two cells, grown on both sides (the probe below a
  // floor sees none of it and stays invalid; the one above it lights what stands there).
  {
    const glm::vec3 grow = glm::max(glm::vec3(2.0f * settings.spacing_m) - (hi - lo), glm::vec3(0.0f)) * 0.5f;
    lo -= grow;
    hi += grow;
  }
  // Cells counted in double before any integer conversion: VPLs 2e9 m apart must widen the
  // spacing, not overflow the dimensions.
  const glm::dvec3 extent = glm::dvec3(hi) - glm::dvec3(lo);
  double spacing_d = settings.spacing_m;
  for (;;) {
    const glm::dvec3 cells = glm::max(glm::ceil(extent / spacing_d), glm::dvec3(1.0));
    if (cells.x * cells.y * cells.z <= double(settings.max_probes)) {
      grid.dims = glm::ivec3(cells);
      break;
    }
    spacing_d *= 1.25;
  }
  const float spacing = static_cast<float>(spacing_d);
  grid.spacing = spacing;
  // Centre the grid on the VPLs' box, one probe per cell at its centre: no probe lies on the
  // box's faces, which are a room's walls, floor and ceiling. (With probes on the box's
  // corners, a probe on a wall saw almost none of the room, came out valid but dark and
  // darkened every point near a wall: 20 cm from one, 0.23 W/m^2 against the path tracer's 1.12.)
  // Points between the outer probes and the walls take the outer probes' light (clamped).
  grid.origin = 0.5f * (lo + hi) - 0.5f * spacing * glm::vec3(grid.dims - 1);
  const std::size_t count = static_cast<std::size_t>(grid.dims.x) * static_cast<std::size_t>(grid.dims.y) *
                            static_cast<std::size_t>(grid.dims.z);
  grid.radiance_sh.assign(count, {});
  grid.valid.assign(count, 0);

  ThreadPool pool(settings.threads);
  pool.parallel_for(
      count,
      [&](std::size_t k) {
        const std::size_t x = k % static_cast<std::size_t>(grid.dims.x);
        const std::size_t y = (k / static_cast<std::size_t>(grid.dims.x)) % static_cast<std::size_t>(grid.dims.y);
        const std::size_t z = k / (static_cast<std::size_t>(grid.dims.x) * static_cast<std::size_t>(grid.dims.y));
        const glm::vec3 p =
            grid.origin + spacing * glm::vec3(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
        std::array<glm::vec3, 9> sh{};
        bool any = false;
        // A probe that sees the back of a surface stands behind a wall or inside an object:
        // its light is not that of the space its neighbours interpolate into (valid = 0).
        constexpr int kInsideRays = 64;
        for (int r = 0; r < kInsideRays; ++r) {
          const float cz = 1.0f - (2.0f * static_cast<float>(r) + 1.0f) / kInsideRays;
          const float rho = std::sqrt(std::max(0.0f, 1.0f - cz * cz));
          const float phi = 2.399963229728653f * static_cast<float>(r);
          const glm::vec3 dir(rho * std::cos(phi), rho * std::sin(phi), cz);
          const Hit hit = static_world.intersect(Ray{.origin = p, .t_min = 0.0f, .direction = dir});
          if (hit.valid() && glm::dot(hit.geometric_normal, dir) > 0.0f) return;
        }
        for (std::size_t i = 0; i < n; ++i) {
          const glm::vec3 to_probe = p - vpls.position[i];
          const float d2 = glm::dot(to_probe, to_probe);
          if (!(d2 > 0.0f)) continue;
          const float d = std::sqrt(d2);
          const glm::vec3 w_out = to_probe / d;
          const float cos_v = glm::dot(vpls.normal[i], w_out);
          if (cos_v <= 0.0f) continue;
          const glm::vec3 start = offset_ray_origin(vpls.position[i], vpls.normal[i]);
          const glm::vec3 dir = p - start;
          if (static_world.occluded(Ray{.origin = start, .t_min = 0.0f, .direction = dir, .t_max = 1.0f})) continue;
          any = true;
          const glm::vec3 flux = vpl_power[i] * (cos_v / (std::numbers::pi_v<float> * d2 + vpls.area_m2[i]));
          const auto y_lm = sh_basis(-w_out);  // direction from the probe towards the VPL
          for (std::size_t j = 0; j < 9; ++j) sh[j] += y_lm[j] * flux;
        }
        grid.radiance_sh[k] = sh;
        grid.valid[k] = any ? 1 : 0;
      },
      4);
  return grid;
}

engine::Result<WorldProbeTransfer> bake_world_probe_transfer(const RayCaster& static_world, const WorldProbeGrid& grid,
                                                             std::span<const glm::vec3> position,
                                                             std::span<const glm::vec3> normal,
                                                             std::span<const float> area_m2, unsigned threads) {
  const std::size_t n = position.size();
  if (normal.size() != n || area_m2.size() != n)
    return engine::Error{.message = "world probe transfer: emitter arrays of different sizes (" + std::to_string(n) +
                                    " positions, " + std::to_string(normal.size()) + " normals, " +
                                    std::to_string(area_m2.size()) + " areas)"};
  for (std::size_t i = 0; i < n; ++i)
    if (!engine::all_finite(position[i]) || !engine::all_finite(normal[i]) || !std::isfinite(area_m2[i]))
      return engine::Error{.message = "world probe transfer: emitter " + std::to_string(i) + " has a non-finite value"};
  WorldProbeTransfer t;
  t.emitter_count = n;
  const std::size_t count = grid.probe_count();
  std::vector<std::vector<std::uint32_t>> seen(count);
  std::vector<std::vector<std::array<float, 9>>> coeff(count);
  ThreadPool pool(threads);
  pool.parallel_for(
      count,
      [&](std::size_t k) {
        if (grid.valid[k] == 0) return;
        const std::size_t x = k % static_cast<std::size_t>(grid.dims.x);
        const std::size_t y = (k / static_cast<std::size_t>(grid.dims.x)) % static_cast<std::size_t>(grid.dims.y);
        const std::size_t z = k / (static_cast<std::size_t>(grid.dims.x) * static_cast<std::size_t>(grid.dims.y));
        const glm::vec3 p =
            grid.origin + grid.spacing * glm::vec3(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
        for (std::size_t i = 0; i < n; ++i) {  // as bake_world_probes, with the power left out
          const glm::vec3 to_probe = p - position[i];
          const float d2 = glm::dot(to_probe, to_probe);
          if (!(d2 > 0.0f)) continue;
          const glm::vec3 w_out = to_probe / std::sqrt(d2);
          const float cos_v = glm::dot(normal[i], w_out);
          if (cos_v <= 0.0f) continue;
          const glm::vec3 start = offset_ray_origin(position[i], normal[i]);
          if (static_world.occluded(Ray{.origin = start, .t_min = 0.0f, .direction = p - start, .t_max = 1.0f}))
            continue;
          const float kernel = cos_v / (std::numbers::pi_v<float> * d2 + area_m2[i]);
          const auto y_lm = sh_basis(-w_out);
          std::array<float, 9> c{};
          for (std::size_t j = 0; j < 9; ++j) c[j] = y_lm[j] * kernel;
          seen[k].push_back(static_cast<std::uint32_t>(i));
          coeff[k].push_back(c);
        }
      },
      4);
  t.first.assign(count + 1, 0);
  for (std::size_t k = 0; k < count; ++k) t.first[k + 1] = t.first[k] + static_cast<std::uint32_t>(seen[k].size());
  t.emitter.reserve(t.first[count]);
  t.coefficient.reserve(t.first[count]);
  for (std::size_t k = 0; k < count; ++k) {
    t.emitter.insert(t.emitter.end(), seen[k].begin(), seen[k].end());
    t.coefficient.insert(t.coefficient.end(), coeff[k].begin(), coeff[k].end());
  }
  return t;
}

engine::Result<std::vector<std::array<glm::vec3, 9>>> reproject_world_probes(const WorldProbeTransfer& transfer,
                                                                             std::span<const glm::vec3> power) {
  if (power.size() != transfer.emitter_count)
    return engine::Error{.message = "world probe reprojection: " + std::to_string(power.size()) + " powers for " +
                                    std::to_string(transfer.emitter_count) + " emitters"};
  for (std::size_t i = 0; i < power.size(); ++i)
    if (!engine::all_finite(power[i]))
      return engine::Error{.message =
                               "world probe reprojection: emitter " + std::to_string(i) + " has a non-finite power"};
  const std::size_t count = transfer.first.empty() ? 0 : transfer.first.size() - 1;
  std::vector<std::array<glm::vec3, 9>> sh(count);
  for (std::size_t k = 0; k < count; ++k) {
    std::array<glm::vec3, 9> acc{};
    for (std::uint32_t e = transfer.first[k]; e < transfer.first[k + 1]; ++e) {
      const glm::vec3 phi = power[transfer.emitter[e]];
      for (std::size_t j = 0; j < 9; ++j) acc[j] += transfer.coefficient[e][j] * phi;
    }
    sh[k] = acc;
  }
  return sh;
}

}  // namespace gi
