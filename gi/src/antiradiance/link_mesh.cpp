#include "antiradiance/link_mesh.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include <glm/gtc/constants.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace gi {

namespace {

// 16 points on the unit disc: the centre, rings of 5 at r = 0.5 and 10 at r = 0.85 (equal
// area strata, fixed so links are deterministic).
constexpr int kSamples = 16;
struct DiscPoint {
  float x, y;
};
constexpr DiscPoint kDisc[kSamples] = {
    {0.0f, 0.0f},         {0.5f, 0.0f},        {0.1545f, 0.4755f},  {-0.4045f, 0.2939f},
    {-0.4045f, -0.2939f}, {0.1545f, -0.4755f}, {0.8084f, 0.2627f},  {0.5f, 0.6877f},
    {0.0f, 0.85f},        {-0.5f, 0.6877f},    {-0.8084f, 0.2627f}, {-0.8084f, -0.2627f},
    {-0.5f, -0.6877f},    {0.0f, -0.85f},      {0.5f, -0.6877f},    {0.8084f, -0.2627f}};

// Point k of n equal-area points on the unit disc (a Fermat spiral: point k stands for the
// ring between radii sqrt(k/n) and sqrt((k+1)/n), turned by the golden angle; deterministic).
DiscPoint spiral_point(int k, int n) {
  if (n == 1) return {0.0f, 0.0f};  // one piece: the centre
  const float r = std::sqrt((static_cast<float>(k) + 0.5f) / static_cast<float>(n));
  const float a = 2.39996323f * static_cast<float>(k);
  return {r * std::cos(a), r * std::sin(a)};
}

// Two unit tangents of the plane with normal n.
void tangents(const glm::vec3& n, glm::vec3& t, glm::vec3& bt) {
  t = glm::normalize(std::abs(n.x) < 0.9f ? glm::cross(n, glm::vec3(1, 0, 0)) : glm::cross(n, glm::vec3(0, 1, 0)));
  bt = glm::cross(n, t);
}

// The near set of precise links (settings.near_link_samples): the deforming groups' elements
// and the static elements within near_radius_m of a deforming group's swept sphere (its
// pivot through its farthest leaf's sphere: any rotation about the pivot stays inside; the
// sphere element_hierarchy.cpp's adaptive leaves use, from the leaves instead of the vertices).
struct NearSet {
  int samples = 0;  // q; 0: no precise links
  int max_pieces = 1;
  float radius_m = 0.0f;
  std::vector<glm::vec4> swept;  // centre, radius

  NearSet() = default;
  NearSet(const ElementHierarchy& h, const AntiradianceSettings& s)
      : samples(std::max(s.near_link_samples, 0)),
        max_pieces(std::clamp(s.near_link_max_pieces, 1, kMaxLeafLinkPieces)),
        radius_m(s.near_radius_m) {
    if (samples == 0) return;
    for (int g = 1; g < h.group_count(); ++g) {
      const std::int32_t root = h.group_root[static_cast<std::size_t>(g)];
      if (root < 0) continue;
      const glm::mat4& m = h.group_transform[static_cast<std::size_t>(g - 1)];
      const float scale =
          std::max({glm::length(glm::vec3(m[0])), glm::length(glm::vec3(m[1])), glm::length(glm::vec3(m[2]))});
      float reach = 0.0f;
      for (std::int32_t i = root; i < h.nodes[static_cast<std::size_t>(root)].end; ++i) {
        const auto k = static_cast<std::size_t>(i);
        if (h.nodes[k].child_count == 0)  // the leaves bound the vertices; a cluster's sphere is looser
          reach = std::max(reach, glm::length(h.object_center[k]) + h.object_radius[k]);
      }
      swept.emplace_back(glm::vec3(m[3]), reach * scale);
    }
  }

