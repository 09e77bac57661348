#include "sweep/antiradiance_door_scoring.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "antiradiance/split_truth_change_score.h"
#include "raytrace/atlas_reference.h"
#include "uv/atlas_input.h"

namespace gi::antiradiance_sweep {
namespace {

// Other random streams than any bake's (see reference_sweep.cpp). The same for every pose,
// so a texel's paths that never meet the door are the same in every pose.
constexpr std::uint64_t kReferenceSeed = 0x616e746972616469ULL;

// "-50+-25+50" -> {-50, -25, 50}; "+25" -> {25}.
std::vector<float> parse_swings(const std::string& key) {
  std::vector<float> out;
  std::size_t at = 0;
  while (at < key.size()) {
    std::size_t end = key.find('+', at);
    if (end == std::string::npos) end = key.size();
    if (end > at) out.push_back(std::stof(key.substr(at, end - at)));
    at = end + 1;
  }
  return out;
}

}  // namespace

engine::Result<DoorSetup> door_setup(const SweepScene& scene, double density, double radius,
                                     const std::string& swings) {
  DoorSetup d;
  d.swings = parse_swings(swings);
  d.input = bake_input_from(scene.asset);
  bool found = false;
  for (std::size_t i = 0; i < d.input.instances.size() && !found; ++i)
    if (d.input.instances[i].deforming) {
      d.door = static_cast<std::uint32_t>(i);
      found = true;
    }
  if (!found) return engine::Error{.message = "the scene has no deforming instance (gi.region \"deforming\")"};
  d.authored = d.input.instances[d.door].object_to_world;
  const std::vector<AtlasInputMesh> inputs = atlas_inputs_from(d.input);
  auto layout = build_atlas_layout(inputs, {.texels_per_metre = static_cast<float>(density)});
  if (!layout) return layout.error();
  d.layout = std::move(layout).value();
  d.texels = rasterize_atlas(d.layout, inputs);
  // The door's swept bounds over the baked pose and the sweep's swings (whatever `swings`
  // scores, so that every run compares the same texels).
  glm::vec3 lo(std::numeric_limits<float>::infinity()), hi(-lo);
  const BakeMesh& mesh = d.input.meshes[d.input.instances[d.door].mesh];
  for (float swing : {0.0f, kSweepSwings[0], kSweepSwings[1], kSweepSwings[2]}) {
    const glm::mat4 m = d.pose(swing);
    for (const BakePrimitive& p : mesh.primitives)
      for (const glm::vec3& v : p.positions) {
        const glm::vec3 w(m * glm::vec4(v, 1.0f));
        lo = glm::min(lo, w);
        hi = glm::max(hi, w);
      }
  }
  std::vector<std::int32_t> static_instance;  // atlas input mesh -> BakeInput instance
  for (std::size_t i = 0; i < d.input.instances.size(); ++i)
    if (d.input.instances[i].mobility == BakeMobility::Static) static_instance.push_back(static_cast<std::int32_t>(i));
  d.mask.assign(d.texels.valid.size(), 0);
  for (std::size_t t = 0; t < d.texels.valid.size(); ++t) {
    if (!d.texels.valid[t] || d.texels.mesh[t] < 0 ||
        static_cast<std::size_t>(d.texels.mesh[t]) >= static_instance.size())
      continue;
    const auto inst = static_cast<std::size_t>(static_instance[static_cast<std::size_t>(d.texels.mesh[t])]);
    if (d.input.instances[inst].deforming) continue;
    const glm::vec3 p = d.texels.position[t];
    const glm::vec3 outside = glm::max(glm::max(lo - p, p - hi), glm::vec3(0.0f));
    if (glm::length(outside) > static_cast<float>(radius)) continue;
    d.mask[t] = 1;
    ++d.compared;
  }
  if (d.compared == 0) return engine::Error{.message = "no static atlas texel lies within the radius of the door"};
  return d;
}

// One random stream's indirect irradiance at the compared texels of every pose, texel-major
// per pose; `part` of `parts` of the job's progress.
namespace {

engine::Result<std::vector<glm::vec3>> door_truth_stream(const ReferenceJob& job, const DoorSetup& d,
                                                         std::uint64_t seed, int part, int parts) {
  const ReferenceRequest& r = job.request;
  AtlasTexels masked = d.texels;
  masked.valid = d.mask;
  const std::size_t n = masked.valid.size();
  const std::size_t poses = d.poses();
  std::vector<glm::vec3> values(n * poses, glm::vec3(0.0f));
  for (std::size_t k = 0; k < poses; ++k) {
    ReferenceSettings rs;
    rs.samples_per_pixel = std::stoi(r.param("spp"));
    rs.seed = seed;
    rs.threads = job.threads;
    if (!r.param("bounces").empty()) rs.max_bounces = std::stoi(r.param("bounces"));
    const ProgressFn& outer = job.progress;
    const double step = static_cast<double>(poses * static_cast<std::size_t>(parts));
    const double done = static_cast<double>(static_cast<std::size_t>(part) * poses + k);
    rs.progress = [&outer, done, step](double f) { return !outer || outer((done + f) / step); };
    auto truth = reference_atlas_irradiance(d.posed(k == 0 ? 0.0f : d.swings[k - 1]), masked, rs);
    if (!truth) return truth.error();
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t]) values[k * n + t] = truth->indirect[t];
  }
  return values;
}

}  // namespace

