#include "antiradiance/antiradiance_io.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstring>
#include <type_traits>

#include "bundle/bundle_reader.h"
#include "bundle/geometry_hash.h"
#include "bundle/manifest.h"
#include "io/zstd_stream.h"

namespace gi {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

static_assert(sizeof(ElementNode) == 72, "ElementNode is written as 18 x 4 bytes");
static_assert(sizeof(Link) == 16, "Link is written as 4 x 4 bytes");
static_assert(sizeof(glm::vec3) == 12 && sizeof(glm::mat4) == 64, "packed GLM types");

engine::Error file_error(const fs::path& path, std::string location, std::string message) {
  return engine::Error{path.string(), std::move(location), std::move(message)};
}

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const std::size_t at = bytes.size();
    bytes.resize(at + sizeof(T));
    std::memcpy(bytes.data() + at, &v, sizeof(T));
  }
  template <class T>
  void array(const std::vector<T>& v) {
    put(static_cast<std::uint64_t>(v.size()));
    const std::size_t at = bytes.size();
    bytes.resize(at + v.size() * sizeof(T));
    if (!v.empty()) std::memcpy(bytes.data() + at, v.data(), v.size() * sizeof(T));
  }
  void string(const std::string& s) {
    put(static_cast<std::uint64_t>(s.size()));
    const std::size_t at = bytes.size();
    bytes.resize(at + s.size());
    if (!s.empty()) std::memcpy(bytes.data() + at, s.data(), s.size());
  }
  std::vector<std::byte> bytes;
};

class Reader {
 public:
  explicit Reader(const std::vector<std::byte>& b) : b_(b) {}
  template <class T>
  bool get(T& v) {
    if (b_.size() - at_ < sizeof(T)) return false;
    std::memcpy(&v, b_.data() + at_, sizeof(T));
    at_ += sizeof(T);
    return true;
  }
  template <class T>
  bool array(std::vector<T>& v) {
    std::uint64_t n = 0;
    if (!get(n) || n > (b_.size() - at_) / sizeof(T)) return false;
    v.resize(static_cast<std::size_t>(n));
    if (n > 0) std::memcpy(v.data(), b_.data() + at_, static_cast<std::size_t>(n) * sizeof(T));
    at_ += static_cast<std::size_t>(n) * sizeof(T);
    return true;
  }
  bool string(std::string& s) {
    std::uint64_t n = 0;
    if (!get(n) || n > b_.size() - at_) return false;
    s.assign(reinterpret_cast<const char*>(b_.data() + at_), static_cast<std::size_t>(n));
    at_ += static_cast<std::size_t>(n);
    return true;
  }
  bool done() const { return at_ == b_.size(); }

 private:
  const std::vector<std::byte>& b_;
  std::size_t at_ = 0;
};

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Empty when the settings a load uses (bins, leaf size, relinking, scheme) are valid, else what is wrong.
std::string check_settings(const AntiradianceSettings& s) {
  if (s.bins_per_side < 1 || s.bins_per_side > 64) return "bins_per_side outside 1..64";
  if (!(s.patch_size_m > 0.0f) || !std::isfinite(s.patch_size_m)) return "patch_size_m must be positive";
  if (!(s.near_patch_size_m >= 0.0f) || !std::isfinite(s.near_patch_size_m))
    return "near_patch_size_m must be finite and not negative";
  if (!(s.near_radius_m >= 0.0f) || !std::isfinite(s.near_radius_m))
    return "near_radius_m must be finite and not negative";
  if (s.leaf_link_pieces < 0 || s.leaf_link_pieces > kMaxLeafLinkPieces)
    return "leaf_link_pieces outside 0.." + std::to_string(kMaxLeafLinkPieces);
  if (s.scheme != AntiradianceScheme::Symmetric && s.scheme != AntiradianceScheme::Asymmetric) return "unknown scheme";
  if (!(s.near_visibility_radius_m >= 0.0f) || !std::isfinite(s.near_visibility_radius_m))
    return "near_visibility_radius_m must be finite and not negative";
  if (s.near_visibility_point_pairs < 1 || s.near_visibility_point_pairs > 64)
    return "near_visibility_point_pairs outside 1..64";
  if (s.near_visibility_budget_bytes > (std::uint64_t{1} << 40))
    return "near_visibility_budget_bytes above 1 TiB (corrupt)";
  return {};
}

