#include "uv/atlas_layout.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <unordered_map>

#include "uv/chart_builder.h"
#include "uv/chart_packer.h"

namespace gi {
namespace {

engine::Status validate_settings(const AtlasSettings& s) {
  auto bad = [](const std::string& what) { return engine::Error{"", "AtlasSettings", what}; };
  if (!std::isfinite(s.texels_per_metre) || !(s.texels_per_metre > 0.0f))
    return bad("texels_per_metre must be a finite positive density, got " + std::to_string(s.texels_per_metre));
  if (s.texels_per_metre > kMaxTexelsPerMetre)
    return bad("texels_per_metre " + std::to_string(s.texels_per_metre) + " is absurd (more than " +
               std::to_string(kMaxTexelsPerMetre) + " texels per metre)");
  if (s.padding_texels < 0 || s.padding_texels > 64)
    return bad("padding_texels must be in 0..64, got " + std::to_string(s.padding_texels));
  if (s.max_atlas_size < 16 || s.max_atlas_size > 16384)
    return bad("max_atlas_size must be in 16..16384, got " + std::to_string(s.max_atlas_size));
  if (s.max_atlas_size - 2 * s.padding_texels < 1)
    return bad("max_atlas_size " + std::to_string(s.max_atlas_size) + " leaves no room inside padding " +
               std::to_string(s.padding_texels));
  if (!(s.chart_max_angle_degrees > 0.0f && s.chart_max_angle_degrees < 90.0f))
    return bad("chart_max_angle_degrees must be in (0, 90), got " + std::to_string(s.chart_max_angle_degrees));
  if (!std::isfinite(s.weld_distance_m) || s.weld_distance_m < 0.0f)
    return bad("weld_distance_m must be finite and >= 0, got " + std::to_string(s.weld_distance_m));
  return {};
}

// Footprint of a chart: whole texels that hold its rectangle with a margin of at least
// 0.005 texel on each side (so conservative rasterization never touches texels outside).
glm::ivec2 footprint(const Chart& c, double density) {
  const double w = static_cast<double>(c.size_m.x) * density, h = static_cast<double>(c.size_m.y) * density;
  return glm::ivec2(static_cast<int>(std::floor(w + 0.01)) + 1, static_cast<int>(std::floor(h + 0.01)) + 1);
}

std::vector<glm::ivec2> footprints(const std::vector<Chart>& charts, double density) {
  std::vector<glm::ivec2> sizes;
  sizes.reserve(charts.size());
  for (const Chart& c : charts) sizes.push_back(footprint(c, density));
  return sizes;
}

// The packing of the charts and the density it was reached at: the largest chart must fit inside
// the padded atlas; then lower the density until the packing fits (footprints carry a fixed
// overhead, so shrink geometrically).
struct DensityPacking {
  ShelfPacking packing;
  std::vector<glm::ivec2> sizes;
  double density = 0.0;
};

engine::Result<DensityPacking> pack_at_fitting_density(const std::vector<Chart>& charts,
                                                       const AtlasSettings& settings) {
  const int pad = settings.padding_texels;
  const int usable = settings.max_atlas_size - 2 * pad;
  double density = settings.texels_per_metre;
  double max_extent_m = 0.0;
  for (const Chart& c : charts)
    max_extent_m = std::max(max_extent_m, static_cast<double>(std::max(c.size_m.x, c.size_m.y)));
  if (max_extent_m * density > usable - 0.02) density = (usable - 0.02) / max_extent_m;

  std::optional<ShelfPacking> packing;
  std::vector<glm::ivec2> sizes;
  for (int attempt = 0; attempt < 400 && density > 0.0; ++attempt) {
    sizes = footprints(charts, density);
    packing = pack_growing(sizes, pad, settings.max_atlas_size);
    if (packing) break;
    const bool all_minimal = std::all_of(sizes.begin(), sizes.end(), [](glm::ivec2 s) { return s == glm::ivec2(1); });
    if (all_minimal) break;
    double needed = 0.0;
    for (glm::ivec2 s : sizes) needed += double(s.x + pad) * double(s.y + pad);
    const double room = double(settings.max_atlas_size) * double(settings.max_atlas_size);
    const double f = attempt < 40 ? std::clamp(std::sqrt(room / needed), 0.5, 0.95) : 0.5;
    density *= f;
  }
  if (!packing)
    return engine::Error{"", "build_atlas_layout",
                         std::to_string(charts.size()) + " charts do not fit a " +
                             std::to_string(settings.max_atlas_size) + " x " + std::to_string(settings.max_atlas_size) +
                             " atlas with padding " + std::to_string(pad) + " at any texel density"};
  return DensityPacking{std::move(*packing), std::move(sizes), density};
}

// One mesh's UV1: one output vertex per (input vertex, chart) pair, uv from that chart's
// projection at `density` into its placed rectangle. out.triangle_chart is already set.
void assign_mesh_uv1(const AtlasInputMesh& in, const std::vector<Chart>& charts,
                     const std::vector<AtlasChart>& placed_charts, double density, glm::dvec2 atlas_size,
                     AtlasMeshUv& out) {
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  const std::size_t n = in.positions.size();
  out.source_vertex.resize(n);
  for (std::size_t v = 0; v < n; ++v) out.source_vertex[v] = static_cast<std::uint32_t>(v);
  out.uv1.assign(n, glm::vec2(0.0f));
  out.indices.resize(in.indices.size());
  std::vector<std::uint32_t> first_chart(n, kNone);
  std::unordered_map<std::uint64_t, std::uint32_t> copies;  // (vertex << 32 | chart) -> output vertex
  for (std::size_t k = 0; k < in.indices.size(); ++k) {
    const std::uint32_t v = in.indices[k];
    const std::uint32_t ci = out.triangle_chart[k / 3];
    std::uint32_t ov;
    if (first_chart[v] == kNone || first_chart[v] == ci) {
      ov = v;
    } else {
      const std::uint64_t key = (std::uint64_t{v} << 32) | ci;
      auto [it, inserted] = copies.try_emplace(key, static_cast<std::uint32_t>(out.source_vertex.size()));
      ov = it->second;
      if (inserted) {
        out.source_vertex.push_back(v);
        out.uv1.emplace_back(0.0f);
      }
    }
    out.indices[k] = ov;
    if (first_chart[v] == kNone) first_chart[v] = ci;
    const Chart& c = charts[ci];
    const AtlasChart& placed = placed_charts[ci];
    const glm::dvec2 extent = glm::dvec2(c.size_m) * density;
    const glm::dvec2 margin = (glm::dvec2(placed.size) - extent) * 0.5;
    const glm::dvec2 texel = glm::dvec2(placed.origin) + margin + glm::dvec2(c.project_m(in.positions[v])) * density;
    out.uv1[ov] = glm::vec2(glm::clamp(texel / atlas_size, 0.0, 1.0));
  }
}

}  // namespace

engine::Result<AtlasLayout> build_atlas_layout(std::span<const AtlasInputMesh> inputs, const AtlasSettings& settings) {
  if (engine::Status s = validate_settings(settings); !s) return s.error();
  if (engine::Status s = validate_atlas_inputs(inputs); !s) return s.error();

  const ChartingSettings charting{.max_angle_degrees = settings.chart_max_angle_degrees,
                                  .weld_distance_m = settings.weld_distance_m,
                                  .rotate_to_min_area = settings.rotate_charts};
  std::vector<Chart> charts;
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    std::vector<Chart> mc = build_charts(inputs[i], static_cast<std::uint32_t>(i), charting);
    charts.insert(charts.end(), std::make_move_iterator(mc.begin()), std::make_move_iterator(mc.end()));
  }