  bool contains(const ElementNode& n) const {
    if (samples == 0) return false;
    if (n.group >= 1) return true;
    for (const glm::vec4& sp : swept)
      if (glm::length(n.center - glm::vec3(sp)) - n.radius_m - sp.w <= radius_m) return true;
    return false;
  }
};

// The links of one pair of elements (both ways), written to `out`: what refinement decided
// to link. Scratch per maker, so one maker per thread.
struct LinkMaker {
  const ElementHierarchy& h;
  const DirectionalBins& bins;
  float threshold_sr;
  std::vector<Link>& out;
  /// Distributed bakes: only links to receivers of this shard (whole: every link).
  WorkShard shard{};
  /// Leaf-leaf links that fail the oracle: pieces per end at most (0: linked regardless).
  int max_pieces = 0;
  /// Per bin: the split link's form factor so far, and the bins touched (scratch).
  std::vector<float> bin_sum{};
  std::vector<std::int32_t> touched{};
  /// The pieces' points of a split link's two ends (scratch).
  std::vector<glm::vec3> sender_points{}, receiver_points{};
  /// Precise near links (settings.near_link_samples > 0).
  const NearSet* near = nullptr;
  /// Counters: precise links made (directed), their piece pairs.
  std::size_t precise_links = 0, precise_pairs = 0;

  const ElementNode& node(std::int32_t i) const { return h.nodes[static_cast<std::size_t>(i)]; }

  static float regularizer(const ElementNode& n) {
    return std::min(n.area_m2 / glm::pi<float>(), n.radius_m * n.radius_m);
  }

  // Coplanar neighbours (one surface cut into leaves): every piece pair lies in the
  // receiver's plane, so they exchange nothing.
  static bool coplanar(const ElementNode& r, const ElementNode& s) {
    if (r.normal == glm::vec3(0.0f) || s.normal == glm::vec3(0.0f)) return false;
    return std::abs(glm::dot(r.normal, s.center - r.center)) <= 1e-5f * (r.radius_m + s.radius_m) &&
           glm::dot(r.normal, s.normal) >= 0.9999f;
  }

  // Receiver r, sender s wholly behind r's plane: nothing to receive.
  static bool behind(const ElementNode& r, const ElementNode& s) {
    if (r.normal == glm::vec3(0.0f)) return false;
    return glm::dot(r.normal, s.center - r.center) < -s.radius_m;
  }

  // Directed link r <- s, spread over the bins the sender covers as seen from the receiver
  // (§3.1: "the precise computation of exchanges between all pairs of bins in the cone
  // subtended by the sender"): kSamples fixed points on a disc standing for the sender (in
  // its plane with its area for a surface element; facing the receiver with its bounding
  // radius for a cluster), each direction point -> receiver centre picks a bin; a bin gets
  // the share of samples that fell in it. One record per (receiver, sender, bin).
  void directed(std::int32_t r, std::int32_t s, bool fine) {
    if (!shard.owns(static_cast<std::size_t>(r))) return;
    const ElementNode& rn = node(r);
    const ElementNode& sn = node(s);
    if (behind(rn, sn)) return;
    if (near != nullptr && (near->contains(rn) || near->contains(sn))) {
      if (!coplanar(rn, sn)) precise_directed(r, s);
      return;
    }
    if (!fine && max_pieces > 0) {
      // Coplanar neighbours (one surface cut into leaves) exchange nothing: every piece pair
      // lies in the receiver's plane. Skipped before the pieces, most of the touching pairs.
      if (coplanar(rn, sn)) return;
      const LinkPieces p = link_pieces(rn, sn, threshold_sr, max_pieces);
      if (p.sender > 1 || p.receiver > 1) {
        split_directed(r, s, p);
        return;
      }
    }
    const glm::vec3 d = rn.center - sn.center;
    const float d2 = glm::dot(d, d);
    const glm::vec3 axis =
        d2 > 0.0f ? d / std::sqrt(d2) : (rn.normal != glm::vec3(0.0f) ? -rn.normal : glm::vec3(0, 0, 1));
    const bool surface = sn.normal != glm::vec3(0.0f);
    const glm::vec3 disc_normal = surface ? sn.normal : axis;
    const float disc_radius = surface ? std::sqrt(sn.area_m2 / glm::pi<float>()) : sn.radius_m;
    const glm::vec3 t = glm::normalize(std::abs(disc_normal.x) < 0.9f ? glm::cross(disc_normal, glm::vec3(1, 0, 0))
                                                                      : glm::cross(disc_normal, glm::vec3(0, 1, 0)));
    const glm::vec3 bt = glm::cross(disc_normal, t);
    const float sep = std::sqrt(d2);
    const bool overlap = sep < rn.radius_m + sn.radius_m;
    const float reg = d2 + (overlap ? regularizer(rn) + regularizer(sn) : 0.0f);
    int bins_hit[kSamples];
    for (int k = 0; k < kSamples; ++k) {
      const glm::vec3 p = sn.center + disc_radius * (kDisc[k].x * t + kDisc[k].y * bt);
      const glm::vec3 dir = rn.center - p;
      bins_hit[k] = glm::dot(dir, dir) > 0.0f ? bins.bin_of(glm::normalize(dir)) : bins.bin_of(axis);
    }
    std::sort(bins_hit, bins_hit + kSamples);
    for (int k = 0; k < kSamples;) {
      int e = k;
      while (e < kSamples && bins_hit[e] == bins_hit[k]) ++e;
      const float share = static_cast<float>(e - k) / static_cast<float>(kSamples);
      out.push_back({r, s, bins_hit[k], share / (reg * bins.solid_angle(bins_hit[k]))});
      k = e;
    }
  }