// Empty when the bake's arrays fit together and its values are valid, else what is wrong.
// Long because it is one list of checks, one per array the file holds, each with its message.
std::string check_bake(const AntiradianceBake& b) {
  if (std::string problem = check_settings(b.settings); !problem.empty()) return problem;
  const ElementHierarchy& h = b.hierarchy;
  const std::size_t n = h.nodes.size();
  const auto in_nodes = [n](std::int64_t i) { return i >= 0 && static_cast<std::size_t>(i) < n; };
  if (n == 0) return "no element";
  if (h.node_instance.size() != n || h.object_center.size() != n || h.object_normal.size() != n ||
      h.object_radius.size() != n || h.object_area.size() != n)
    return "per-element arrays differ in size from the " + std::to_string(n) + " elements";
  // The triangles (near-door visibility's rays): 3 corners per element, or none.
  if ((!h.corners.empty() && h.corners.size() != 3 * n) || h.object_corners.size() != h.corners.size())
    return "the element triangles are not 3 corners per element";
  if (b.settings.near_visibility && h.corners.empty()) return "near visibility without the element triangles";
  for (std::size_t c = 0; c < h.corners.size(); ++c)
    if (!finite3(h.corners[c]) || !finite3(h.object_corners[c]))
      return "an element triangle has a NaN or infinite corner";
  if (h.group_transform.size() != h.deforming_instances.size() ||
      h.group_root.size() != h.deforming_instances.size() + 1)
    return "group arrays do not match the " + std::to_string(h.deforming_instances.size()) + " deforming instances";
  for (std::int32_t r : h.group_root)
    if (r != -1 && !in_nodes(r)) return "a group root is out of range";
  for (std::int32_t c : h.children)
    if (!in_nodes(c)) return "a child index is out of range";
  for (std::int32_t l : h.leaves)
    if (!in_nodes(l) || h.nodes[static_cast<std::size_t>(l)].child_count != 0) return "a leaf index is not a leaf";
  for (std::size_t i = 0; i < n; ++i) {
    const ElementNode& e = h.nodes[i];
    if (!finite3(e.center) || !finite3(e.normal) || !finite3(e.albedo) || !std::isfinite(e.radius_m) ||
        !std::isfinite(e.area_m2) || e.area_m2 < 0.0f || !finite3(h.object_center[i]) || !finite3(h.object_normal[i]) ||
        !std::isfinite(h.object_radius[i]) || !std::isfinite(h.object_area[i]))
      return "element " + std::to_string(i) + " has a NaN, infinite or negative value";
    if ((e.parent != -1 && !in_nodes(e.parent)) || e.child_count < 0 || e.first_child < 0 ||
        static_cast<std::size_t>(e.first_child) + static_cast<std::size_t>(e.child_count) > h.children.size() ||
        e.leaf_begin < 0 || e.leaf_end < e.leaf_begin || static_cast<std::size_t>(e.leaf_end) > h.leaves.size() ||
        e.end <= static_cast<std::int32_t>(i) || static_cast<std::size_t>(e.end) > n || e.group < -1 ||
        e.group > static_cast<std::int32_t>(h.deforming_instances.size()))
      return "element " + std::to_string(i) + " has an index out of range";
    if (i > 0 && e.parent >= static_cast<std::int32_t>(i))
      return "element " + std::to_string(i) + " follows its parent";
  }
  const std::int32_t bins = b.settings.bins_per_side * b.settings.bins_per_side;
  for (std::size_t k = 0; k < b.static_links.links.size(); ++k) {
    const Link& l = b.static_links.links[k];
    if (!in_nodes(l.receiver) || !in_nodes(l.sender) || l.bin < 0 || l.bin >= bins || !std::isfinite(l.form_factor) ||
        l.form_factor < 0.0f)
      return "static link " + std::to_string(k) + " is out of range";
    if (h.nodes[static_cast<std::size_t>(l.receiver)].group != 0 ||
        h.nodes[static_cast<std::size_t>(l.sender)].group != 0)
      return "static link " + std::to_string(k) + " has an end in a deforming group";
    if (k > 0) {
      const Link& p = b.static_links.links[k - 1];
      if (p.receiver > l.receiver || (p.receiver == l.receiver && p.bin > l.bin))
        return "static links are not sorted by receiver and bin";
    }
  }
  if (b.baseline.size() != h.leaves.size())
    return "the baseline has " + std::to_string(b.baseline.size()) + " values for " + std::to_string(h.leaves.size()) +
           " leaves";
  for (const glm::vec3& v : b.baseline)
    if (!finite3(v)) return "the baseline holds a NaN or infinite value";
  return {};
}

