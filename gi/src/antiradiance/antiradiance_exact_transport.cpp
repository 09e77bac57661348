#include "antiradiance/antiradiance_exact_transport.h"

#include <engine/check.h>
#include <engine/segment_box.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/polygon_form_factor.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/scene_adapter.h"

namespace gi {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kMinClosePairs = 16;
constexpr int kMaxReusedPairs = 64;      // at most four 16-bit words of visibility bits per leaf pair
constexpr std::size_t kBatchRays = 256;  // rays queued before a flush (one stream)

std::uint64_t mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

float unit(std::uint64_t& state) {
  state = mix(state);
  return static_cast<float>(state >> 40) * (1.0f / 16777216.0f);
}

// A uniform point of triangle (a, b, c) from (u, v) in [0, 1)^2 (the square folded on its diagonal).
glm::vec3 on_triangle(const glm::vec3* t, float u, float v) {
  if (u + v > 1.0f) {
    u = 1.0f - u;
    v = 1.0f - v;
  }
  return t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0]);
}

// Leaves near enough for the 1/r^2 peak (touching, or nearly): within twice their radii.
bool close_pair(const ElementNode& ei, const ElementNode& ej) {
  const float reach = 2.0f * (ei.radius_m + ej.radius_m);
  return glm::dot(ei.center - ej.center, ei.center - ej.center) < reach * reach;
}

// True when every corner of `t` lies on or behind the plane through `p` with normal `n`.
bool behind(const glm::vec3* t, const glm::vec3& p, const glm::vec3& n) {
  for (int k = 0; k < 3; ++k)
    if (glm::dot(t[k] - p, n) > 1e-6f) return false;
  return true;
}

// A Jacobi step's change: sum |dE|, sum E, and the largest share any one leaf moved (|dE_l|
// over its own E_l, or over 1% of the mean E for the darkest leaves).
struct StepChange {
  double change = 0.0, total = 0.0, worst_leaf = 0.0;
};

template <class Old, class New>
StepChange step_change(std::size_t count, Old old_at, New new_at) {
  StepChange c;
  for (std::size_t q = 0; q < count; ++q) {
    const glm::vec3 e = new_at(q), d = e - old_at(q);
    c.change += static_cast<double>(std::abs(d.x) + std::abs(d.y) + std::abs(d.z));
    c.total += static_cast<double>(e.x + e.y + e.z);
  }
  const double floor = count > 0 ? 0.01 * std::abs(c.total) / static_cast<double>(count) : 0.0;
  for (std::size_t q = 0; q < count; ++q) {
    const glm::vec3 e = new_at(q), d = e - old_at(q);
    const double moved = static_cast<double>(std::abs(d.x) + std::abs(d.y) + std::abs(d.z));
    const double level = static_cast<double>(std::abs(e.x) + std::abs(e.y) + std::abs(e.z));
    if (moved > 0.0) c.worst_leaf = std::max(c.worst_leaf, moved / std::max(level, floor));
  }
  return c;
}

// The Jacobi solves' shared bookkeeping after each step: the iteration count and the relative
// residuals (the step's change over the irradiance it reached, overall and at the leaf that
// moved most). True when the solve stops: it diverged (not converged, and visibly so), or with
// a tolerance (bounces <= 0) it converged overall and at every leaf.
bool end_of_step(ExactSolveResult& out, int it, const StepChange& c, const ExactTransportSettings& s) {
  out.iterations = it + 1;
  out.residual = c.total > 0.0 ? c.change / c.total : 0.0;
  out.leaf_residual = c.worst_leaf;
  if (!std::isfinite(c.total)) return true;
  if (s.bounces <= 0 && out.residual < s.tolerance && out.leaf_residual < s.leaf_tolerance) {
    out.converged = true;
    return true;
  }
  return false;
}

}  // namespace

std::size_t ExactLeafTransport::row_bytes_per_leaf(int point_pairs) {
  const auto words = static_cast<std::size_t>(std::max(point_pairs, kMinClosePairs) + 15) / 16;
  return sizeof(float) + words * sizeof(std::uint16_t);
}

