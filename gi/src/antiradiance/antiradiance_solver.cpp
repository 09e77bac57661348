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

namespace {

// The growth test of both schemes: the residual sum exceeded the previous iteration's and
// the first one's `limit` iterations in a row.
struct GrowthWatch {
  int limit = 2;
  double first = -1.0, previous = -1.0;
  int growing = 0;
  bool grew(double change, int i) {
    if (first < 0.0) first = change;
    growing = (i > 0 && change > previous && change > first) ? growing + 1 : 0;
    previous = change;
    return growing >= std::max(limit, 1);
  }
};

// The symmetric iteration can stall short of the tolerance without growing (the corridor at
// 0.4 m elements: its residual hovers at ~2% for 64 iterations, where the asymmetric scheme
// converges in 12): stalled when, after kStallWindow iterations, the last kStallWindow
// did not halve the residual sum.
constexpr std::size_t kStallWindow = 8;
bool stalled(const std::vector<double>& changes) {
  const std::size_t n = changes.size();
  return n > 2 * kStallWindow && changes[n - 1] > 0.5 * changes[n - 1 - kStallWindow];
}

// Converged: the relative residual is below the tolerance. A warm start begins near the
// fixed point everywhere except where the door changed the light, so that alone would stop it
// while the change itself is still far from converged (its error shrinks by the iteration's
// rate per step, the same as a cold start's remainder); it also needs the residual down by
// warm_tolerance from its first iteration's (the change's error down by about that factor),
// or the whole residual negligible (below tolerance x warm_tolerance).
bool converged(const AntiradianceSettings& settings, const LocalPassSums& s, bool warm, double first_change) {
  if (!(settings.residual_tolerance > 0.0 && relative(s) < settings.residual_tolerance)) return false;
  if (!warm) return true;
  return s.change <= settings.warm_tolerance * first_change ||
         relative(s) < settings.residual_tolerance * settings.warm_tolerance;
}

// The symmetric scheme; false when it diverged (the report then holds its residual changes).
bool run_symmetric(AntiradiancePasses& passes, const AntiradianceSettings& settings, int budget,
                   AntiradianceSolveReport& report) {
  GrowthWatch watch{settings.growth_limit};
  for (int i = 0; i < budget; ++i) {
    const LocalPassSums s = step(passes, true, true);
    ++report.passes;
    if (!finite(s)) return false;
    report.residuals.push_back(relative(s));
    report.changes.push_back(s.change);
    report.iterations = i + 1;
    if (watch.grew(s.change, i)) return false;
    if (converged(settings, s, report.warm, report.changes.front())) {
      report.converged = true;
      break;
    }
    if (settings.residual_tolerance > 0.0 && stalled(report.changes)) {
      report.stalled = true;
      return false;
    }
  }
  return true;
}

void run_asymmetric(AntiradiancePasses& passes, const AntiradianceSettings& settings, int budget,
                    AntiradianceSolveReport& report) {
  report.scheme = AntiradianceScheme::Asymmetric;
  const int a_steps = std::max(settings.antiradiance_steps, 1);
  GrowthWatch watch{settings.growth_limit};
  double first_change = 0.0;
  for (int i = 0; i < budget; ++i) {
    for (int j = 0; j < a_steps; ++j) {
      step(passes, false, true);
      ++report.passes;
    }
    const LocalPassSums s = step(passes, true, false);
    ++report.passes;
    report.residuals.push_back(finite(s) ? relative(s) : std::numeric_limits<double>::infinity());
    report.iterations = i + 1;
    if (!finite(s) || watch.grew(s.change, i)) {
      report.diverged = true;
      break;
    }
    if (i == 0) first_change = s.change;
    if (converged(settings, s, report.warm, first_change)) {
      report.converged = true;
      break;
    }
  }
}

}  // namespace

AntiradianceSolveReport run_antiradiance(AntiradiancePasses& passes, std::span<const glm::vec3> direct,
                                         const AntiradianceSettings& settings, const ElementHierarchy& h,
                                         AntiradianceStart start) {
  AntiradianceSolveReport report;
  const int budget = std::max(settings.iterations, 0);
  report.warm = start == AntiradianceStart::Warm;
  if (report.warm)
    passes.warm_start(direct);
  else
    passes.reset(direct);
  bool done = false;
  if (settings.scheme == AntiradianceScheme::Symmetric) {
    done = run_symmetric(passes, settings, budget, report);
    if (!done) {
      report.fell_back = true;
      report.warm = false;
      report.residuals.clear();
      report.iterations = 0;
      passes.reset(direct);
    }
  }
  if (!done) run_asymmetric(passes, settings, budget, report);
  report.residual = report.residuals.empty() ? 0.0 : report.residuals.back();
  // Converged in the budget, or told to run exactly the budget (tolerance 0).
  report.budget_exhausted = settings.residual_tolerance > 0.0 && !report.converged && !report.diverged;
  check_energy(passes, h, direct, report);
  return report;
}

}  // namespace gi