// Empty when b.at_baked_pose fits b's hierarchy (indices, bins, order, values), else what
// is wrong.
std::string check_at_pose(const AntiradianceBake& b) {
  const AntiradianceBake::AtBakedPose& p = b.at_baked_pose;
  const ElementHierarchy& h = b.hierarchy;
  const std::size_t n = h.nodes.size();
  const auto in_nodes = [n](std::int64_t i) { return i >= 0 && static_cast<std::size_t>(i) < n; };
  const std::int32_t bins = b.settings.bins_per_side * b.settings.bins_per_side;
  if (p.links.relinked_elements > n) return "more relinked elements than elements";
  for (std::size_t k = 0; k < p.links.links.size(); ++k) {
    const Link& l = p.links.links[k];
    if (!in_nodes(l.receiver) || !in_nodes(l.sender) || l.bin < 0 || l.bin >= bins || !std::isfinite(l.form_factor) ||
        l.form_factor < 0.0f)
      return "posed link " + std::to_string(k) + " is out of range";
    if (h.nodes[static_cast<std::size_t>(l.receiver)].group < 1 &&
        h.nodes[static_cast<std::size_t>(l.sender)].group < 1)
      return "posed link " + std::to_string(k) + " has no end in a deforming group";
    if (k > 0) {
      const Link& q = p.links.links[k - 1];
      if (q.receiver > l.receiver ||
          (q.receiver == l.receiver && (q.bin > l.bin || (q.bin == l.bin && q.sender >= l.sender))))
        return "posed links are not sorted by receiver, bin and sender";
    }
  }
  const std::size_t leaves = h.leaves.size();
  for (std::size_t k = 0; k < p.blends.size(); ++k) {
    const AntiradianceTexelBlend& t = p.blends[k];
    if (k > 0 && t.texel <= p.blends[k - 1].texel) return "texel blends are not in increasing texel order";
    for (int j = 0; j < 4; ++j)
      if (t.leaves[j] < -1 || (t.leaves[j] >= 0 && static_cast<std::size_t>(t.leaves[j]) >= leaves) ||
          !std::isfinite(t.weights[j]))
        return "texel blend " + std::to_string(k) + " names a leaf out of range or a non-finite weight";
  }
  return {};
}

// CSR offsets of sorted links.
void index_links(std::size_t nodes, LinkMesh& mesh) {
  mesh.offsets.assign(nodes + 1, 0u);
  for (const Link& l : mesh.links) ++mesh.offsets[static_cast<std::size_t>(l.receiver) + 1];
  for (std::size_t i = 1; i < mesh.offsets.size(); ++i) mesh.offsets[i] += mesh.offsets[i - 1];
}