engine::Result<ExactLeafTransport> ExactLeafTransport::create(const BakeInput& input,
                                                              const ExactTransportSettings& settings) {
  if (settings.point_pairs < 1) return engine::Error{.message = "exact transport: point_pairs must be at least 1"};
  if (settings.reuse_visibility && settings.point_pairs > kMaxReusedPairs)
    return engine::Error{.message = "exact transport: reuse_visibility keeps at most 64 point pairs per leaf pair"};
  if (engine::Status st = validate_bake_input(input); !st) return st.error();
  ExactLeafTransport out;
  out.settings_ = settings;
  RtSceneData data = rt_scene_from(input);
  out.moving_ = MovingInstances::mark(input, data);
  if (!settings.reuse_visibility || !settings.door_only_rays) {
    auto caster = make_embree_ray_caster(data);
    if (!caster) return caster.error();
    out.caster_ = std::move(caster).value();
    return out;
  }
  // door_only_rays: the static instances in one scene, the deforming ones in another (the
  // same instancing as in the whole scene's), and each deforming one's box at its pose.
  RtSceneData statics, doors;
  statics.geometries = data.geometries;
  doors.geometries = data.geometries;
  out.door_slot_.assign(input.instances.size(), -1);
  out.door_box_.resize(input.instances.size());
  for (std::size_t i = 0; i < data.instances.size(); ++i) {
    if (!out.moving_.deforming(static_cast<std::int32_t>(i))) {
      statics.instances.push_back(data.instances[i]);
      continue;
    }
    out.door_slot_[i] = static_cast<std::int32_t>(doors.instances.size());
    doors.instances.push_back(data.instances[i]);
    MovingInstances::Box& b = out.door_box_[i];
    b = {glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
    for (const glm::vec3& v : data.geometries[data.instances[i].geometry].positions)
      b.lo = glm::min(b.lo, v), b.hi = glm::max(b.hi, v);
    out.door_now_.push_back(out.world_box(static_cast<std::uint32_t>(i), data.instances[i].object_to_world));
  }
  auto caster = make_embree_ray_caster(statics);
  if (!caster) return caster.error();
  out.caster_ = std::move(caster).value();
  auto door_caster = make_embree_ray_caster(doors);
  if (!door_caster) return door_caster.error();
  out.door_caster_ = std::move(door_caster).value();
  return out;
}

// As MovingInstances' swept boxes: the object box's corners transformed, a 1 cm margin.
MovingInstances::Box ExactLeafTransport::world_box(std::uint32_t instance, const glm::mat4& m) const {
  const MovingInstances::Box& o = door_box_[instance];
  MovingInstances::Box w{glm::vec3(std::numeric_limits<float>::infinity()),
                         glm::vec3(-std::numeric_limits<float>::infinity())};
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? o.hi.x : o.lo.x, (c & 2) ? o.hi.y : o.lo.y, (c & 4) ? o.hi.z : o.lo.z);
    const glm::vec3 p(m * glm::vec4(corner, 1.0f));
    w.lo = glm::min(w.lo, p), w.hi = glm::max(w.hi, p);
  }
  w.lo -= glm::vec3(0.01f), w.hi += glm::vec3(0.01f);
  return w;
}

void ExactLeafTransport::set_instance_transform(std::uint32_t instance, const glm::mat4& m) {
  GI_EXPECTS(moving_.deforming(static_cast<std::int32_t>(instance)),
             "ExactLeafTransport: only deforming instances move");
  moving_.move(instance, m);
  if (!door_caster_) {
    caster_->set_instance_transform(instance, m);
  } else {
    const auto slot = static_cast<std::size_t>(door_slot_[instance]);
    door_caster_->set_instance_transform(static_cast<std::uint32_t>(slot), m);
    door_now_[slot] = world_box(instance, m);
  }
  dirty_ = true;
}

std::size_t ExactLeafTransport::pair_index(std::size_t i, std::size_t j) const {
  return i * n_ - i * (i + 1) / 2 + (j - i - 1);
}

std::size_t ExactLeafTransport::pair_slot(std::size_t i, std::size_t j) const {
  if (slot_.empty()) return pair_index(i, j);
  return slot_[i] >= 0 ? static_cast<std::size_t>(slot_[i]) * n_ + j : static_cast<std::size_t>(slot_[j]) * n_ + i;
}

