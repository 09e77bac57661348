#pragma once
// Links of an antiradiance solve (Dachsbacher et al. 2007, §3.1-3.2): which element
// exchanges light with which, through which directional bin, with which form factor.
// Refinement starts from the root's self-link (always subdivided) and uses the paper's
// oracle: a pair is linked when each element's bounding-sphere solid angle seen from the
// other is at most oracle_scale x the smallest bin's solid angle (and the spheres do not
// overlap); otherwise the larger element is subdivided; two leaves are linked regardless,
// unless settings.leaf_link_pieces > 0 (issue 37): then a leaf pair that fails the oracle is
// split virtually, each end into as many equal-area pieces as the oracle asks for at the
// pair's distance (link_pieces, at most leaf_link_pieces), every piece pair with its own
// distance and bin; the link keeps one record per (receiver, sender, bin).
// Precise near links (settings.near_link_samples = q > 0, issue 37, the paper's CPU scheme):
// every link with an end in the near set (the deforming groups' elements and the static
// elements within near_radius_m of a group's swept sphere) is made from pieces of both ends
// (a surface element's triangle cut into k^2 congruent sub-triangles, ElementHierarchy::corners;
// a cluster a disc facing the other end), each at most 1/q of the oracle's solid angle (the
// sender at least q), every piece pair in
// the bin of its own direction at its own distance: the link's form factor spread over the
// bins of the cone the sender subtends, bin by bin. More records per near link, the same
// record format, so the solver, the GPU pass and the bundle's link planes are unchanged.
// No visibility anywhere: antiradiance stands for it.
//
// Form factor, eq. 17: F = 1 / (d^2 omega_bin), spread over the bins the sender covers as
// seen from the receiver (the paper's "precise computation ... between all pairs of bins in
// the cone subtended by the sender", §3.1, with 16 fixed sample points on a disc standing
// for the sender instead of its exact cone): bin b gets share_b / (d^2 omega_b).
// Deviation: when the two bounding spheres overlap (only leaves can be linked then), d^2 is
// regularized to d^2 + min(a_r/pi, r_r^2) + min(a_s/pi, r_s^2) (the disc form factor of
// point_emitters.h), so touching leaves (a door against its frame) stay bounded.
// Links are directed (receiver <- sender); a receiver with a normal (a surface element)
// gets no link from a sender wholly behind its plane: solid objects receive light only in
// their positive hemisphere (§3.1, Fig. 7).
//
// Relinking (§3.3 "Moving Objects"): links between two static elements never change; when
// groups move only the links with an end in a moved group are rebuilt (its links to itself
// too: a rigid motion keeps their form factors but turns their bins).
//   gi::LinkMesh links = gi::link_elements(hierarchy, bins, settings);
//   gi::relink_moved(hierarchy, bins, settings, {1}, links);  // group 1 (the door) moved

#include <engine/result.h>

#include <cstdint>
#include <vector>

#include "antiradiance/antiradiance_settings.h"
#include "antiradiance/directional_bins.h"
#include "antiradiance/element_hierarchy.h"
#include "core/work_shard.h"

namespace gi {

struct Link {
  std::int32_t receiver = 0;
  std::int32_t sender = 0;
  std::int32_t bin = 0;      ///< Bin of the direction sender -> receiver (same global bins at both ends).
  float form_factor = 0.0f;  ///< 1 / (d^2_regularized omega_bin), 1/(m^2 sr).
};

/// Links sorted by (receiver, bin, sender): receiver r's links are [offsets[r], offsets[r+1]),
/// and within them each bin's links are contiguous (the GPU sums one (receiver, bin) run
/// per invocation; the CPU twin sums in the same order).
struct LinkMesh {
  std::vector<Link> links;
  std::vector<std::uint32_t> offsets;  ///< nodes + 1 entries.
  /// Counters of the last (re)link: elements whose links were rebuilt, links made.
  std::size_t relinked_elements = 0;
  std::size_t links_made = 0;
  /// Of the last (re)link: directed precise near links made (settings.near_link_samples), and
  /// the piece pairs they summed (their cost).
  std::size_t precise_links = 0;
  std::size_t precise_piece_pairs = 0;
};

/// The oracle's threshold: oracle_scale x 4 pi / bins (sr).
float oracle_threshold_sr(const DirectionalBins& bins, const AntiradianceSettings& settings);

/// The paper's oracle for a pair: the spheres do not overlap and each one's solid angle seen
/// from the other's centre (pi r^2 / d^2) is at most threshold_sr.
bool meets_oracle(const ElementNode& a, const ElementNode& b, float threshold_sr);

/// How many equal-area pieces each end of a leaf-leaf link is split into (1: not split).
struct LinkPieces {
  int sender = 1;
  int receiver = 1;
};
/// The pieces a link receiver <- sender that fails the oracle is split into: per end the
/// fewest n with pi radius_m^2 / (n d^2) <= threshold_sr (d: the centres' distance), at most
/// max_pieces (>= 1).
LinkPieces link_pieces(const ElementNode& receiver, const ElementNode& sender, float threshold_sr, int max_pieces);

/// All links of the hierarchy (counters: every element, every link).
LinkMesh link_elements(const ElementHierarchy& h, const DirectionalBins& bins, const AntiradianceSettings& settings);

/// Distributed bakes (docs/distributed-bake.md): the links of link_elements whose receiver
/// node is in `shard`'s blocks of 64 node indices, sorted as a LinkMesh, each one computed as
/// the whole refinement computes it (pairs whose subtrees hold no receiver of the shard are
/// not visited). Counters: the shard's receivers, its links.
LinkMesh link_elements_shard(const ElementHierarchy& h, const DirectionalBins& bins,
                             const AntiradianceSettings& settings, const WorkShard& shard);

/// The whole link mesh from the `parts[i]` = link_elements_shard(..., {i, parts.size()}):
/// each receiver's run taken from its shard, in linear time; equal to link_elements
/// (counters included). Error (naming "antiradiance shard i of N") when a part holds a
/// receiver outside its shard's blocks or out of range, or is not sorted.
engine::Result<LinkMesh> merge_link_shards(const ElementHierarchy& h, const std::vector<std::vector<Link>>& parts);

/// The links of `mesh` between two static elements (group 0): the ones no motion changes,
/// which a bake stores.
LinkMesh static_links(const ElementHierarchy& h, const LinkMesh& mesh);

/// Rebuilds the links with an end in a group of `moved` (deforming groups, >= 1, whose
/// elements already moved: set_group_transform), keeps the rest; the counters say how many
/// elements' links and how many links were rebuilt.
void relink_moved(const ElementHierarchy& h, const DirectionalBins& bins, const AntiradianceSettings& settings,
                  const std::vector<int>& moved, LinkMesh& mesh);

/// The links relink_moved(h, bins, settings, groups, mesh) adds to a mesh of static links
/// at the groups' current poses, sorted, with its counters: what a bake stores so that a
/// load at the baked pose merges them (merge_posed_links) instead of relinking.
LinkMesh posed_links(const ElementHierarchy& h, const DirectionalBins& bins, const AntiradianceSettings& settings,
                     const std::vector<int>& groups);

/// What relink_moved(h, bins, settings, groups, mesh) makes of `mesh` (static links only)
/// when `posed` = posed_links(h, bins, settings, groups) at the same poses: the same links
/// in the same order, offsets and counters, bit for bit, by a linear merge.
void merge_posed_links(const ElementHierarchy& h, const LinkMesh& posed, LinkMesh& mesh);

}  // namespace gi