// zstd level of the link planes: level 3 packs the corridor's 1.5 M links in ~0.2 s.
constexpr int kZstdLevel = 3;
// Bytes per link in the planes: receiver step (u32), bin (u16), sender code (i32), and the
// form factor's four bytes, each its own plane.
constexpr std::size_t kLinkPlaneBytes = 4 + 2 + 4 + 4;

// The links as planes (lossless): the receiver as the step from the previous link's (0 or
// small), the bin, the sender as the step from the previous link's sender when receiver and
// bin are the same (sorted runs: small positive steps) else as itself, and the float bits
// of the form factor split into four byte planes (the exponent byte compresses well).
std::vector<std::uint8_t> link_planes(const std::vector<Link>& links) {
  const std::size_t n = links.size();
  std::vector<std::uint8_t> out(n * kLinkPlaneBytes);
  std::uint8_t* receiver = out.data();
  std::uint8_t* bin = receiver + 4 * n;
  std::uint8_t* sender = bin + 2 * n;
  std::uint8_t* ff = sender + 4 * n;
  for (std::size_t k = 0; k < n; ++k) {
    const Link& l = links[k];
    const bool same_run = k > 0 && links[k - 1].receiver == l.receiver && links[k - 1].bin == l.bin;
    const std::uint32_t step =
        static_cast<std::uint32_t>(l.receiver) - (k > 0 ? static_cast<std::uint32_t>(links[k - 1].receiver) : 0u);
    const std::uint16_t b = static_cast<std::uint16_t>(l.bin);
    const std::uint32_t sc =
        static_cast<std::uint32_t>(l.sender) - (same_run ? static_cast<std::uint32_t>(links[k - 1].sender) : 0u);
    std::uint32_t bits = 0;
    std::memcpy(&bits, &l.form_factor, 4);
    std::memcpy(receiver + 4 * k, &step, 4);
    std::memcpy(bin + 2 * k, &b, 2);
    std::memcpy(sender + 4 * k, &sc, 4);
    for (int j = 0; j < 4; ++j) ff[static_cast<std::size_t>(j) * n + k] = static_cast<std::uint8_t>(bits >> (8 * j));
  }
  return out;
}

std::vector<Link> links_from_planes(const std::vector<std::uint8_t>& planes, std::size_t n) {
  std::vector<Link> links(n);
  const std::uint8_t* receiver = planes.data();
  const std::uint8_t* bin = receiver + 4 * n;
  const std::uint8_t* sender = bin + 2 * n;
  const std::uint8_t* ff = sender + 4 * n;
  for (std::size_t k = 0; k < n; ++k) {
    std::uint32_t step = 0, sc = 0, bits = 0;
    std::uint16_t b = 0;
    std::memcpy(&step, receiver + 4 * k, 4);
    std::memcpy(&b, bin + 2 * k, 2);
    std::memcpy(&sc, sender + 4 * k, 4);
    for (int j = 0; j < 4; ++j) bits |= static_cast<std::uint32_t>(ff[static_cast<std::size_t>(j) * n + k]) << (8 * j);
    Link& l = links[k];
    l.receiver = static_cast<std::int32_t>((k > 0 ? static_cast<std::uint32_t>(links[k - 1].receiver) : 0u) + step);
    l.bin = b;
    const bool same_run = k > 0 && links[k - 1].receiver == l.receiver && links[k - 1].bin == l.bin;
    l.sender = static_cast<std::int32_t>((same_run ? static_cast<std::uint32_t>(links[k - 1].sender) : 0u) + sc);
    std::memcpy(&l.form_factor, &bits, 4);
  }
  return links;
}

// Bytes per texel blend in the stream: texel (u32), four leaves (i32), four weights (f32).
constexpr std::size_t kBlendBytes = 4 + 16 + 16;