float ExactLeafTransport::coupling(std::size_t i, std::size_t j) const {
  if (i == j) return 0.0f;
  if (i > j) std::swap(i, j);
  if (slot_.empty()) return g_[pair_index(i, j)];
  if (slot_[i] >= 0) return rows_[static_cast<std::size_t>(slot_[i]) * n_ + j];
  if (slot_[j] >= 0) return rows_[static_cast<std::size_t>(slot_[j]) * n_ + i];
  return 0.0f;  // neither a receiver: never computed
}

// Pairs queued for their rays: a task's pairs of one row, traced together (one stream of the
// samples of neighbouring pairs).
struct ExactLeafTransport::PairBatch {
  struct Pair {
    std::size_t i, j;
    std::uint32_t first, count;  // its samples in `samples`
    int m;                       // the divisor: the point pairs drawn (skipped ones count as 0)
    bool zero;                   // back to back: G = 0, nothing drawn
  };
  struct Sample {
    float weight;  // cos cos / max(r^2, min r^2)
    // Its ray in `rays` (the caster's scene: the whole, or the static part with door_only_rays),
    // or -1: the stored bit; and in `door_rays` (the deforming instances alone), or -1: none.
    std::int32_t ray, door_ray;
    std::uint32_t bit;  // the sample's index s (its visibility bit)
  };
  std::vector<Pair> pairs;
  std::vector<Sample> samples;
  std::vector<Ray> rays, door_rays;
  std::vector<std::uint8_t> occluded, door_occluded;
  std::size_t pairs_done = 0, rays_done = 0, moving_rays = 0, door_rays_done = 0;  // the task's counts
  std::int64_t trace_ns = 0;                                                       // its time in the caster
};

// Whether a sample of a static pair is traced again after a move (without door_only_rays):
// when its segment meets a swept box; else its stored bit stands (nothing that moved is on it).
bool ExactLeafTransport::meets_swept(const Ray& r) const {
  return std::any_of(moving_.swept().begin(), moving_.swept().end(), [&](const MovingInstances::Box& b) {
    return engine::segment_meets_box(r.origin, r.direction, 1.0f, b.lo, b.hi);
  });
}

// door_only_rays: the sample's visibility is its static visibility (the bit, traced in the
// static scene when its ends moved or on the first update) and, when a deforming instance's
// box now meets its segment, not occluded by the instances (their scene alone).
void ExactLeafTransport::queue_split_sample(const Ray& r, bool traced, bool static_visible, std::int32_t& ray,
                                            std::int32_t& door_ray, PairBatch& batch) const {
  if (traced) {
    ray = static_cast<std::int32_t>(batch.rays.size());
    batch.rays.push_back(r);
  } else if (!static_visible) {
    return;  // a static occluder: occluded whatever the door does
  }
  for (const MovingInstances::Box& b : door_now_)
    if (engine::segment_meets_box(r.origin, r.direction, 1.0f, b.lo, b.hi)) {
      door_ray = static_cast<std::int32_t>(batch.door_rays.size());
      batch.door_rays.push_back(r);
      return;
    }
}

int ExactLeafTransport::point_pairs_of(const ElementNode& ei, const ElementNode& ej) const {
  int m = settings_.point_pairs;
  const bool close = close_pair(ei, ej);
  // Close pairs (touching leaves: the 1/r^2 peak) at least kMinClosePairs: with fewer, one
  // unlucky pair near the clamp can push the operator's norm above 1 and the solve diverges.
  if (close) m = std::max(m, kMinClosePairs);
  if (settings_.reference_area_m2 > 0.0f && !close) {
    const double share =
        static_cast<double>(ei.area_m2) * static_cast<double>(ej.area_m2) /
        (static_cast<double>(settings_.reference_area_m2) * static_cast<double>(settings_.reference_area_m2));
    m = std::clamp(static_cast<int>(std::ceil(static_cast<double>(m) * share)), 1, m);
  }
  return m;
}

