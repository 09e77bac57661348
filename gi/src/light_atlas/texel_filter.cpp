#include "light_atlas/texel_filter.h"

#include <cmath>

#include "light_atlas/local_linear.h"
#include "light_atlas/texel_cells.h"

namespace gi {

// Step 4: Gaussian over texels on the same plane within the radius, across chart borders.
// Each cell (of the radius) gathers its 27 neighbour cells' texels once and filters all of
// its own texels against them.
std::vector<glm::vec3> filter_world(const AtlasTexels& tx, std::span<const std::uint32_t> work,
                                    const std::vector<glm::vec3>& e, const std::vector<std::uint8_t>& hidden,
                                    float radius_m, float texel_m, ThreadPool& pool, float slope_ridge) {
  std::vector<std::uint32_t> visible;
  for (std::uint32_t i : work)
    if (!hidden[i]) visible.push_back(i);
  const TexelCells cells(tx, visible, radius_m);
  std::vector<glm::vec3> out = e;
  const float r2 = radius_m * radius_m, plane = 0.5f * texel_m;
  pool.parallel_for(
      cells.cell_count(),
      [&](std::size_t c) {
        struct Candidate {
          glm::vec3 position, normal, value;
        };
        std::vector<Candidate> near;
        cells.for_around(cells.cell(c), [&](std::uint32_t j) { near.push_back({tx.position[j], tx.normal[j], e[j]}); });
        std::vector<Neighbour> taken;
        cells.for_cell(c, [&](std::uint32_t i) {
          const glm::vec3 p = tx.position[i], n = tx.normal[i];
          const glm::mat3 frame = tangent_frame(n);
          taken.clear();
          for (std::size_t k = 0; k < near.size(); ++k) {
            const Candidate& q = near[k];
            const glm::vec3 d = q.position - p;
            const float d2 = glm::dot(d, d);
            if (d2 > r2 || glm::dot(q.normal, n) < 0.95f || std::fabs(glm::dot(d, n)) > plane) continue;
            taken.push_back({static_cast<std::uint32_t>(k), std::exp(-2.0f * d2 / r2),
                             glm::vec2(glm::dot(d, frame[0]), glm::dot(d, frame[1])) / radius_m});
          }
          if (slope_ridge >= 0.0f && !taken.empty()) to_linear_weights(slope_ridge, taken);
          glm::vec3 sum(0.0f);
          float weight = 0.0f;
          for (const Neighbour& q : taken) sum += near[q.j].value * q.w, weight += q.w;
          if (weight > 0.0f) out[i] = glm::max(sum / weight, glm::vec3(0.0f));
        });
      },
      4);
  return out;
}

}  // namespace gi