  // The n equal-area pieces' points of leaf `e` as a disc of its area in its plane.
  static void piece_points(const ElementNode& e, int n, std::vector<glm::vec3>& points) {
    glm::vec3 t, bt;
    tangents(e.normal, t, bt);
    const float radius = std::sqrt(e.area_m2 / glm::pi<float>());
    points.resize(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      const DiscPoint a = spiral_point(k, n);
      points[static_cast<std::size_t>(k)] = e.center + radius * (a.x * t + a.y * bt);
    }
  }

  // Directed leaf link r <- s split virtually (§3.1's refinement for a pair of leaves): both
  // leaves as discs of their area in their planes, cut into p.sender / p.receiver equal-area
  // pieces (spiral_point); each piece pair adds, in the bin of its own direction, its share
  // of the sender's intensity (1 / p.sender, the leaf's I_ex spread evenly over its area)
  // averaged over the receiver's pieces, at its own distance: F_b = sum 1 / (ps pr d^2 omega_b),
  // d^2 regularized by both pieces' disc terms (bounded for touching leaves). Sender pieces
  // behind a receiver piece's plane add nothing (the positive hemisphere, as `behind`).
  void split_directed(std::int32_t r, std::int32_t s, const LinkPieces& p) {
    const ElementNode& rn = node(r);
    const ElementNode& sn = node(s);
    bin_sum.assign(static_cast<std::size_t>(bins.count()), 0.0f);
    touched.clear();
    piece_points(sn, p.sender, sender_points);
    piece_points(rn, p.receiver, receiver_points);
    const float reg =
        (sn.area_m2 / static_cast<float>(p.sender) + rn.area_m2 / static_cast<float>(p.receiver)) / glm::pi<float>();
    const float weight = 1.0f / (static_cast<float>(p.sender) * static_cast<float>(p.receiver));
    for (const glm::vec3& ps : sender_points)
      for (const glm::vec3& pr : receiver_points) {
        const glm::vec3 dir = pr - ps;
        const float d2 = glm::dot(dir, dir);
        if (!(d2 > 0.0f) || glm::dot(rn.normal, dir) >= 0.0f) continue;  // behind the receiver piece
        const int bin = bins.bin_of(dir / std::sqrt(d2));
        if (bin_sum[static_cast<std::size_t>(bin)] == 0.0f) touched.push_back(bin);
        bin_sum[static_cast<std::size_t>(bin)] += weight / ((d2 + reg) * bins.solid_angle(bin));
      }
    std::sort(touched.begin(), touched.end());
    for (std::int32_t b : touched) out.push_back({r, s, b, bin_sum[static_cast<std::size_t>(b)]});
  }