void ExactLeafTransport::queue_pair(const ElementHierarchy& h, std::size_t i, std::size_t j, bool reuse,
                                    PairBatch& batch) const {
  const auto ni = static_cast<std::size_t>(h.leaves[i]), nj = static_cast<std::size_t>(h.leaves[j]);
  const glm::vec3* ti = &h.corners[3 * ni];
  const glm::vec3* tj = &h.corners[3 * nj];
  const glm::vec3 n_i = h.nodes[ni].normal, n_j = h.nodes[nj].normal;
  PairBatch::Pair pair{i, j, static_cast<std::uint32_t>(batch.samples.size()), 0, 1, false};
  if (behind(tj, ti[0], n_i) || behind(ti, tj[0], n_j)) {
    pair.zero = true;
    batch.pairs.push_back(pair);
    return;
  }
  const int m = point_pairs_of(h.nodes[ni], h.nodes[nj]);
  pair.m = m;
  // Touching leaves: each sample's geometry is the exact form factor from its point on i to
  // the whole of j (Lambert's formula), pi / A_j of it in G's units; the point on j only
  // tests visibility. The point-to-point kernel's 1/r^2 peak at a shared edge made single
  // samples worth several times a whole row's light: 42% of the corridor's rows summed to a
  // form factor above 1 (up to 2.9), and with every leaf a receiver the solve diverged.
  const bool close = close_pair(h.nodes[ni], h.nodes[nj]);
  const float area_j = 0.5f * glm::length(glm::cross(tj[1] - tj[0], tj[2] - tj[0]));
  const float to_g = area_j > 0.0f ? kPi / area_j : 0.0f;
  const int strata = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(m))));
  const float min_r2 = settings_.min_distance_m * settings_.min_distance_m;
  std::uint64_t state = mix(settings_.seed ^ mix(static_cast<std::uint64_t>(i) * 0x100000001b3ULL + j));
  reuse = reuse && !visible_.empty();
  for (int s = 0; s < m; ++s) {
    const int cell = s % (strata * strata);
    const float u = (static_cast<float>(cell % strata) + unit(state)) / static_cast<float>(strata);
    const float v = (static_cast<float>(cell / strata) + unit(state)) / static_cast<float>(strata);
    const glm::vec3 x = on_triangle(ti, u, v);
    const float a = unit(state), b = unit(state);
    const glm::vec3 y = on_triangle(tj, a, b);
    const glm::vec3 d = y - x;
    const float r2 = glm::dot(d, d);
    if (r2 <= 0.0f) continue;
    const float r = std::sqrt(r2);
    const float ci = glm::dot(n_i, d) / r, cj = -glm::dot(n_j, d) / r;
    if (ci <= 0.0f || cj <= 0.0f) continue;
    // Off both surfaces by 0.1 mm along their normals, the segment between.
    const glm::vec3 o = x + 1e-4f * n_i;
    const glm::vec3 e = y + 1e-4f * n_j;
    const float g = close ? to_g * (glm::dot(x - tj[0], n_j) < 0.0f ? 0.0f : polygon_form_factor(x, n_i, {tj, 3}))
                          : ci * cj / std::max(r2, min_r2);
    PairBatch::Sample sample{g, -1, -1, static_cast<std::uint32_t>(s)};
    const Ray ray{.origin = o, .t_min = 0.0f, .direction = e - o, .t_max = 1.0f};
    if (door_caster_) {
      const bool kept = reuse && visible_bit(pair_slot(i, j), static_cast<std::uint32_t>(s));
      queue_split_sample(ray, !reuse, kept, sample.ray, sample.door_ray, batch);
    } else if (!reuse || meets_swept(ray)) {
      sample.ray = static_cast<std::int32_t>(batch.rays.size());
      batch.rays.push_back(ray);
    }
    batch.samples.push_back(sample);
  }
  pair.count = static_cast<std::uint32_t>(batch.samples.size()) - pair.first;
  batch.pairs.push_back(pair);
}