  engine::Result<DensityPacking> fitted = pack_at_fitting_density(charts, settings);
  if (!fitted) return fitted.error();
  const ShelfPacking& packing = fitted->packing;
  const std::vector<glm::ivec2>& sizes = fitted->sizes;
  const double density = fitted->density;
  const int pad = settings.padding_texels;

  AtlasLayout layout;
  layout.width = packing.width;
  layout.height = packing.height;
  layout.texels_per_metre = static_cast<float>(density);
  if (layout.texels_per_metre > settings.texels_per_metre) layout.texels_per_metre = settings.texels_per_metre;
  layout.requested_texels_per_metre = settings.texels_per_metre;
  layout.padding_texels = pad;
  const glm::dvec2 atlas_size(layout.width, layout.height);

  layout.meshes.resize(inputs.size());
  for (std::size_t i = 0; i < inputs.size(); ++i) {
    layout.meshes[i].id = inputs[i].id;
    layout.meshes[i].triangle_chart.assign(inputs[i].indices.size() / 3, 0u);
  }
  layout.charts.reserve(charts.size());
  for (std::size_t ci = 0; ci < charts.size(); ++ci) {
    const Chart& c = charts[ci];
    AtlasChart out;
    out.mesh = c.mesh;
    out.origin = packing.origins[ci];
    out.size = sizes[ci];
    out.normal = c.normal;
    out.triangle_count = static_cast<std::uint32_t>(c.triangles.size());
    out.area_m2 = c.area_m2;
    layout.charts.push_back(out);
    for (std::uint32_t t : c.triangles) layout.meshes[c.mesh].triangle_chart[t] = static_cast<std::uint32_t>(ci);
  }

  // Per mesh: one output vertex per (input vertex, chart) pair, uv from that chart's projection.
  for (std::size_t mi = 0; mi < inputs.size(); ++mi)
    assign_mesh_uv1(inputs[mi], charts, layout.charts, density, atlas_size, layout.meshes[mi]);
  return layout;
}

engine::Result<AtlasLayout> static_world_layout(const BakeInput& input, float texels_per_metre) {
  return build_atlas_layout(atlas_inputs_from(input), {.texels_per_metre = texels_per_metre});
}

}  // namespace gi
