#include "antiradiance/antiradiance_region.h"

#include <algorithm>
#include <chrono>

#include "bundle/atlas_layout_file.h"
#include "core/stopwatch.h"

namespace gi {

namespace {

using Clock = std::chrono::steady_clock;

engine::Status check_bins(const AntiradianceSettings& settings) {
  if (settings.bins_per_side < 1 || settings.bins_per_side > 64)
    return engine::Error{"", "antiradiance bake", "bins_per_side must lie in [1, 64]"};
  return {};
}

// The bake from the hierarchy and all its links (link_elements, or the merge of its shards).
engine::Result<AntiradianceBake> solve_baseline(const BakeInput& input, const AntiradianceSettings& settings,
                                                ElementHierarchy hierarchy, const LinkMesh& all, double link_seconds) {
  AntiradianceBake bake;
  bake.settings = settings;
  bake.hierarchy = std::move(hierarchy);
  bake.seconds.links = link_seconds;
  const DirectionalBins bins(settings.bins_per_side);
  auto t = Clock::now();
  bake.static_links = static_links(bake.hierarchy, all);
  bake.seconds.static_links = seconds_since(t);
  // The baseline: the region at the pose it is baked at (the pose the light atlas and the
  // PRM bake it at), direct light shadowed by it, all links; solved once.
  t = Clock::now();
  auto direct_light = AntiradianceDirectLight::create(input, settings);
  if (!direct_light) return direct_light.error();
  const std::vector<glm::vec3> direct = direct_light->irradiance(bake.hierarchy);
  bake.seconds.direct = seconds_since(t);
  t = Clock::now();
  CpuAntiradiancePasses base(bake.hierarchy, bins, all);
  const AntiradianceSolveReport rep = run_antiradiance(base, direct, settings, bake.hierarchy);
  bake.baseline = base.irradiance();
  for (glm::vec3& v : bake.baseline) v *= rep.output_scale;
  bake.seconds.solve = seconds_since(t);
  bake.baseline_report = rep;
  return bake;
}

}  // namespace

engine::Result<AntiradianceBake> bake_antiradiance(const BakeInput& input, const AntiradianceSettings& settings) {
  if (auto ok = check_bins(settings); !ok) return ok.error();
  auto h = build_element_hierarchy(input, settings);
  if (!h) return h.error();
  const DirectionalBins bins(settings.bins_per_side);
  const auto t = Clock::now();
  const LinkMesh all = link_elements(*h, bins, settings);
  return solve_baseline(input, settings, std::move(h).value(), all, seconds_since(t));
}

engine::Result<LinkMesh> bake_antiradiance_links_shard(const BakeInput& input, const AntiradianceSettings& settings,
                                                       const WorkShard& shard) {
  if (auto ok = check_bins(settings); !ok) return ok.error();
  auto h = build_element_hierarchy(input, settings);
  if (!h) return h.error();
  const DirectionalBins bins(settings.bins_per_side);
  return link_elements_shard(*h, bins, settings, shard);
}

engine::Result<AntiradianceBake> bake_antiradiance_from_link_shards(const BakeInput& input,
                                                                    const AntiradianceSettings& settings,
                                                                    const std::vector<std::vector<Link>>& parts) {
  if (auto ok = check_bins(settings); !ok) return ok.error();
  auto h = build_element_hierarchy(input, settings);
  if (!h) return h.error();
  const auto t = Clock::now();
  auto all = merge_link_shards(*h, parts);
  if (!all) return all.error();
  return solve_baseline(input, settings, std::move(h).value(), *all, seconds_since(t));
}

engine::Result<AntiradianceRegion> AntiradianceRegion::create(const BakeInput& input,
                                                              const AntiradianceSettings& settings) {
  auto bake = bake_antiradiance(input, settings);
  if (!bake) return bake.error();
  return create(input, std::move(bake).value());
}

engine::Result<AntiradianceRegion> AntiradianceRegion::create(const BakeInput& input, AntiradianceBake bake) {
  const ElementHierarchy& bh = bake.hierarchy;
  for (std::size_t g = 0; g < bh.deforming_instances.size(); ++g) {
    const std::uint32_t i = bh.deforming_instances[g];
    if (i >= input.instances.size() || !input.instances[i].deforming)
      return engine::Error{"", "antiradiance region",
                           "the bake's deforming instance " + std::to_string(i) + " is not a deforming instance of " +
                               (input.name.empty() ? std::string("the scene") : input.name)};
  }
  std::size_t deforming = 0;
  for (const BakeInstance& inst : input.instances) deforming += inst.deforming ? 1 : 0;
  if (deforming != bh.deforming_instances.size())
    return engine::Error{"", "antiradiance region",
                         "the scene has " + std::to_string(deforming) + " deforming instances, the bake " +
                             std::to_string(bh.deforming_instances.size())};
  auto direct = AntiradianceDirectLight::create(input, bake.settings);
  if (!direct) return direct.error();
  AntiradianceRegion r;
  r.settings_ = bake.settings;
  r.bins_ = std::make_unique<DirectionalBins>(bake.settings.bins_per_side);
  r.hierarchy_ = std::make_unique<ElementHierarchy>(std::move(bake.hierarchy));
  r.baseline_ = std::move(bake.baseline);
  r.links_ = std::make_unique<LinkMesh>(std::move(bake.static_links));
  r.direct_light_ = std::make_unique<AntiradianceDirectLight>(std::move(direct).value());
  r.baked_transform_ = r.hierarchy_->group_transform;
  // Place the deforming groups where `input` has them and link them.
  std::vector<int> groups;
  r.at_baked_pose_ = true;
  for (int g = 1; g < r.hierarchy_->group_count(); ++g) {
    const std::uint32_t i = r.hierarchy_->deforming_instances[static_cast<std::size_t>(g - 1)];
    // At the baked pose the elements keep their baked world values (bit for bit the
    // baseline's); elsewhere they are placed from object space.
    if (r.hierarchy_->group_transform[static_cast<std::size_t>(g - 1)] != input.instances[i].object_to_world) {
      r.hierarchy_->set_group_transform(g, input.instances[i].object_to_world);
      r.at_baked_pose_ = false;
    }
    groups.push_back(g);
  }
  // At the baked pose the bake's posed links are what relinking would make.
  if (r.at_baked_pose_ && bake.at_baked_pose.present)
    merge_posed_links(*r.hierarchy_, bake.at_baked_pose.links, *r.links_);
  else
    relink_moved(*r.hierarchy_, *r.bins_, r.settings_, groups, *r.links_);
  r.cpu_ = std::make_unique<CpuAntiradiancePasses>(*r.hierarchy_, *r.bins_, *r.links_);
  r.direct_ = r.direct_light_->irradiance(*r.hierarchy_);
  r.counters_ = {groups.size(), r.links_->relinked_elements, r.links_->links_made, r.links_->links.size()};
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
  at_baked_pose_ = false;
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
  adopted_.clear();
  if (!moved_.empty()) {
    std::sort(moved_.begin(), moved_.end());
    relink_moved(*hierarchy_, *bins_, settings_, moved_, *links_);
    counters_.moved_groups = moved_.size();
    counters_.relinked_elements = links_->relinked_elements;
    counters_.links_made = links_->links_made;
    direct_ = direct_light_->update(*hierarchy_);  // only the leaves the motion can change
    counters_.direct_leaves = direct_light_->last_recomputed();
    moved_.clear();
  }
  counters_.links = links_->links.size();
  if (!solve) return {};
  if (solved_ && posed_as_baked()) {
    // The baseline is this pose's solve; the tables keep the last pose's (the next warm start).
    last_ = {};
    last_.converged = true;
    showing_baseline_ = true;
    return last_;
  }
  const bool warm = settings_.warm_start && warm_startable_;
  last_ = run_antiradiance(*cpu_, direct_, settings_, *hierarchy_,
                           warm ? AntiradianceStart::Warm : AntiradianceStart::Cold);
  solved_ = true;
  // Only a converged solve's tables start the next one: the change is then the difference of
  // two solves within the tolerance of their fixed points, like the cold-started baseline's. An
  // unconverged one (a budget too small, or a fixed count: tolerance 0) would carry its
  // iterations over, and the change would hold the difference of iteration counts; a diverged
  // (or energy-clamped) one is no start either.
  warm_startable_ = last_.converged && !last_.diverged && last_.output_scale == 1.0f;
  showing_baseline_ = false;
  return last_;
}

bool AntiradianceRegion::posed_as_baked() const { return hierarchy_->group_transform == baked_transform_; }

void prepare_antiradiance_load(AntiradianceBake& bake, const BakeInput& input, const AtlasLayout* layout) {
  // The groups AntiradianceRegion::create relinks, at the pose the bake holds them.
  std::vector<int> groups;
  for (int g = 1; g < bake.hierarchy.group_count(); ++g) groups.push_back(g);
  const DirectionalBins bins(bake.settings.bins_per_side);
  AntiradianceBake::AtBakedPose& p = bake.at_baked_pose;
  p.links = posed_links(bake.hierarchy, bins, bake.settings, groups);
  p.blends.clear();
  p.layout_fingerprint = 0;
  if (layout != nullptr) {
    p.blends = antiradiance_texel_blends(bake.hierarchy, input, *layout);
    p.layout_fingerprint = atlas_layout_fingerprint(*layout);
  }
  p.present = true;
}

}  // namespace gi