void ExactLeafTransport::flush(PairBatch& batch) {
  batch.occluded.resize(batch.rays.size());
  const auto t0 = std::chrono::steady_clock::now();
  if (settings_.streams) {
    caster_->occluded_many(batch.rays, batch.occluded);
  } else {
    for (std::size_t r = 0; r < batch.rays.size(); ++r) batch.occluded[r] = caster_->occluded(batch.rays[r]) ? 1 : 0;
  }
  batch.door_occluded.resize(batch.door_rays.size());
  if (!batch.door_rays.empty()) door_caster_->occluded_many(batch.door_rays, batch.door_occluded);
  batch.trace_ns += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
  batch.rays_done += batch.rays.size();
  batch.door_rays_done += batch.door_rays.size();
  for (const PairBatch::Pair& p : batch.pairs) {
    const std::size_t slot = pair_slot(p.i, p.j);
    const bool keep = !visible_.empty();
    double sum = 0.0;  // in sample order, as one sample at a time summed
    for (std::uint32_t k = p.first; k < p.first + p.count; ++k) {
      const PairBatch::Sample& s = batch.samples[k];
      bool visible = false;
      if (s.ray >= 0) {
        visible = batch.occluded[static_cast<std::size_t>(s.ray)] == 0;
        if (keep) set_visible_bit(slot, s.bit, visible);
      } else {
        visible = visible_bit(slot, s.bit);  // reuse: the segment meets nothing that moved
      }
      if (visible && s.door_ray >= 0) visible = batch.door_occluded[static_cast<std::size_t>(s.door_ray)] == 0;
      if (visible) sum += static_cast<double>(s.weight);
    }
    store(p.i, p.j, p.zero ? 0.0f : static_cast<float>(sum / static_cast<double>(p.m)));
  }
  batch.pairs.clear();
  batch.samples.clear();
  batch.rays.clear();
  batch.door_rays.clear();
}

void ExactLeafTransport::reset(std::size_t n) {
  n_ = n;
  sized_ = true;
  recv_.clear();
  slot_.assign(receivers_.empty() ? 0 : n, -1);
  for (std::size_t l = 0; l < slot_.size(); ++l)
    if (receivers_[l]) {
      slot_[l] = static_cast<std::int32_t>(recv_.size());
      recv_.push_back(static_cast<std::uint32_t>(l));
    }
  rows_.assign(recv_.size() * n, 0.0f);
  // With receivers their rows are the only table: the pairs of two other leaves are never
  // computed, so n(n-1)/2 slots would hold mostly zeros.
  const std::size_t slots = slot_.empty() ? n * (n - 1) / 2 : recv_.size() * n;
  g_.assign(slot_.empty() ? slots : 0, 0.0f);
  visible_words_ = static_cast<std::size_t>(std::max(settings_.point_pairs, kMinClosePairs) + 15) / 16;
  visible_.assign(settings_.reuse_visibility ? slots * visible_words_ : 0, 0);
}

void ExactLeafTransport::update(const ElementHierarchy& h) {
  GI_EXPECTS(h.corners.size() == 3 * h.nodes.size(), "ExactLeafTransport: the hierarchy needs its triangles");
  if (dirty_) {
    caster_->commit();
    if (door_caster_) door_caster_->commit();
    dirty_ = false;
  }
  const std::size_t n = h.leaf_count();
  const bool all = n != n_ || !sized_;
  if (all) reset(n);
  std::vector<char> moving(n, 0);
  std::vector<MovingInstances::Box> bounds(n);  // each leaf's triangle's box
  for (std::size_t l = 0; l < n; ++l) {
    const auto node = static_cast<std::size_t>(h.leaves[l]);
    moving[l] = moving_.deforming(h.node_instance[node]);
    const glm::vec3* t = &h.corners[3 * node];
    bounds[l] = {glm::min(glm::min(t[0], t[1]), t[2]), glm::max(glm::max(t[0], t[1]), t[2])};
  }
  std::atomic<std::size_t> pairs{0}, rays{0}, moving_rays{0}, door_rays{0};
  std::atomic<std::int64_t> trace_ns{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    PairBatch batch;
    for (std::size_t i = r.begin(); i != r.end(); ++i) update_row(h, i, all, moving, bounds, batch);
    pairs += batch.pairs_done;
    rays += batch.rays_done;
    moving_rays += batch.moving_rays;
    door_rays += batch.door_rays_done;
    trace_ns += batch.trace_ns;
  });
  moving_.clear_swept();
  last_door_only_rays_ = door_rays;
  last_pairs_ = pairs;
  last_rays_ = rays;
  last_moving_rays_ = moving_rays;
  last_trace_cpu_ms_ = static_cast<double>(trace_ns.load()) * 1e-6;
}