std::vector<std::uint8_t> blend_records(const std::vector<AntiradianceTexelBlend>& blends) {
  std::vector<std::uint8_t> out(blends.size() * kBlendBytes);
  for (std::size_t k = 0; k < blends.size(); ++k) {
    std::uint8_t* o = out.data() + k * kBlendBytes;
    std::memcpy(o, &blends[k].texel, 4);
    std::memcpy(o + 4, &blends[k].leaves, 16);
    std::memcpy(o + 20, &blends[k].weights, 16);
  }
  return out;
}

std::vector<AntiradianceTexelBlend> blends_from_records(const std::vector<std::uint8_t>& records, std::size_t n) {
  std::vector<AntiradianceTexelBlend> blends(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint8_t* o = records.data() + k * kBlendBytes;
    std::memcpy(&blends[k].texel, o, 4);
    std::memcpy(&blends[k].leaves, o + 4, 16);
    std::memcpy(&blends[k].weights, o + 20, 16);
  }
  return blends;
}

json settings_json(const AntiradianceSettings& s) {
  return json{{"bins_per_side", s.bins_per_side},
              {"patch_size_m", s.patch_size_m},
              {"exchange_radius_m", s.exchange_radius_m},
              {"oracle_scale", s.oracle_scale},
              {"iterations", s.iterations},
              {"antiradiance_steps", s.antiradiance_steps},
              {"scheme", s.scheme == AntiradianceScheme::Symmetric ? "symmetric" : "asymmetric"},
              {"residual_tolerance", s.residual_tolerance},
              {"growth_limit", s.growth_limit},
              {"area_light_samples", s.area_light_samples},
              {"near_patch_size_m", s.near_patch_size_m},
              {"near_radius_m", s.near_radius_m},
              {"leaf_link_pieces", s.leaf_link_pieces},
              {"near_visibility", s.near_visibility},
              {"near_visibility_radius_m", s.near_visibility_radius_m},
              {"near_visibility_point_pairs", s.near_visibility_point_pairs},
              {"near_visibility_budget_bytes", s.near_visibility_budget_bytes},
              {"seed", s.seed}};
}

}  // namespace

engine::Status write_antiradiance(const fs::path& path, const AntiradianceBake& b, const std::string& geometry_hash) {
  if (std::string problem = check_bake(b); !problem.empty())
    return file_error(path, "", "cannot save the antiradiance bake: " + problem);
  Writer w;
  w.string(geometry_hash);
  const AntiradianceSettings& s = b.settings;
  w.put(static_cast<std::int32_t>(s.bins_per_side));
  w.put(s.patch_size_m);
  w.put(s.exchange_radius_m);
  w.put(s.oracle_scale);
  w.put(static_cast<std::int32_t>(s.iterations));
  w.put(static_cast<std::int32_t>(s.antiradiance_steps));
  w.put(static_cast<std::uint8_t>(s.scheme));
  w.put(s.residual_tolerance);
  w.put(static_cast<std::int32_t>(s.growth_limit));
  w.put(static_cast<std::int32_t>(s.area_light_samples));
  w.put(static_cast<std::uint64_t>(s.seed));
  w.put(s.near_patch_size_m);
  w.put(s.near_radius_m);
  w.put(static_cast<std::int32_t>(s.leaf_link_pieces));
  w.put(static_cast<std::uint8_t>(s.near_visibility ? 1 : 0));
  w.put(s.near_visibility_radius_m);
  w.put(static_cast<std::int32_t>(s.near_visibility_point_pairs));
  w.put(static_cast<std::uint64_t>(s.near_visibility_budget_bytes));
  const ElementHierarchy& h = b.hierarchy;
  w.array(h.deforming_instances);
  w.array(h.group_transform);
  w.array(h.nodes);
  w.array(h.children);
  w.array(h.leaves);
  w.array(h.group_root);
  w.array(h.node_instance);
  w.array(h.object_center);
  w.array(h.object_normal);
  w.array(h.object_radius);
  w.array(h.object_area);
  // The triangles only where the runtime traces rays against them (near-door visibility).
  const std::vector<glm::vec3> none;
  w.array(s.near_visibility ? h.corners : none);
  w.array(s.near_visibility ? h.object_corners : none);
  // The static links, most of the file: their planes as one zstd frame.
  const std::vector<std::uint8_t> planes = link_planes(b.static_links.links);
  auto frame = write_zstd_stream(path, planes, kZstdLevel);
  if (!frame) return frame.error();
  w.put(static_cast<std::uint64_t>(b.static_links.links.size()));
  w.array(*frame);
  w.array(b.baseline);
  return write_blob(path, kAntiradianceMagic, kAntiradianceVersion, w.bytes);
}

