#include "antiradiance/antiradiance_exact_transport.h"

#include <engine/check.h>
#include <engine/segment_box.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "raytrace/embree_ray_caster.h"
#include "raytrace/scene_adapter.h"

namespace gi {
namespace {

constexpr float kPi = 3.14159265358979f;
constexpr int kMinClosePairs = 16;
constexpr int kMaxReusedPairs = 64;  // one std::uint64_t of visibility bits per leaf pair

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

// True when every corner of `t` lies on or behind the plane through `p` with normal `n`.
bool behind(const glm::vec3* t, const glm::vec3& p, const glm::vec3& n) {
  for (int k = 0; k < 3; ++k)
    if (glm::dot(t[k] - p, n) > 1e-6f) return false;
  return true;
}

}  // namespace

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
  auto caster = make_embree_ray_caster(data);
  if (!caster) return caster.error();
  out.caster_ = std::move(caster).value();
  return out;
}

void ExactLeafTransport::set_instance_transform(std::uint32_t instance, const glm::mat4& m) {
  GI_EXPECTS(moving_.deforming(static_cast<std::int32_t>(instance)),
             "ExactLeafTransport: only deforming instances move");
  caster_->set_instance_transform(instance, m);
  moving_.move(instance, m);
  dirty_ = true;
}

std::size_t ExactLeafTransport::pair_index(std::size_t i, std::size_t j) const {
  return i * n_ - i * (i + 1) / 2 + (j - i - 1);
}

float ExactLeafTransport::coupling(std::size_t i, std::size_t j) const {
  if (i == j) return 0.0f;
  return i < j ? g_[pair_index(i, j)] : g_[pair_index(j, i)];
}

float ExactLeafTransport::pair_coupling(const ElementHierarchy& h, std::size_t i, std::size_t j, bool reuse,
                                        std::size_t& rays) {
  const auto ni = static_cast<std::size_t>(h.leaves[i]), nj = static_cast<std::size_t>(h.leaves[j]);
  const glm::vec3* ti = &h.corners[3 * ni];
  const glm::vec3* tj = &h.corners[3 * nj];
  const glm::vec3 n_i = h.nodes[ni].normal, n_j = h.nodes[nj].normal;
  if (behind(tj, ti[0], n_i) || behind(ti, tj[0], n_j)) return 0.0f;
  int m = settings_.point_pairs;
  const ElementNode& ei = h.nodes[ni];
  const ElementNode& ej = h.nodes[nj];
  const float reach = 2.0f * (ei.radius_m + ej.radius_m);
  const bool close = glm::dot(ei.center - ej.center, ei.center - ej.center) < reach * reach;
  // Close pairs (touching leaves: the 1/r^2 peak) at least kMinClosePairs: with fewer, one
  // unlucky pair near the clamp can push the operator's norm above 1 and the solve diverges.
  if (close) m = std::max(m, kMinClosePairs);
  if (settings_.reference_area_m2 > 0.0f && !close) {
    const double share =
        static_cast<double>(ei.area_m2) * static_cast<double>(ej.area_m2) /
        (static_cast<double>(settings_.reference_area_m2) * static_cast<double>(settings_.reference_area_m2));
    m = std::clamp(static_cast<int>(std::ceil(static_cast<double>(m) * share)), 1, m);
  }
  const int strata = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(m))));
  const float min_r2 = settings_.min_distance_m * settings_.min_distance_m;
  std::uint64_t state = mix(settings_.seed ^ mix(static_cast<std::uint64_t>(i) * 0x100000001b3ULL + j));
  std::uint64_t* bits = visible_.empty() ? nullptr : &visible_[pair_index(i, j)];
  reuse = reuse && bits != nullptr;
  double sum = 0.0;
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
    bool crosses = !reuse;
    for (std::size_t k = 0; k < moving_.swept().size() && !crosses; ++k)
      crosses = engine::segment_meets_box(o, e - o, 1.0f, moving_.swept()[k].lo, moving_.swept()[k].hi);
    const std::uint64_t bit = std::uint64_t{1} << s;
    bool visible = false;
    if (crosses) {
      ++rays;
      visible = !caster_->occluded(Ray{.origin = o, .t_min = 0.0f, .direction = e - o, .t_max = 1.0f});
      if (bits) *bits = visible ? (*bits | bit) : (*bits & ~bit);
    } else {
      visible = (*bits & bit) != 0;  // reuse: the segment meets nothing that moved
    }
    if (!visible) continue;
    sum += static_cast<double>(ci * cj / std::max(r2, min_r2));
  }
  return static_cast<float>(sum / static_cast<double>(m));
}