  // About n equal-area pieces' points of node `i` seen from `from`: a surface element as its
  // triangle cut into k^2 congruent sub-triangles (k = ceil(sqrt(n)); their centroids), or,
  // without its corners (a hierarchy from a bundle), a disc of its area in its plane; a
  // cluster (no normal) as a disc of its bounding radius facing `from`. Returns the pieces'
  // total area (their count is points.size()).
  float end_points(std::int32_t i, const glm::vec3& from, int n, std::vector<glm::vec3>& points) const {
    const ElementNode& e = node(i);
    if (e.normal != glm::vec3(0.0f) && h.corners.size() == 3 * h.nodes.size()) {
      const glm::vec3* c = &h.corners[3 * static_cast<std::size_t>(i)];
      const int k = std::max(1, static_cast<int>(std::ceil(std::sqrt(static_cast<float>(n)) - 1e-4f)));
      const glm::vec3 u = (c[1] - c[0]) / static_cast<float>(k), v = (c[2] - c[0]) / static_cast<float>(k);
      points.clear();
      for (int a = 0; a < k; ++a)
        for (int b = 0; a + b < k; ++b) {
          const glm::vec3 corner = c[0] + static_cast<float>(a) * u + static_cast<float>(b) * v;
          points.push_back(corner + (u + v) / 3.0f);                            // upright sub-triangle
          if (a + b + 1 < k) points.push_back(corner + 2.0f * (u + v) / 3.0f);  // the inverted one beside it
        }
      return e.area_m2;
    }
    if (e.normal != glm::vec3(0.0f)) {
      piece_points(e, n, points);
      return e.area_m2;
    }
    const glm::vec3 d = from - e.center;
    const float len = glm::length(d);
    const glm::vec3 axis = len > 0.0f ? d / len : glm::vec3(0, 0, 1);
    glm::vec3 t, bt;
    tangents(axis, t, bt);
    points.resize(static_cast<std::size_t>(n));
    for (int k = 0; k < n; ++k) {
      const DiscPoint a = spiral_point(k, n);
      points[static_cast<std::size_t>(k)] = e.center + e.radius_m * (a.x * t + a.y * bt);
    }
    return glm::pi<float>() * e.radius_m * e.radius_m;
  }

  // Precise near link r <- s (§3.1, the paper's CPU scheme): both ends cut into equal-area
  // pieces (end_points), each piece at most 1/q of the oracle's solid angle as seen from the
  // other end's centre (the sender at least q pieces, so even a sender within one bin is
  // sampled across it; at most near->max_pieces per end); every piece pair adds
  // 1 / (n_s n_r (d^2 + a_s/(pi n_s) + a_r/(pi n_r)) omega_b) to the bin b of its own
  // direction: bin b's weight is the sender's share in b of the flux reaching the receiver,
  // over omega_b. Pieces behind a receiver piece's plane add nothing (surface receivers).
  void precise_directed(std::int32_t r, std::int32_t s) {
    const ElementNode& rn = node(r);
    const ElementNode& sn = node(s);
    const float d2 = std::max(glm::dot(rn.center - sn.center, rn.center - sn.center), 1e-12f);
    const float q = static_cast<float>(near->samples);
    const auto pieces = [&](const ElementNode& e, int least) {
      const double need = static_cast<double>(q) * glm::pi<double>() * static_cast<double>(e.radius_m) *
                          static_cast<double>(e.radius_m) /
                          (static_cast<double>(d2) * static_cast<double>(threshold_sr));
      return static_cast<int>(
          std::clamp(std::ceil(need), static_cast<double>(least), static_cast<double>(near->max_pieces)));
    };
    bin_sum.assign(static_cast<std::size_t>(bins.count()), 0.0f);
    touched.clear();
    const float as = end_points(s, rn.center, pieces(sn, std::min(near->samples, near->max_pieces)), sender_points);
    const float ar = end_points(r, sn.center, pieces(rn, 1), receiver_points);
    const int ns = static_cast<int>(sender_points.size()), nr = static_cast<int>(receiver_points.size());
    const float reg = (as / static_cast<float>(ns) + ar / static_cast<float>(nr)) / glm::pi<float>();
    const float weight = 1.0f / (static_cast<float>(ns) * static_cast<float>(nr));
    const bool surface = rn.normal != glm::vec3(0.0f);
    for (const glm::vec3& ps : sender_points)
      for (const glm::vec3& pr : receiver_points) {
        const glm::vec3 dir = pr - ps;
        const float dd = glm::dot(dir, dir);
        if (!(dd > 0.0f) || (surface && glm::dot(rn.normal, dir) >= 0.0f)) continue;
        const int bin = bins.bin_of(dir / std::sqrt(dd));
        if (bin_sum[static_cast<std::size_t>(bin)] == 0.0f) touched.push_back(bin);
        bin_sum[static_cast<std::size_t>(bin)] += weight / ((dd + reg) * bins.solid_angle(bin));
      }
    std::sort(touched.begin(), touched.end());
    for (std::int32_t b : touched) out.push_back({r, s, b, bin_sum[static_cast<std::size_t>(b)]});
    ++precise_links;
    precise_pairs += static_cast<std::size_t>(ns) * static_cast<std::size_t>(nr);
  }