engine::Result<AntiradianceFile> read_antiradiance(const fs::path& path) {
  auto payload = read_blob(path, kAntiradianceMagic, kAntiradianceVersion);
  if (!payload) return payload.error();
  Reader r(*payload);
  AntiradianceFile f;
  AntiradianceSettings& s = f.bake.settings;
  ElementHierarchy& h = f.bake.hierarchy;
  std::int32_t bins = 0, iterations = 0, steps = 0, growth = 0, samples = 0, pieces = 0, near_pairs = 0;
  std::uint8_t scheme = 0, near = 0;
  std::uint64_t seed = 0;
  const bool ok = r.string(f.geometry_hash) && r.get(bins) && r.get(s.patch_size_m) && r.get(s.exchange_radius_m) &&
                  r.get(s.oracle_scale) && r.get(iterations) && r.get(steps) && r.get(scheme) &&
                  r.get(s.residual_tolerance) && r.get(growth) && r.get(samples) && r.get(seed) &&
                  r.get(s.near_patch_size_m) && r.get(s.near_radius_m) && r.get(pieces) && r.get(near) &&
                  r.get(s.near_visibility_radius_m) && r.get(near_pairs) && r.get(s.near_visibility_budget_bytes) &&
                  r.array(h.deforming_instances) && r.array(h.group_transform) && r.array(h.nodes) &&
                  r.array(h.children) && r.array(h.leaves) && r.array(h.group_root) && r.array(h.node_instance) &&
                  r.array(h.object_center) && r.array(h.object_normal) && r.array(h.object_radius) &&
                  r.array(h.object_area) && r.array(h.corners) && r.array(h.object_corners);
  std::uint64_t link_count = 0;
  std::vector<std::uint8_t> frame;
  if (!ok || !r.get(link_count) || !r.array(frame) || !r.array(f.bake.baseline))
    return file_error(path, "", "truncated: a field or array runs past the end of the payload");
  if (!r.done()) return file_error(path, "", "trailing bytes after the last array");
  // The link planes: one zstd frame of exactly link_count x 14 bytes.
  if (link_count > (std::uint64_t{1} << 40) / kLinkPlaneBytes)
    return file_error(path, "static_links", std::to_string(link_count) + " links is beyond any bake (corrupt)");
  auto planes = read_zstd_stream(path, "static_links", frame, link_count * kLinkPlaneBytes);
  if (!planes) return planes.error();
  f.bake.static_links.links = links_from_planes(*planes, static_cast<std::size_t>(link_count));
  s.bins_per_side = bins;
  s.iterations = iterations;
  s.antiradiance_steps = steps;
  s.scheme = static_cast<AntiradianceScheme>(scheme);
  s.growth_limit = growth;
  s.area_light_samples = samples;
  s.seed = seed;
  s.leaf_link_pieces = pieces;
  if (near > 1) return file_error(path, "near_visibility", "not 0 or 1 (corrupt)");
  s.near_visibility = near == 1;
  s.near_visibility_point_pairs = near_pairs;
  if (std::string problem = check_bake(f.bake); !problem.empty()) return file_error(path, "", problem);
  index_links(h.nodes.size(), f.bake.static_links);
  f.bake.static_links.links_made = f.bake.static_links.links.size();
  return f;
}

