#include "antiradiance/antiradiance_passes.h"

#include <engine/check.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace gi {

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

void CpuAntiradiancePasses::global() {
  const std::size_t m = static_cast<std::size_t>(m_);
  for (std::size_t r = 0; r < h_.nodes.size(); ++r) {
    glm::vec3* row = &l_in_[r * m];
    std::fill(row, row + m, glm::vec3(0.0f));
    // Links of r sorted by (bin, sender): each bin's sum runs in link order from zero, as
    // one invocation of antiradiance_global.comp.glsl sums it.
    for (std::uint32_t k = links_.offsets[r]; k < links_.offsets[r + 1]; ++k) {
      const Link& l = links_.links[k];
      const auto b = static_cast<std::size_t>(l.bin);
      row[b] += l.form_factor * i_ex_[static_cast<std::size_t>(l.sender) * m + b];
    }
  }
}

void CpuAntiradiancePasses::push() {
  const std::size_t m = static_cast<std::size_t>(m_);
  for (std::size_t d = 1; d + 1 < level_offsets_.size(); ++d)
    for (std::uint32_t i = level_offsets_[d]; i < level_offsets_[d + 1]; ++i) {
      const auto n = static_cast<std::size_t>(by_level_[i]);
      const auto p = static_cast<std::size_t>(h_.nodes[n].parent);
      for (std::size_t b = 0; b < m; ++b) l_in_[n * m + b] += l_in_[p * m + b];
    }
}

LocalPassSums CpuAntiradiancePasses::local(bool radiance, bool antiradiance) {
  const std::size_t m = static_cast<std::size_t>(m_);
  LocalPassSums sums;
  for (std::size_t l = 0; l < h_.leaf_count(); ++l) {
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
    sums.change += static_cast<double>(change);
    sums.magnitude += static_cast<double>(magnitude);
  }
  return sums;
}

void CpuAntiradiancePasses::pull() {
  const std::size_t m = static_cast<std::size_t>(m_);
  for (std::size_t d = level_offsets_.size() - 1; d-- > 0;)
    for (std::uint32_t i = level_offsets_[d]; i < level_offsets_[d + 1]; ++i) {
      const auto n = static_cast<std::size_t>(by_level_[i]);
      const ElementNode& e = h_.nodes[n];
      if (e.child_count == 0) continue;
      for (std::size_t b = 0; b < m; ++b) {
        glm::vec3 sum(0.0f);
        for (std::int32_t c = 0; c < e.child_count; ++c)
          sum += i_ex_[static_cast<std::size_t>(h_.children[static_cast<std::size_t>(e.first_child + c)]) * m + b];
        i_ex_[n * m + b] = sum;
      }
    }
}

}  // namespace gi
