#include "antiradiance/antiradiance_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gi {

namespace {

double relative(const LocalPassSums& s) { return s.magnitude > 0.0 ? s.change / s.magnitude : 0.0; }

bool finite(const LocalPassSums& s) { return std::isfinite(s.change) && std::isfinite(s.magnitude); }

LocalPassSums step(AntiradiancePasses& p, bool radiance, bool antiradiance) {
  p.global();
  p.push();
  const LocalPassSums s = p.local(radiance, antiradiance);
  p.pull();
  return s;
}

}  // namespace

double indirect_flux_bound(const ElementHierarchy& h, std::span<const glm::vec3> direct) {
  double reflected = 0.0;
  float albedo_max = 0.0f;
  for (std::size_t l = 0; l < h.leaf_count() && l < direct.size(); ++l) {
    const ElementNode& n = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    const glm::vec3 r = n.area_m2 * n.albedo * direct[l];
    reflected += static_cast<double>(r.x) + static_cast<double>(r.y) + static_cast<double>(r.z);
    albedo_max = std::max({albedo_max, n.albedo.x, n.albedo.y, n.albedo.z});
  }
  return reflected / (1.0 - static_cast<double>(std::min(albedo_max, 0.999f)));
}

namespace {

// The energy guard: the indirect flux of the result against the bound.
void check_energy(const AntiradiancePasses& passes, const ElementHierarchy& h, std::span<const glm::vec3> direct,
                  AntiradianceSolveReport& report) {
  const std::vector<glm::vec3> e = passes.irradiance();
  double flux = 0.0;
  for (std::size_t l = 0; l < e.size() && l < h.leaf_count(); ++l) {
    const glm::vec3 a = h.nodes[static_cast<std::size_t>(h.leaves[l])].area_m2 * glm::abs(e[l]);
    flux += static_cast<double>(a.x) + static_cast<double>(a.y) + static_cast<double>(a.z);
  }
  report.indirect_flux = flux;
  report.flux_bound = indirect_flux_bound(h, direct);
  if (!std::isfinite(flux))
    report.output_scale = 0.0f;
  else if (flux > report.flux_bound)
    report.output_scale = static_cast<float>(report.flux_bound / flux);
}

}  // namespace

// Long because it is one solve with its fallback: the symmetric scheme until it converges or
// diverges, then the asymmetric one from the same start, both filling the one report.
AntiradianceSolveReport run_antiradiance(AntiradiancePasses& passes, std::span<const glm::vec3> direct,
                                         const AntiradianceSettings& settings, const ElementHierarchy& h) {
  AntiradianceSolveReport report;
  const int iterations = std::max(settings.iterations, 0);
  passes.reset(direct);

  if (settings.scheme == AntiradianceScheme::Symmetric) {
    double first = -1.0, previous = -1.0;
    int growing = 0;
    bool diverged = false;
    for (int i = 0; i < iterations; ++i) {
      const LocalPassSums s = step(passes, true, true);
      ++report.passes;
      if (!finite(s)) {
        diverged = true;
        break;
      }
      report.residuals.push_back(relative(s));
      report.changes.push_back(s.change);
      report.iterations = i + 1;
      if (first < 0.0) first = s.change;
      growing = (i > 0 && s.change > previous && s.change > first) ? growing + 1 : 0;
      previous = s.change;
      if (growing >= std::max(settings.growth_limit, 1)) {
        diverged = true;
        break;
      }
      if (settings.residual_tolerance > 0.0 && relative(s) < settings.residual_tolerance) break;
    }
    if (!diverged) {
      check_energy(passes, h, direct, report);
      return report;
    }
    report.fell_back = true;
    report.residuals.clear();
    report.iterations = 0;
    passes.reset(direct);
  }

  report.scheme = AntiradianceScheme::Asymmetric;
  const int a_steps = std::max(settings.antiradiance_steps, 1);
  double first = -1.0, previous = -1.0;
  int growing = 0;
  for (int i = 0; i < iterations; ++i) {
    for (int j = 0; j < a_steps; ++j) {
      step(passes, false, true);
      ++report.passes;
    }
    const LocalPassSums s = step(passes, true, false);
    ++report.passes;
    report.residuals.push_back(finite(s) ? relative(s) : std::numeric_limits<double>::infinity());
    report.iterations = i + 1;
    if (!finite(s)) {
      report.diverged = true;
      break;
    }
    if (first < 0.0) first = s.change;
    growing = (i > 0 && s.change > previous && s.change > first) ? growing + 1 : 0;
    previous = s.change;
    if (growing >= std::max(settings.growth_limit, 1)) {
      report.diverged = true;
      break;
    }
    if (settings.residual_tolerance > 0.0 && relative(s) < settings.residual_tolerance) break;
  }
  check_energy(passes, h, direct, report);
  return report;
}

}  // namespace gi