engine::Status write_antiradiance_at_pose(const fs::path& path, const AntiradianceBake& b,
                                          const std::string& geometry_hash) {
  if (std::string problem = check_bake(b); !problem.empty())
    return file_error(path, "", "cannot save the antiradiance bake: " + problem);
  if (!b.at_baked_pose.present)
    return file_error(path, "", "cannot save what the bake did not prepare (at_baked_pose)");
  if (std::string problem = check_at_pose(b); !problem.empty())
    return file_error(path, "", "cannot save the antiradiance load data: " + problem);
  const AntiradianceBake::AtBakedPose& p = b.at_baked_pose;
  auto links = write_zstd_stream(path, link_planes(p.links.links), kZstdLevel);
  if (!links) return links.error();
  auto blends = write_zstd_stream(path, blend_records(p.blends), kZstdLevel);
  if (!blends) return blends.error();
  Writer w;
  w.string(geometry_hash);
  w.put(static_cast<std::uint64_t>(p.links.relinked_elements));
  w.put(static_cast<std::uint64_t>(p.links.links.size()));
  w.array(*links);
  w.put(p.layout_fingerprint);
  w.put(static_cast<std::uint64_t>(p.blends.size()));
  w.array(*blends);
  return write_blob(path, kAntiradianceAtPoseMagic, kAntiradianceAtPoseVersion, w.bytes);
}

engine::Result<AntiradianceAtPoseFile> read_antiradiance_at_pose(const fs::path& path) {
  auto payload = read_blob(path, kAntiradianceAtPoseMagic, kAntiradianceAtPoseVersion);
  if (!payload) return payload.error();
  Reader r(*payload);
  AntiradianceAtPoseFile f;
  AntiradianceBake::AtBakedPose& p = f.at_baked_pose;
  std::uint64_t relinked = 0, link_count = 0, blend_count = 0;
  std::vector<std::uint8_t> link_frame, blend_frame;
  const bool ok = r.string(f.geometry_hash) && r.get(relinked) && r.get(link_count) && r.array(link_frame) &&
                  r.get(p.layout_fingerprint) && r.get(blend_count) && r.array(blend_frame);
  if (!ok) return file_error(path, "", "truncated: a field or array runs past the end of the payload");
  if (!r.done()) return file_error(path, "", "trailing bytes after the last array");
  if (link_count > (std::uint64_t{1} << 40) / kLinkPlaneBytes)
    return file_error(path, "posed_links", std::to_string(link_count) + " links is beyond any bake (corrupt)");
  if (blend_count > (std::uint64_t{1} << 40) / kBlendBytes)
    return file_error(path, "texel_blends", std::to_string(blend_count) + " blends is beyond any bake (corrupt)");
  auto planes = read_zstd_stream(path, "posed_links", link_frame, link_count * kLinkPlaneBytes);
  if (!planes) return planes.error();
  auto records = read_zstd_stream(path, "texel_blends", blend_frame, blend_count * kBlendBytes);
  if (!records) return records.error();
  p.links.links = links_from_planes(*planes, static_cast<std::size_t>(link_count));
  p.links.relinked_elements = static_cast<std::size_t>(relinked);
  p.links.links_made = p.links.links.size();
  p.blends = blends_from_records(*records, static_cast<std::size_t>(blend_count));
  p.present = true;
  return f;
}