  void link(std::int32_t a, std::int32_t b, bool fine) {
    directed(a, b, fine);
    directed(b, a, fine);
  }
};

// A pair refinement decided to link (both ways); fine: it meets the oracle.
struct LinkPair {
  std::int32_t a = 0, b = 0;
  bool fine = false;
};

// The refinement (§3.2): which pairs of elements are linked, from the root's self-link or
// from pairs of groups; collects them, LinkMaker makes their links (make_links).
struct Refinement {
  const ElementHierarchy& h;
  float threshold_sr;
  std::vector<LinkPair>& pairs;
  /// Distributed bakes: pairs whose subtrees hold no receiver of the shard are not visited.
  WorkShard shard{};

  const ElementNode& node(std::int32_t i) const { return h.nodes[static_cast<std::size_t>(i)]; }

  // Does the subtree of node a hold a receiver of the shard? (Subtrees are index ranges.)
  bool subtree_owned(std::int32_t a) const {
    if (shard.whole()) return true;
    const std::size_t lo = static_cast<std::size_t>(a), hi = static_cast<std::size_t>(node(a).end);
    const std::size_t block = WorkShard::kBlockItems;
    if (hi - lo >= block * shard.count) return true;
    for (std::size_t b = lo / block; b * block < hi; ++b)
      if (b % shard.count == shard.index) return true;
    return false;
  }

  void refine(std::int32_t a, std::int32_t b) {
    if (!subtree_owned(a) && !subtree_owned(b)) return;  // no link of the shard below
    const ElementNode& an = node(a);
    const ElementNode& bn = node(b);
    if (LinkMaker::behind(an, bn) && LinkMaker::behind(bn, an)) return;  // back to back: no exchange either way
    const float d2 = glm::dot(an.center - bn.center, an.center - bn.center);
    const float d = std::sqrt(d2);
    const bool a_leaf = an.child_count == 0, b_leaf = bn.child_count == 0;
    const float sa = glm::pi<float>() * an.radius_m * an.radius_m / std::max(d2, 1e-30f);
    const float sb = glm::pi<float>() * bn.radius_m * bn.radius_m / std::max(d2, 1e-30f);
    const bool fine = d > an.radius_m + bn.radius_m && std::max(sa, sb) <= threshold_sr;
    if (fine || (a_leaf && b_leaf)) {
      pairs.push_back({a, b, fine});
      return;
    }
    const bool split_a = b_leaf || (!a_leaf && an.radius_m >= bn.radius_m);
    const std::int32_t split = split_a ? a : b, other = split_a ? b : a;
    const ElementNode& sn = node(split);
    for (std::int32_t c = 0; c < sn.child_count; ++c)
      refine(h.children[static_cast<std::size_t>(sn.first_child + c)], other);
  }