// The door's reference: the sweep's stream (or `seed`'s), and with `pair` a second,
// independent stream (the one `seed` = pair gives) stacked below it: rows [0, h poses) the
// first, [h poses, 2 h poses) the second (the split truth of split_truth_change_score.h).
engine::Result<RgbField> door_reference(const ReferenceJob& job) {
  const ReferenceRequest& r = job.request;
  if (std::find(kSwingChoices.begin(), kSwingChoices.end(), r.param("swings")) == kSwingChoices.end())
    return engine::Error{"<sweep>", r.key(), "unknown swings"};
  auto d = door_setup(job.scene, std::stod(r.param("texels_per_m")), std::stod(r.param("radius")), r.param("swings"));
  if (!d) return engine::Error{"<sweep>", r.key(), d.error().message};
  const std::uint64_t seed = r.param("seed").empty() ? kReferenceSeed : kReferenceSeed ^ std::stoull(r.param("seed"));
  const bool paired = !r.param("pair").empty();
  const int parts = paired ? 2 : 1;
  auto values = door_truth_stream(job, *d, seed, 0, parts);
  if (!values) return values.error();
  if (paired) {
    auto second = door_truth_stream(job, *d, kReferenceSeed ^ std::stoull(r.param("pair")), 1, parts);
    if (!second) return second.error();
    values->insert(values->end(), second->begin(), second->end());
  }
  std::vector<std::uint8_t> valid;
  for (int p = 0; p < parts * static_cast<int>(d->poses()); ++p)
    valid.insert(valid.end(), d->mask.begin(), d->mask.end());
  const int height = d->texels.height * static_cast<int>(d->poses()) * parts;
  return RgbField::from_texels(d->texels.width, height, *values, std::move(valid));
}

// What changing nothing scores (the baked atlas left as it is) on the same texels: the
// field with every moved pose's compared texels set back to the reference's baked pose.
RgbField nothing_changed(const RgbField& field, const RgbField& reference, const DoorSetup& d) {
  const std::size_t n = d.texels.valid.size();
  RgbField nothing = field;
  for (std::size_t k = 1; k < d.poses(); ++k)
    for (std::size_t t = 0; t < n; ++t)
      if (d.mask[t])
        for (int c = 0; c < 3; ++c)
          nothing.rgb[3 * (k * n + t) + static_cast<std::size_t>(c)] =
              reference.rgb[3 * t + static_cast<std::size_t>(c)];
  return nothing;
}

// The run's change against the split truth (two references, `a` the one the run was scored
// against, `b` independent of it): the error and the correlation of the change with the
// references' noise removed (split_truth_change_score.h), as `split_*` extras. `field` holds
// the run's moved poses as the baked truth of `a` plus the run's change.
std::vector<std::pair<std::string, double>> split_truth_extras(const DoorSetup& d, const RgbField& field,
                                                               const RgbField& a, const RgbField& b) {
  const std::size_t n = d.texels.valid.size();
  SplitTruthChangeScore all, nothing;
  double truth_sq = 0.0, level = 0.0;  // sum over moved poses of t^2 (unbiased: a b), the baked level
  for (std::size_t t = 0; t < n; ++t)
    if (d.mask[t]) level += 0.5 * static_cast<double>(glm::dot(ref_at(a, t) + ref_at(b, t), glm::vec3(1.0f)));
  level /= 3.0 * static_cast<double>(d.compared);
  std::vector<std::pair<std::string, double>> per_angle;
  for (std::size_t k = 1; k < d.poses(); ++k) {
    SplitTruthChangeScore pose, pose_nothing;
    for (std::size_t t = 0; t < n; ++t) {
      if (!d.mask[t] || !field.is_valid(k * n + t)) continue;
      const glm::vec3 m = ref_at(field, k * n + t) - ref_at(a, t);
      const glm::vec3 ca = ref_at(a, k * n + t) - ref_at(a, t), cb = ref_at(b, k * n + t) - ref_at(b, t);
      truth_sq += static_cast<double>(glm::dot(ref_at(a, k * n + t), ref_at(b, k * n + t)));
      for (int c = 0; c < 3; ++c) {
        pose.add(static_cast<double>(m[c]), static_cast<double>(ca[c]), static_cast<double>(cb[c]));
        pose_nothing.add(0.0, static_cast<double>(ca[c]), static_cast<double>(cb[c]));
      }
    }
    all.merge(pose);
    nothing.merge(pose_nothing);
    const int swing = static_cast<int>(d.swings[k - 1]);
    const std::string name = std::string(swing < 0 ? "m" : "p") + std::to_string(std::abs(swing));
    const double count = std::max(pose.samples(), 1.0);
    per_angle.emplace_back("split_change_nrmse_swing_" + name,
                           std::sqrt(std::max(0.0, pose.noise_removed_sse()) / count) / level);
    per_angle.emplace_back("split_nothing_nrmse_swing_" + name,
                           std::sqrt(std::max(0.0, pose_nothing.noise_removed_sse()) / count) / level);
  }
  std::vector<std::pair<std::string, double>> extras = {
      // As rel_rmse (the run's error against the first reference), the noise removed.
      {"split_rel_rmse", std::sqrt(std::max(0.0, all.noise_removed_sse()) / truth_sq)},
      {"split_nothing_rel_rmse", std::sqrt(std::max(0.0, nothing.noise_removed_sse()) / truth_sq)},
      // The noise of one reference's change, in the same units (what the old columns include).
      {"split_ref_noise_rel_rmse", std::sqrt(all.noise_of_one() / truth_sq)},
      {"split_change_correlation", all.correlation_noise_removed()},
      {"split_change_correlation_raw", all.correlation_raw()},
      {"split_change_fit_scale", all.fit_scale()}};
  extras.insert(extras.end(), per_angle.begin(), per_angle.end());
  return extras;
}

}  // namespace gi::antiradiance_sweep