// Every segment between two triangles lies in their convex hull, so within the box of both
// triangles' boxes and within the centres' segment widened by the larger radius: a moved box
// that misses either cannot change the pair.
bool ExactLeafTransport::pair_may_change(const ElementHierarchy& h, std::size_t i, std::size_t j,
                                         std::span<const MovingInstances::Box> bounds) const {
  const ElementNode& a = h.nodes[static_cast<std::size_t>(h.leaves[i])];
  const ElementNode& b = h.nodes[static_cast<std::size_t>(h.leaves[j])];
  const glm::vec3 widen(std::max(a.radius_m, b.radius_m));
  const glm::vec3 lo = glm::min(bounds[i].lo, bounds[j].lo), hi = glm::max(bounds[i].hi, bounds[j].hi);
  for (const MovingInstances::Box& box : moving_.swept())
    if (glm::all(glm::lessThanEqual(box.lo, hi)) && glm::all(glm::lessThanEqual(lo, box.hi)) &&
        engine::segment_meets_box(a.center, b.center - a.center, 1.0f, box.lo - widen, box.hi + widen))
      return true;
  return false;
}

void ExactLeafTransport::update_row(const ElementHierarchy& h, std::size_t i, bool all, std::span<const char> moving,
                                    std::span<const MovingInstances::Box> bounds, PairBatch& batch) {
  for (std::size_t j = i + 1; j < n_; ++j) {
    if (!receivers_.empty() && !receivers_[i] && !receivers_[j]) continue;
    const bool moves = moving[i] || moving[j];
    if (!all && !moves && !pair_may_change(h, i, j, bounds)) continue;
    // A pair with a moving leaf moves its samples: every one is traced again.
    const std::size_t before = batch.rays.size();
    queue_pair(h, i, j, !all && !moves, batch);
    if (moves) batch.moving_rays += batch.rays.size() - before;
    if (batch.rays.size() + batch.door_rays.size() >= kBatchRays) flush(batch);
    ++batch.pairs_done;
  }
  flush(batch);
}

void ExactLeafTransport::store(std::size_t i, std::size_t j, float g) {
  if (slot_.empty()) {
    g_[pair_index(i, j)] = g;
    return;
  }
  if (slot_[i] >= 0) rows_[static_cast<std::size_t>(slot_[i]) * n_ + j] = g;
  if (slot_[j] >= 0) rows_[static_cast<std::size_t>(slot_[j]) * n_ + i] = g;
}

ExactSolveResult ExactLeafTransport::solve(const ElementHierarchy& h, std::span<const glm::vec3> direct) const {
  return iterate(h, direct);
}

ExactSolveResult ExactLeafTransport::solve_receivers(const ElementHierarchy& h, std::span<const glm::vec3> direct,
                                                     std::span<const glm::vec3> others,
                                                     std::span<const glm::vec3> start) const {
  GI_EXPECTS(receivers_.size() == h.leaf_count() && others.size() == h.leaf_count(),
             "ExactLeafTransport::solve_receivers: set_receivers and others for every leaf");
  GI_EXPECTS(start.empty() || start.size() == h.leaf_count(),
             "ExactLeafTransport::solve_receivers: a start for every leaf, or none");
  return iterate_receivers(h, direct, others, start);
}