  // Self-links are always subdivided: all pairs of children, each child with itself.
  void self(std::int32_t a) {
    if (!subtree_owned(a)) return;
    const ElementNode& an = node(a);
    for (std::int32_t i = 0; i < an.child_count; ++i) {
      const std::int32_t ci = h.children[static_cast<std::size_t>(an.first_child + i)];
      self(ci);
      for (std::int32_t j = i + 1; j < an.child_count; ++j)
        refine(ci, h.children[static_cast<std::size_t>(an.first_child + j)]);
    }
  }
};

// Appends the links of `pairs` to `out` (in pair order), the pairs' links made on TBB's
// threads in chunks, each chunk into its own list: the same links as one thread makes.
// Counts the precise links made (directed) into mesh's counters.
void make_links(const ElementHierarchy& h, const DirectionalBins& bins, float threshold_sr, const WorkShard& shard,
                const AntiradianceSettings& settings, const std::vector<LinkPair>& pairs, LinkMesh& mesh) {
  constexpr std::size_t kChunk = 256;
  const std::size_t chunks = (pairs.size() + kChunk - 1) / kChunk;
  std::vector<std::vector<Link>> parts(chunks);
  std::vector<std::pair<std::size_t, std::size_t>> precise(chunks);
  const NearSet near(h, settings);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t c = r.begin(); c != r.end(); ++c) {
      LinkMaker maker{h, bins, threshold_sr, parts[c], shard, settings.leaf_link_pieces};
      if (near.samples > 0) maker.near = &near;
      for (std::size_t i = c * kChunk; i < std::min(pairs.size(), (c + 1) * kChunk); ++i)
        maker.link(pairs[i].a, pairs[i].b, pairs[i].fine);
      precise[c] = {maker.precise_links, maker.precise_pairs};
    }
  });
  std::vector<Link>& out = mesh.links;
  std::size_t total = out.size();
  for (const std::vector<Link>& part : parts) total += part.size();
  out.reserve(total);
  for (const std::vector<Link>& part : parts) out.insert(out.end(), part.begin(), part.end());
  mesh.precise_links = 0;
  mesh.precise_piece_pairs = 0;
  for (const auto& [links, piece_pairs] : precise) {
    mesh.precise_links += links;
    mesh.precise_piece_pairs += piece_pairs;
  }
}

// (receiver, bin, sender): a total order, since refinement links a pair once and a pair's
// links differ in their bins.
bool link_less(const Link& x, const Link& y) {
  if (x.receiver != y.receiver) return x.receiver < y.receiver;
  return x.bin != y.bin ? x.bin < y.bin : x.sender < y.sender;
}

void index_links(const ElementHierarchy& h, LinkMesh& mesh) {
  mesh.offsets.assign(h.nodes.size() + 1, 0u);
  for (const Link& l : mesh.links) ++mesh.offsets[static_cast<std::size_t>(l.receiver) + 1];
  for (std::size_t i = 1; i < mesh.offsets.size(); ++i) mesh.offsets[i] += mesh.offsets[i - 1];
}

void sort_and_index(const ElementHierarchy& h, LinkMesh& mesh) {
  std::sort(mesh.links.begin(), mesh.links.end(), link_less);
  index_links(h, mesh);
}

}  // namespace

float oracle_threshold_sr(const DirectionalBins& bins, const AntiradianceSettings& s) {
  return std::max(s.oracle_scale, 1e-6f) * 4.0f * glm::pi<float>() / static_cast<float>(bins.count());
}

bool meets_oracle(const ElementNode& a, const ElementNode& b, float threshold_sr) {
  const float d2 = glm::dot(a.center - b.center, a.center - b.center);
  const float d = std::sqrt(d2);
  const float r = std::max(a.radius_m, b.radius_m);
  return d > a.radius_m + b.radius_m && glm::pi<float>() * r * r / std::max(d2, 1e-30f) <= threshold_sr;
}

LinkPieces link_pieces(const ElementNode& receiver, const ElementNode& sender, float threshold_sr, int max_pieces) {
  // A piece of n has radius radius_m / sqrt(n): its solid angle at the centres' distance is
  // pi radius_m^2 / (n d^2); the oracle asks for at most threshold_sr, so n >= that / threshold.
  const float d2 = glm::dot(receiver.center - sender.center, receiver.center - sender.center);
  const auto pieces = [&](const ElementNode& e) {
    const double need = glm::pi<double>() * static_cast<double>(e.radius_m) * static_cast<double>(e.radius_m) /
                        (std::max(static_cast<double>(d2), 1e-30) * static_cast<double>(threshold_sr));
    return static_cast<int>(std::clamp(std::ceil(need), 1.0, static_cast<double>(std::max(max_pieces, 1))));
  };
  return {pieces(sender), pieces(receiver)};
}

