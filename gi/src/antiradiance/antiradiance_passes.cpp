#include "antiradiance/antiradiance_passes.h"

#include <engine/check.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gi {

namespace {

// Calls fn(i) for i in [begin, end) on TBB's threads, `grain` items at least per task. Every
// caller writes only item i's own entries, so the tables are bit for bit the same for any
// thread count (the tests compare 1 and 4 threads).
template <class Fn>
void for_each_item(std::size_t begin, std::size_t end, std::size_t grain, const Fn& fn) {
  if (begin >= end) return;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) fn(i);
  });
}

}  // namespace

void nodes_by_level(const ElementHierarchy& h, std::vector<std::int32_t>& nodes, std::vector<std::uint32_t>& offsets) {
  std::vector<std::int32_t> depth(h.nodes.size(), 0);
  std::int32_t deepest = 0;
  for (std::size_t n = 1; n < h.nodes.size(); ++n) {  // parents precede children (depth-first)
    depth[n] = depth[static_cast<std::size_t>(h.nodes[n].parent)] + 1;
    deepest = std::max(deepest, depth[n]);
  }
  offsets.assign(static_cast<std::size_t>(deepest) + 2, 0u);
  for (std::int32_t d : depth) ++offsets[static_cast<std::size_t>(d) + 1];
  for (std::size_t i = 1; i < offsets.size(); ++i) offsets[i] += offsets[i - 1];
  nodes.assign(h.nodes.size(), 0);
  std::vector<std::uint32_t> fill(offsets.begin(), offsets.end() - 1);
  for (std::size_t n = 0; n < h.nodes.size(); ++n)
    nodes[fill[static_cast<std::size_t>(depth[n])]++] = static_cast<std::int32_t>(n);
}

CpuAntiradiancePasses::CpuAntiradiancePasses(const ElementHierarchy& h, const DirectionalBins& bins,
                                             const LinkMesh& links)
    : h_(h), bins_(bins), links_(links), m_(bins.count()) {
  const std::size_t m = static_cast<std::size_t>(m_);
  i_ex_.assign(h.nodes.size() * m, glm::vec3(0.0f));
  l_in_.assign(h.nodes.size() * m, glm::vec3(0.0f));
  nodes_by_level(h, by_level_, level_offsets_);
  i_l_.assign(h.leaf_count() * m, glm::vec3(0.0f));
  i_a_.assign(h.leaf_count() * m, glm::vec3(0.0f));
  e_.assign(h.leaf_count(), glm::vec3(0.0f));
  direct_.assign(h.leaf_count(), glm::vec3(0.0f));
  leaf_sums_.assign(h.leaf_count(), glm::vec2(0.0f));
}

void CpuAntiradiancePasses::reset(std::span<const glm::vec3> direct) {
  GI_EXPECTS(direct.size() == h_.leaf_count(), "reset: one direct irradiance per leaf");
  direct_.assign(direct.begin(), direct.end());
  // The local pass over zero incident light writes I_L from the direct light, I_A = 0, E = 0
  // (what the GPU twin does too).
  for (auto* t : {&l_in_, &i_a_, &i_ex_}) std::fill(t->begin(), t->end(), glm::vec3(0.0f));
  local(true, true);
  pull();
}

void CpuAntiradiancePasses::warm_start(std::span<const glm::vec3> direct) {
  GI_EXPECTS(direct.size() == h_.leaf_count(), "warm_start: one direct irradiance per leaf");
  // The local pass reads the leaves' normals and areas from the hierarchy itself.
  direct_.assign(direct.begin(), direct.end());
}

void CpuAntiradiancePasses::global() {
  const std::size_t m = static_cast<std::size_t>(m_);
  // One receiver's row per item (its links are contiguous): 16 rows a task at least.
  for_each_item(0, h_.nodes.size(), 16, [&](std::size_t r) {
    glm::vec3* row = &l_in_[r * m];
    std::fill(row, row + m, glm::vec3(0.0f));
    // Links of r sorted by (bin, sender): each bin's sum runs in link order from zero, as
    // one invocation of antiradiance_global.comp.glsl sums it.
    for (std::uint32_t k = links_.offsets[r]; k < links_.offsets[r + 1]; ++k) {
      const Link& l = links_.links[k];
      const auto b = static_cast<std::size_t>(l.bin);
      row[b] += l.form_factor * i_ex_[static_cast<std::size_t>(l.sender) * m + b];
    }
  });
}

