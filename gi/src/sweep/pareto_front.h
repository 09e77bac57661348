#pragma once
// The accuracy/cost trade-off of a sweep: the runs no other run beats on both error and
// time, and the presets (preview / medium / high) picked from them by a stated rule.
//   std::vector<std::size_t> front = gi::pareto_front(points);
//   auto presets = gi::choose_presets(points, front, {});

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace gi {

/// One run on the trade-off plane: its error (relative RMSE) and its cost (seconds or ms).
struct ParetoPoint {
  double error = 0.0;
  double cost = 0.0;
};

/// Indices of the points not dominated by another point, sorted by cost ascending (so by
/// error descending). q dominates p when q.error <= p.error and q.cost <= p.cost with at
/// least one strict. Points with a non-finite error or cost are never on the front; exact
/// duplicates are both kept.
std::vector<std::size_t> pareto_front(std::span<const ParetoPoint> points);

/// Error targets of the presets (relative RMSE).
struct PresetTargets {
  double preview = 0.20;
  double medium = 0.05;
  double high = 0.01;
};

struct PresetChoice {
  std::string name;         ///< "preview", "medium", "high".
  double target = 0.0;      ///< Its error target.
  std::size_t index = 0;    ///< Index into the points.
  bool target_met = false;  ///< False when no front point reaches the target.
};

/// The rule: each preset is the CHEAPEST point of the front whose error is <= its target;
/// when no front point reaches the target, the most accurate front point, marked
/// target_met = false. Empty when the front is empty. Precondition: `front` as returned by
/// pareto_front(points).
std::vector<PresetChoice> choose_presets(std::span<const ParetoPoint> points, std::span<const std::size_t> front,
                                         const PresetTargets& targets);

}  // namespace gi