LinkMesh link_elements(const ElementHierarchy& h, const DirectionalBins& bins, const AntiradianceSettings& settings) {
  LinkMesh mesh;
  const float threshold = oracle_threshold_sr(bins, settings);
  std::vector<LinkPair> pairs;
  Refinement{h, threshold, pairs}.self(0);
  make_links(h, bins, threshold, {}, settings, pairs, mesh);
  sort_and_index(h, mesh);
  mesh.relinked_elements = h.nodes.size();
  mesh.links_made = mesh.links.size();
  return mesh;
}

LinkMesh link_elements_shard(const ElementHierarchy& h, const DirectionalBins& bins,
                             const AntiradianceSettings& settings, const WorkShard& shard) {
  LinkMesh mesh;
  const float threshold = oracle_threshold_sr(bins, settings);
  std::vector<LinkPair> pairs;
  Refinement{h, threshold, pairs, shard}.self(0);
  make_links(h, bins, threshold, shard, settings, pairs, mesh);
  sort_and_index(h, mesh);
  mesh.relinked_elements = shard.items(h.nodes.size()).size();
  mesh.links_made = mesh.links.size();
  return mesh;
}

engine::Result<LinkMesh> merge_link_shards(const ElementHierarchy& h, const std::vector<std::vector<Link>>& parts) {
  const auto count = static_cast<std::uint32_t>(parts.size());
  const std::size_t nodes = h.nodes.size();
  const auto error = [&](std::uint32_t i, const std::string& what) {
    return engine::Error{"", "antiradiance shard " + std::to_string(i) + " of " + std::to_string(count), what};
  };
  std::size_t total = 0;
  for (std::uint32_t i = 0; i < count; ++i) {
    const WorkShard shard{.index = i, .count = count};
    const std::vector<Link>& p = parts[i];
    for (std::size_t k = 0; k < p.size(); ++k) {
      const Link& l = p[k];
      if (l.receiver < 0 || static_cast<std::size_t>(l.receiver) >= nodes || l.sender < 0 ||
          static_cast<std::size_t>(l.sender) >= nodes || !shard.owns(static_cast<std::size_t>(l.receiver)))
        return error(
            i, "link " + std::to_string(k) + " has a receiver that is not the shard's or an element out of range");
      if (k > 0 && !link_less(p[k - 1], l)) return error(i, "its links are not sorted");
    }
    total += p.size();
  }
  // Receiver r's links are the run of r in the part of its shard: copied in receiver order.
  LinkMesh mesh;
  mesh.links.reserve(total);
  std::vector<std::size_t> cursor(count, 0);
  for (std::size_t r = 0; r < nodes; ++r) {
    const std::uint32_t i = count <= 1 ? 0 : static_cast<std::uint32_t>((r / WorkShard::kBlockItems) % count);
    const std::vector<Link>& p = parts[i];
    std::size_t& k = cursor[i];
    while (k < p.size() && static_cast<std::size_t>(p[k].receiver) == r) mesh.links.push_back(p[k++]);
  }
  index_links(h, mesh);
  mesh.relinked_elements = nodes;
  mesh.links_made = mesh.links.size();
  return mesh;
}

LinkMesh static_links(const ElementHierarchy& h, const LinkMesh& mesh) {
  LinkMesh out;
  for (const Link& l : mesh.links)
    if (h.nodes[static_cast<std::size_t>(l.receiver)].group == 0 &&
        h.nodes[static_cast<std::size_t>(l.sender)].group == 0)
      out.links.push_back(l);
  // A LinkMesh's links are sorted (a total order), so the filtered ones are too: the sort
  // (most of this function's time on 3 M links) only runs for a mesh that is not.
  if (std::is_sorted(out.links.begin(), out.links.end(), link_less))
    index_links(h, out);
  else
    sort_and_index(h, out);
  out.links_made = out.links.size();
  return out;
}