void CpuAntiradiancePasses::push() {
  const std::size_t m = static_cast<std::size_t>(m_);
  // Level by level (a node reads its parent's finished row); the nodes of a level in parallel.
  for (std::size_t d = 1; d + 1 < level_offsets_.size(); ++d)
    for_each_item(level_offsets_[d], level_offsets_[d + 1], 64, [&](std::size_t i) {
      const auto n = static_cast<std::size_t>(by_level_[i]);
      const auto p = static_cast<std::size_t>(h_.nodes[n].parent);
      for (std::size_t b = 0; b < m; ++b) l_in_[n * m + b] += l_in_[p * m + b];
    });
}

LocalPassSums CpuAntiradiancePasses::local(bool radiance, bool antiradiance) {
  const std::size_t m = static_cast<std::size_t>(m_);
  // Each leaf on its own (its partial sums into leaf_sums_), then the sums in leaf order.
  for_each_item(0, h_.leaf_count(), 16, [&](std::size_t l) {
    const std::size_t n = static_cast<std::size_t>(h_.leaves[l]);
    const ElementNode& e = h_.nodes[n];
    glm::vec3 irradiance(0.0f);
    for (std::size_t b = 0; b < m; ++b) {
      const float cos_minus = std::max(0.0f, -glm::dot(e.normal, bins_.direction(static_cast<int>(b))));
      irradiance += (cos_minus * bins_.solid_angle(static_cast<int>(b))) * l_in_[n * m + b];
    }
    constexpr float kInvPi = 0.318309886183790671538f;  // as antiradiance_local.comp.glsl
    const glm::vec3 reflected = e.albedo * kInvPi * (irradiance + direct_[l]);
    if (radiance) e_[l] = irradiance;
    float change = 0.0f, magnitude = 0.0f;
    for (std::size_t b = 0; b < m; ++b) {
      const float c = glm::dot(e.normal, bins_.direction(static_cast<int>(b)));
      if (radiance) i_l_[l * m + b] = (e.area_m2 * std::max(0.0f, c)) * reflected;
      if (antiradiance) i_a_[l * m + b] = (e.area_m2 * std::max(0.0f, -c)) * l_in_[n * m + b];
      const glm::vec3 ex = i_l_[l * m + b] - i_a_[l * m + b];
      const glm::vec3 d = glm::abs(ex - i_ex_[n * m + b]);
      const glm::vec3 a = glm::abs(ex);
      change += d.x + d.y + d.z;
      magnitude += a.x + a.y + a.z;
      i_ex_[n * m + b] = ex;
    }
    leaf_sums_[l] = {change, magnitude};
  });
  LocalPassSums sums;
  for (const glm::vec2& s : leaf_sums_) {
    sums.change += static_cast<double>(s.x);
    sums.magnitude += static_cast<double>(s.y);
  }
  return sums;
}

void CpuAntiradiancePasses::pull() {
  const std::size_t m = static_cast<std::size_t>(m_);
  // From the deepest level up (a node reads its children's finished rows); a level in parallel.
  for (std::size_t d = level_offsets_.size() - 1; d-- > 0;)
    for_each_item(level_offsets_[d], level_offsets_[d + 1], 16, [&](std::size_t i) {
      const auto n = static_cast<std::size_t>(by_level_[i]);
      const ElementNode& e = h_.nodes[n];
      if (e.child_count == 0) return;
      for (std::size_t b = 0; b < m; ++b) {
        glm::vec3 sum(0.0f);
        for (std::int32_t c = 0; c < e.child_count; ++c)
          sum += i_ex_[static_cast<std::size_t>(h_.children[static_cast<std::size_t>(e.first_child + c)]) * m + b];
        i_ex_[n * m + b] = sum;
      }
    });
}

}  // namespace gi
