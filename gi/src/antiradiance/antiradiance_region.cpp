#include "antiradiance/antiradiance_region.h"

#include <algorithm>

namespace gi {

engine::Result<AntiradianceRegion> AntiradianceRegion::create(const BakeInput& input,
                                                              const AntiradianceSettings& settings) {
  if (settings.bins_per_side < 1 || settings.bins_per_side > 64)
    return engine::Error{"", "antiradiance region", "bins_per_side must lie in [1, 64]"};
  auto h = build_element_hierarchy(input, settings);
  if (!h) return h.error();
  auto direct = AntiradianceDirectLight::create(input, settings);
  if (!direct) return direct.error();
  AntiradianceRegion r;
  r.settings_ = settings;
  r.bins_ = std::make_unique<DirectionalBins>(settings.bins_per_side);
  r.hierarchy_ = std::make_unique<ElementHierarchy>(std::move(h).value());
  r.links_ = std::make_unique<LinkMesh>(link_elements(*r.hierarchy_, *r.bins_, settings));
  r.direct_light_ = std::make_unique<AntiradianceDirectLight>(std::move(direct).value());
  r.cpu_ = std::make_unique<CpuAntiradiancePasses>(*r.hierarchy_, *r.bins_, *r.links_);
  r.direct_ = r.direct_light_->irradiance(*r.hierarchy_);
  // The baseline: static links only, direct light without the region's shadows, solved once.
  {
    auto unshadowed = AntiradianceDirectLight::create(input, settings, true);
    if (!unshadowed) return unshadowed.error();
    std::vector<glm::vec3> base_direct = unshadowed->irradiance(*r.hierarchy_);
    for (std::size_t l = 0; l < base_direct.size(); ++l)
      if (r.hierarchy_->nodes[static_cast<std::size_t>(r.hierarchy_->leaves[l])].group != 0) base_direct[l] = glm::vec3(0.0f);
    const LinkMesh links = static_links(*r.hierarchy_, *r.links_);
    CpuAntiradiancePasses base(*r.hierarchy_, *r.bins_, links);
    const AntiradianceSolveReport rep = run_antiradiance(base, base_direct, settings, *r.hierarchy_);
    r.baseline_ = base.irradiance();
    for (glm::vec3& v : r.baseline_) v *= rep.output_scale;
  }
  r.counters_ = {0, r.links_->relinked_elements, r.links_->links_made, r.links_->links.size()};
  return r;
}

bool AntiradianceRegion::set_instance_transform(std::uint32_t instance, const glm::mat4& m) {
  const auto& d = hierarchy_->deforming_instances;
  const auto it = std::find(d.begin(), d.end(), instance);
  if (it == d.end()) return false;
  const int group = 1 + static_cast<int>(it - d.begin());
  if (hierarchy_->group_transform[static_cast<std::size_t>(group - 1)] == m) return false;
  hierarchy_->set_group_transform(group, m);
  direct_light_->set_instance_transform(instance, m);
  if (std::find(moved_.begin(), moved_.end(), group) == moved_.end()) moved_.push_back(group);
  return true;
}

std::vector<glm::vec3> AntiradianceRegion::delta(const std::vector<glm::vec3>& irradiance) const {
  std::vector<glm::vec3> out(irradiance);
  for (std::size_t l = 0; l < out.size() && l < baseline_.size(); ++l) out[l] -= baseline_[l];
  return out;
}

AntiradianceSolveReport AntiradianceRegion::update(bool solve) {
  counters_ = {};
  if (!moved_.empty()) {
    std::sort(moved_.begin(), moved_.end());
    relink_moved(*hierarchy_, *bins_, settings_, moved_, *links_);
    counters_.moved_groups = moved_.size();
    counters_.relinked_elements = links_->relinked_elements;
    counters_.links_made = links_->links_made;
    direct_ = direct_light_->irradiance(*hierarchy_);
    moved_.clear();
  }
  counters_.links = links_->links.size();
  if (!solve) return {};
  last_ = run_antiradiance(*cpu_, direct_, settings_, *hierarchy_);
  return last_;
}

}  // namespace gi