ExactSolveResult ExactLeafTransport::iterate_receivers(const ElementHierarchy& h, std::span<const glm::vec3> direct,
                                                       std::span<const glm::vec3> others,
                                                       std::span<const glm::vec3> start) const {
  const std::size_t n = h.leaf_count(), r = recv_.size();
  GI_EXPECTS(n == n_ && direct.size() == n && rows_.size() == r * n,
             "ExactLeafTransport::solve_receivers: update() with this hierarchy first");
  const auto area_rho = [&](std::size_t l) {  // A_l albedo_l / pi
    const ElementNode& e = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    return e.area_m2 * e.albedo / kPi;
  };
  ExactSolveResult out;
  out.irradiance.assign(others.begin(), others.end());
  for (std::size_t q = 0; q < r; ++q) out.irradiance[recv_[q]] = start.empty() ? glm::vec3(0.0f) : start[recv_[q]];
  // The held senders' light, the same at every step: summed once.
  std::vector<glm::vec3> source(n);
  for (std::size_t l = 0; l < n; ++l)
    source[l] = slot_[l] >= 0 ? glm::vec3(0.0f) : area_rho(l) * (direct[l] + others[l]);
  std::vector<glm::dvec3> fixed(r);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r, 8), [&](const tbb::blocked_range<std::size_t>& b) {
    for (std::size_t q = b.begin(); q != b.end(); ++q) {
      const float* row = &rows_[q * n];
      glm::dvec3 sum(0.0);
      for (std::size_t j = 0; j < n; ++j) sum += static_cast<double>(row[j]) * glm::dvec3(source[j]);
      fixed[q] = sum;
    }
  });
  std::vector<glm::vec3> src(r), next(r);
  const int budget = settings_.bounces > 0 ? settings_.bounces : settings_.max_iterations;
  for (int it = 0; it < budget; ++it) {
    for (std::size_t q = 0; q < r; ++q) src[q] = area_rho(recv_[q]) * (direct[recv_[q]] + out.irradiance[recv_[q]]);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, r, 16), [&](const tbb::blocked_range<std::size_t>& b) {
      for (std::size_t q = b.begin(); q != b.end(); ++q) {
        const float* row = &rows_[q * n];
        glm::dvec3 sum = fixed[q];
        for (std::size_t k = 0; k < r; ++k) sum += static_cast<double>(row[recv_[k]]) * glm::dvec3(src[k]);
        next[q] = glm::vec3(sum);
      }
    });
    const StepChange c = step_change(
        r, [&](std::size_t q) { return out.irradiance[recv_[q]]; }, [&](std::size_t q) { return next[q]; });
    for (std::size_t q = 0; q < r; ++q) out.irradiance[recv_[q]] = next[q];
    if (end_of_step(out, it, c, settings_)) break;
  }
  if (settings_.bounces > 0) out.converged = std::isfinite(out.residual);
  return out;
}

ExactSolveResult ExactLeafTransport::iterate(const ElementHierarchy& h, std::span<const glm::vec3> direct) const {
  GI_EXPECTS(slot_.empty(), "ExactLeafTransport::solve: with receivers only their pairs exist (solve_receivers)");
  const std::size_t n = h.leaf_count();
  GI_EXPECTS(n == n_ && direct.size() == n, "ExactLeafTransport::solve: update() with this hierarchy first");
  std::vector<glm::vec3> area_rho(n);  // A_j albedo_j / pi
  for (std::size_t l = 0; l < n; ++l) {
    const ElementNode& e = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    area_rho[l] = e.area_m2 * e.albedo / kPi;
  }
  ExactSolveResult out;
  out.irradiance.assign(n, glm::vec3(0.0f));
  std::vector<glm::vec3> next = out.irradiance, source(n);
  const int budget = settings_.bounces > 0 ? settings_.bounces : settings_.max_iterations;
  for (int it = 0; it < budget; ++it) {
    for (std::size_t l = 0; l < n; ++l) source[l] = area_rho[l] * (direct[l] + out.irradiance[l]);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        glm::dvec3 sum(0.0);
        for (std::size_t j = 0; j < i; ++j) sum += static_cast<double>(g_[pair_index(j, i)]) * glm::dvec3(source[j]);
        const std::size_t row = i < n - 1 ? pair_index(i, i + 1) : 0;
        for (std::size_t j = i + 1; j < n; ++j)
          sum += static_cast<double>(g_[row + (j - i - 1)]) * glm::dvec3(source[j]);
        next[i] = glm::vec3(sum);
      }
    });
    const StepChange c = step_change(
        n, [&](std::size_t l) { return out.irradiance[l]; }, [&](std::size_t l) { return next[l]; });
    out.irradiance = next;
    if (end_of_step(out, it, c, settings_)) break;
  }
  if (settings_.bounces > 0) out.converged = std::isfinite(out.residual);
  return out;
}

}  // namespace gi
