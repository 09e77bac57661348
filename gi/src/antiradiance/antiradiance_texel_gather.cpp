#include "antiradiance/antiradiance_texel_gather.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include <glm/gtc/constants.hpp>

namespace gi {

namespace {

// 16 points on the unit disc (equal-area strata), as the links spread a sender (link_mesh.cpp).
constexpr int kSamples = 16;
constexpr float kDisc[kSamples][2] = {
    {0.0f, 0.0f},         {0.5f, 0.0f},        {0.1545f, 0.4755f},  {-0.4045f, 0.2939f},
    {-0.4045f, -0.2939f}, {0.1545f, -0.4755f}, {0.8084f, 0.2627f},  {0.5f, 0.6877f},
    {0.0f, 0.85f},        {-0.5f, 0.6877f},    {-0.8084f, 0.2627f}, {-0.8084f, -0.2627f},
    {-0.5f, -0.6877f},    {0.0f, -0.85f},      {0.5f, -0.6877f},    {0.8084f, -0.2627f}};

struct PointGather {
  const ElementHierarchy& h;
  const DirectionalBins& bins;
  std::span<const glm::vec3> exitant;
  float threshold_sr;
  std::size_t m;

  glm::vec3 intensity(std::size_t node, int bin) const { return exitant[node * m + static_cast<std::size_t>(bin)]; }

  // Node read as a whole: I_ex towards the point, cosine at the point, 1 / d^2.
  glm::vec3 whole(const GatherPoint& p, std::size_t node, const glm::vec3& to_node, float d2) const {
    const glm::vec3 w = to_node / std::sqrt(d2);  // point -> node
    const float cos_p = glm::dot(p.normal, w);
    if (cos_p <= 0.0f) return glm::vec3(0.0f);
    return intensity(node, bins.bin_of(-w)) * (cos_p / d2);
  }

  // A leaf too near for the oracle: 16 points on a disc of its area in its plane, each with
  // a sixteenth of the intensity in its own bin, over its own distance (regularized by a
  // sixteenth of the disc's area / pi: the point may lie on the leaf).
  glm::vec3 near_leaf(const GatherPoint& p, std::size_t node) const {
    const ElementNode& n = h.nodes[node];
    const glm::vec3 axis = n.normal != glm::vec3(0.0f) ? n.normal : glm::vec3(0.0f, 0.0f, 1.0f);
    const glm::vec3 t = glm::normalize(std::abs(axis.x) < 0.9f ? glm::cross(axis, glm::vec3(1, 0, 0))
                                                               : glm::cross(axis, glm::vec3(0, 1, 0)));
    const glm::vec3 bt = glm::cross(axis, t);
    const float radius = std::sqrt(n.area_m2 / glm::pi<float>());
    const float reg = n.area_m2 / (glm::pi<float>() * static_cast<float>(kSamples));
    glm::vec3 e(0.0f);
    for (const auto& s : kDisc) {
      const glm::vec3 q = n.center + radius * (s[0] * t + s[1] * bt);
      const glm::vec3 to_q = q - p.position;
      const float d2 = glm::dot(to_q, to_q);
      if (d2 <= 0.0f) continue;
      const glm::vec3 w = to_q / std::sqrt(d2);
      const float cos_p = glm::dot(p.normal, w);
      if (cos_p <= 0.0f) continue;
      e += intensity(node, bins.bin_of(-w)) * (cos_p / (d2 + reg));
    }
    return e / static_cast<float>(kSamples);
  }

  glm::vec3 at(const GatherPoint& p) const {
    glm::vec3 e(0.0f);
    std::vector<std::int32_t> stack{0};
    while (!stack.empty()) {
      const auto node = static_cast<std::size_t>(stack.back());
      stack.pop_back();
      const ElementNode& n = h.nodes[node];
      const glm::vec3 to_node = n.center - p.position;
      if (glm::dot(p.normal, to_node) < -n.radius_m) continue;  // wholly behind the point's plane
      const float d2 = glm::dot(to_node, to_node);
      const bool fine = d2 > n.radius_m * n.radius_m && glm::pi<float>() * n.radius_m * n.radius_m <= threshold_sr * d2;
      if (fine) {
        e += whole(p, node, to_node, d2);
      } else if (n.child_count == 0) {
        e += near_leaf(p, node);
      } else {
        for (std::int32_t c = 0; c < n.child_count; ++c)
          stack.push_back(h.children[static_cast<std::size_t>(n.first_child + c)]);
      }
    }
    return e;
  }
};

}  // namespace

std::vector<glm::vec3> gather_at_points(const ElementHierarchy& h, const DirectionalBins& bins,
                                        const AntiradianceSettings& settings, std::span<const glm::vec3> exitant,
                                        std::span<const GatherPoint> points) {
  const PointGather g{
      h, bins, exitant,
      std::max(settings.oracle_scale, 1e-6f) * 4.0f * glm::pi<float>() / static_cast<float>(bins.count()),
      static_cast<std::size_t>(bins.count())};
  std::vector<glm::vec3> out(points.size(), glm::vec3(0.0f));
  if (h.nodes.empty() || exitant.size() < h.nodes.size() * g.m) return out;
  tbb::parallel_for(std::size_t{0}, points.size(), [&](std::size_t i) { out[i] = g.at(points[i]); });
  return out;
}

}  // namespace gi