void ExactLeafTransport::update(const ElementHierarchy& h) {
  GI_EXPECTS(h.corners.size() == 3 * h.nodes.size(), "ExactLeafTransport: the hierarchy needs its triangles");
  if (dirty_) {
    caster_->commit();
    dirty_ = false;
  }
  const std::size_t n = h.leaf_count();
  const bool all = n != n_ || g_.empty();
  if (all) {
    n_ = n;
    g_.assign(n * (n - 1) / 2, 0.0f);
    if (settings_.reuse_visibility) visible_.assign(g_.size(), 0);
  }
  std::vector<char> moving(n, 0);
  std::vector<MovingInstances::Box> bounds(n);  // each leaf's triangle's box
  for (std::size_t l = 0; l < n; ++l) {
    const auto node = static_cast<std::size_t>(h.leaves[l]);
    moving[l] = moving_.deforming(h.node_instance[node]);
    const glm::vec3* t = &h.corners[3 * node];
    bounds[l] = {glm::min(glm::min(t[0], t[1]), t[2]), glm::max(glm::max(t[0], t[1]), t[2])};
  }
  std::atomic<std::size_t> pairs{0}, rays{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    std::size_t my_pairs = 0, my_rays = 0;
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const ElementNode& a = h.nodes[static_cast<std::size_t>(h.leaves[i])];
      for (std::size_t j = i + 1; j < n; ++j) {
        if (!receivers_.empty() && !receivers_[i] && !receivers_[j]) continue;
        bool todo = all || moving[i] || moving[j];
        if (!todo) {
          // Every segment between the two triangles lies in their convex hull, so within the
          // box of both triangles' boxes and within the centres' segment widened by the larger
          // radius: a moved box that misses either cannot change the pair.
          const ElementNode& b = h.nodes[static_cast<std::size_t>(h.leaves[j])];
          const glm::vec3 widen(std::max(a.radius_m, b.radius_m));
          const glm::vec3 lo = glm::min(bounds[i].lo, bounds[j].lo), hi = glm::max(bounds[i].hi, bounds[j].hi);
          for (const MovingInstances::Box& box : moving_.swept())
            if (glm::all(glm::lessThanEqual(box.lo, hi)) && glm::all(glm::lessThanEqual(lo, box.hi)) &&
                engine::segment_meets_box(a.center, b.center - a.center, 1.0f, box.lo - widen, box.hi + widen)) {
              todo = true;
              break;
            }
        }
        if (!todo) continue;
        // A pair with a moving leaf moves its samples: every one is traced again.
        g_[pair_index(i, j)] = pair_coupling(h, i, j, !all && !moving[i] && !moving[j], my_rays);
        ++my_pairs;
      }
    }
    pairs += my_pairs;
    rays += my_rays;
  });
  moving_.clear_swept();
  last_pairs_ = pairs;
  last_rays_ = rays;
}

ExactSolveResult ExactLeafTransport::solve(const ElementHierarchy& h, std::span<const glm::vec3> direct) const {
  return iterate(h, direct, {}, {}, {});
}

ExactSolveResult ExactLeafTransport::solve_receivers(const ElementHierarchy& h, std::span<const glm::vec3> direct,
                                                     std::span<const glm::vec3> others,
                                                     std::span<const glm::vec3> start) const {
  GI_EXPECTS(receivers_.size() == h.leaf_count() && others.size() == h.leaf_count(),
             "ExactLeafTransport::solve_receivers: set_receivers and others for every leaf");
  GI_EXPECTS(start.empty() || start.size() == h.leaf_count(),
             "ExactLeafTransport::solve_receivers: a start for every leaf, or none");
  return iterate(h, direct, receivers_, others, start);
}

ExactSolveResult ExactLeafTransport::iterate(const ElementHierarchy& h, std::span<const glm::vec3> direct,
                                             std::span<const char> rows, std::span<const glm::vec3> others,
                                             std::span<const glm::vec3> start) const {
  const std::size_t n = h.leaf_count();
  GI_EXPECTS(n == n_ && direct.size() == n, "ExactLeafTransport::solve: update() with this hierarchy first");
  std::vector<glm::vec3> area_rho(n);  // A_j albedo_j / pi
  for (std::size_t l = 0; l < n; ++l) {
    const ElementNode& e = h.nodes[static_cast<std::size_t>(h.leaves[l])];
    area_rho[l] = e.area_m2 * e.albedo / kPi;
  }
  ExactSolveResult out;
  out.irradiance.assign(n, glm::vec3(0.0f));
  if (!rows.empty())
    for (std::size_t l = 0; l < n; ++l)
      out.irradiance[l] = !rows[l] ? others[l] : start.empty() ? glm::vec3(0.0f) : start[l];
  std::vector<glm::vec3> next = out.irradiance, source(n);
  const int budget = settings_.bounces > 0 ? settings_.bounces : settings_.max_iterations;
  for (int it = 0; it < budget; ++it) {
    for (std::size_t l = 0; l < n; ++l) source[l] = area_rho[l] * (direct[l] + out.irradiance[l]);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 16), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        if (!rows.empty() && !rows[i]) continue;  // held
        glm::dvec3 sum(0.0);
        for (std::size_t j = 0; j < i; ++j) sum += static_cast<double>(g_[pair_index(j, i)]) * glm::dvec3(source[j]);
        const std::size_t row = i < n - 1 ? pair_index(i, i + 1) : 0;
        for (std::size_t j = i + 1; j < n; ++j)
          sum += static_cast<double>(g_[row + (j - i - 1)]) * glm::dvec3(source[j]);
        next[i] = glm::vec3(sum);
      }
    });
    double change = 0.0, total = 0.0;
    for (std::size_t l = 0; l < n; ++l) {
      if (!rows.empty() && !rows[l]) continue;
      const glm::vec3 d = next[l] - out.irradiance[l];
      change += static_cast<double>(std::abs(d.x) + std::abs(d.y) + std::abs(d.z));
      total += static_cast<double>(next[l].x + next[l].y + next[l].z);
    }
    out.irradiance = next;
    out.iterations = it + 1;
    out.residual = total > 0.0 ? change / total : 0.0;
    if (!std::isfinite(total)) break;  // diverged: not converged, and visibly so
    if (settings_.bounces <= 0 && out.residual < settings_.tolerance) {
      out.converged = true;
      break;
    }
  }
  if (settings_.bounces > 0) out.converged = std::isfinite(out.residual);
  return out;
}

}  // namespace gi