engine::Status save_antiradiance(const fs::path& bundle_dir, const AntiradianceBake& bake, const BakeInput& input) {
  const fs::path file = bundle_dir / kAntiradianceFile;
  if (std::string problem = check_bake(bake); !problem.empty())
    return file_error(file, "", "cannot save the antiradiance bake: " + problem);
  std::error_code ec;
  fs::create_directories(bundle_dir, ec);
  if (ec) return engine::Error{bundle_dir.string(), "", "cannot create the bundle directory: " + ec.message()};
  const std::string geometry_hash = scene_geometry_hash(input);
  if (engine::Status st = write_antiradiance(file, bake, geometry_hash); !st) return st;
  auto sum = file_checksum(file);
  if (!sum) return sum.error();
  const std::uintmax_t bytes = fs::file_size(file, ec);
  if (ec) return file_error(file, "", "cannot read the file size: " + ec.message());
  json files{{"elements", {{"file", kAntiradianceFile}, {"xxh3_64", *sum}}}};
  if (bake.at_baked_pose.present) {
    const fs::path at_pose = bundle_dir / kAntiradianceAtPoseFile;
    if (engine::Status st = write_antiradiance_at_pose(at_pose, bake, geometry_hash); !st) return st;
    auto at_pose_sum = file_checksum(at_pose);
    if (!at_pose_sum) return at_pose_sum.error();
    files["at_pose"] = {{"file", kAntiradianceAtPoseFile}, {"xxh3_64", *at_pose_sum}};
  }
  const json entry{{"files", files},
                   {"settings", settings_json(bake.settings)},
                   {"elements", bake.hierarchy.nodes.size()},
                   {"leaves", bake.hierarchy.leaves.size()},
                   {"static_links", bake.static_links.links.size()},
                   {"deforming_instances", bake.hierarchy.deforming_instances},
                   {"memory", {{"file_bytes", static_cast<std::uint64_t>(bytes)}}}};
  return update_manifest_method(bundle_dir, geometry_hash, fs::path(input.name).filename().string(),
                                kAntiradianceMethod, entry);
}

engine::Result<AntiradianceBake> load_antiradiance(const fs::path& bundle_dir, const BakeInput& input) {
  auto bundle = BundleReader::open(bundle_dir, kAntiradianceMethod, input, "re-bake the antiradiance region");
  if (!bundle) return bundle.error();
  auto path = bundle->file("elements");
  if (!path) return path.error();
  auto f = read_antiradiance(*path);
  if (!f) return f.error();
  if (engine::Status st = bundle->check_geometry(*path, f->geometry_hash); !st) return st.error();
  // What the bake computed for a load at its pose (absent: the load computes it).
  if (bundle->has_file("at_pose")) {
    auto at_pose_path = bundle->file("at_pose");
    if (!at_pose_path) return at_pose_path.error();
    auto at_pose = read_antiradiance_at_pose(*at_pose_path);
    if (!at_pose) return at_pose.error();
    if (engine::Status st = bundle->check_geometry(*at_pose_path, at_pose->geometry_hash); !st) return st.error();
    f->bake.at_baked_pose = std::move(at_pose->at_baked_pose);
    if (std::string problem = check_at_pose(f->bake); !problem.empty())
      return file_error(*at_pose_path, "", problem + " (corrupt, or of another bake; re-bake)");
  }
  return std::move(f->bake);
}

engine::Result<std::vector<std::uint8_t>> pack_link_shard(const fs::path& path, const std::vector<Link>& links) {
  const std::vector<std::uint8_t> planes = link_planes(links);
  return write_zstd_stream(path, planes, kZstdLevel);
}

engine::Result<std::vector<Link>> unpack_link_shard(const fs::path& path, std::span<const std::uint8_t> frame,
                                                    std::uint64_t link_count) {
  if (link_count > (std::uint64_t{1} << 40) / kLinkPlaneBytes)
    return file_error(path, "antiradiance links", std::to_string(link_count) + " links is beyond any bake (corrupt)");
  auto planes = read_zstd_stream(path, "antiradiance links", frame, link_count * kLinkPlaneBytes);
  if (!planes) return planes.error();
  return links_from_planes(*planes, static_cast<std::size_t>(link_count));
}

}  // namespace gi
