#include "sweep/pareto_front.h"

#include <engine/check.h>

#include <algorithm>
#include <cmath>

namespace gi {

std::vector<std::size_t> pareto_front(std::span<const ParetoPoint> points) {
  auto usable = [](const ParetoPoint& p) { return std::isfinite(p.error) && std::isfinite(p.cost); };
  std::vector<std::size_t> front;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const ParetoPoint& p = points[i];
    if (!usable(p)) continue;
    bool dominated = false;
    for (std::size_t j = 0; j < points.size() && !dominated; ++j) {
      const ParetoPoint& q = points[j];
      dominated =
          j != i && usable(q) && q.error <= p.error && q.cost <= p.cost && (q.error < p.error || q.cost < p.cost);
    }
    if (!dominated) front.push_back(i);
  }
  std::stable_sort(front.begin(), front.end(), [&](std::size_t a, std::size_t b) {
    return points[a].cost < points[b].cost || (points[a].cost == points[b].cost && points[a].error > points[b].error);
  });
  return front;
}

std::vector<PresetChoice> choose_presets(std::span<const ParetoPoint> points, std::span<const std::size_t> front,
                                         const PresetTargets& targets) {
  std::vector<PresetChoice> out;
  if (front.empty()) return out;
  for (std::size_t i : front) GI_EXPECTS(i < points.size(), "choose_presets: front index out of range");
  const std::size_t most_accurate = *std::min_element(
      front.begin(), front.end(), [&](std::size_t a, std::size_t b) { return points[a].error < points[b].error; });
  const std::pair<const char*, double> presets[] = {
      {"preview", targets.preview}, {"medium", targets.medium}, {"high", targets.high}};
  for (const auto& [name, target] : presets) {
    PresetChoice c{name, target, most_accurate, false};
    for (std::size_t i : front) {  // sorted by cost: the first that meets the target is the cheapest
      if (points[i].error <= target) {
        c.index = i;
        c.target_met = true;
        break;
      }
    }
    out.push_back(c);
  }
  return out;
}

}  // namespace gi