void relink_moved(const ElementHierarchy& h, const DirectionalBins& bins, const AntiradianceSettings& settings,
                  const std::vector<int>& moved, LinkMesh& mesh) {
  std::vector<char> is_moved(static_cast<std::size_t>(h.group_count()), 0);
  for (int g : moved)
    if (g >= 1 && g < h.group_count() && h.group_root[static_cast<std::size_t>(g)] >= 0)
      is_moved[static_cast<std::size_t>(g)] = 1;
  mesh.relinked_elements = 0;
  mesh.links_made = 0;
  auto group_moved = [&](std::int32_t node) {
    const std::int32_t g = h.nodes[static_cast<std::size_t>(node)].group;
    return g >= 1 && is_moved[static_cast<std::size_t>(g)] != 0;
  };
  // Drop every link with an end in a moved group (a rigid motion keeps a group's own form
  // factors but turns their directions, hence their bins); links between unmoved groups stay.
  std::erase_if(mesh.links, [&](const Link& l) { return group_moved(l.receiver) || group_moved(l.sender); });
  const std::size_t kept = mesh.links.size();
  const float threshold = oracle_threshold_sr(bins, settings);
  std::vector<LinkPair> pairs;
  Refinement refinement{h, threshold, pairs};
  for (int a = 0; a < h.group_count(); ++a)
    for (int b = a + 1; b < h.group_count(); ++b) {
      if (!is_moved[static_cast<std::size_t>(a)] && !is_moved[static_cast<std::size_t>(b)]) continue;
      const std::int32_t ra = h.group_root[static_cast<std::size_t>(a)], rb = h.group_root[static_cast<std::size_t>(b)];
      if (ra < 0 || rb < 0) continue;
      refinement.refine(ra, rb);
    }
  for (int g = 1; g < h.group_count(); ++g)
    if (is_moved[static_cast<std::size_t>(g)]) refinement.self(h.group_root[static_cast<std::size_t>(g)]);
  make_links(h, bins, threshold, {}, settings, pairs, mesh);
  for (int g = 1; g < h.group_count(); ++g)
    if (is_moved[static_cast<std::size_t>(g)]) {
      const std::int32_t r = h.group_root[static_cast<std::size_t>(g)];
      mesh.relinked_elements += static_cast<std::size_t>(h.nodes[static_cast<std::size_t>(r)].end - r);
    }
  mesh.links_made = mesh.links.size() - kept;
  // The kept links are still sorted (erase_if keeps their order): sort only the new ones and
  // merge (the same order a full sort gives, the order being total), instead of sorting all.
  std::sort(mesh.links.begin() + static_cast<std::ptrdiff_t>(kept), mesh.links.end(), link_less);
  std::inplace_merge(mesh.links.begin(), mesh.links.begin() + static_cast<std::ptrdiff_t>(kept), mesh.links.end(),
                     link_less);
  index_links(h, mesh);
}

LinkMesh posed_links(const ElementHierarchy& h, const DirectionalBins& bins, const AntiradianceSettings& settings,
                     const std::vector<int>& groups) {
  LinkMesh mesh;
  relink_moved(h, bins, settings, groups, mesh);
  return mesh;
}

void merge_posed_links(const ElementHierarchy& h, const LinkMesh& posed, LinkMesh& mesh) {
  // relink_moved's tail: the kept (static) links, then the new ones sorted, merged.
  const std::size_t kept = mesh.links.size();
  mesh.links.insert(mesh.links.end(), posed.links.begin(), posed.links.end());
  std::inplace_merge(mesh.links.begin(), mesh.links.begin() + static_cast<std::ptrdiff_t>(kept), mesh.links.end(),
                     link_less);
  index_links(h, mesh);
  mesh.relinked_elements = posed.relinked_elements;
  mesh.links_made = posed.links.size();
  mesh.precise_links = posed.precise_links;
  mesh.precise_piece_pairs = posed.precise_piece_pairs;
}

}  // namespace gi
