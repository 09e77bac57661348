#include "prm/pane_upsample.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace gi {
namespace {

// Chart c's affine map from fine to coarse texel coordinates: coarse = a * (fine - f0) + c0.
struct ChartMap {
  glm::dmat2 a{1.0};
  glm::dvec2 f0{0.0}, c0{0.0};
  bool known = false;
};

glm::dvec2 texel_coords(const AtlasLayout& layout, const AtlasMeshUv& mesh, std::uint32_t vertex) {
  return glm::dvec2(mesh.uv1[vertex]) * glm::dvec2(layout.width, layout.height);
}

// Per chart, from its triangle of largest fine-texel area (a sliver would make the solve
// ill-conditioned).
engine::Result<std::vector<ChartMap>> chart_maps(const AtlasLayout& coarse, const AtlasLayout& fine) {
  const auto mismatch = [](const std::string& what) {
    return engine::Error{.message = "PRM pane upsampling: the pane layout and the atlas layout " + what};
  };
  if (coarse.charts.size() != fine.charts.size() || coarse.meshes.size() != fine.meshes.size())
    return mismatch("have different charts (" + std::to_string(coarse.charts.size()) + " and " +
                    std::to_string(fine.charts.size()) + ")");
  std::vector<ChartMap> maps(fine.charts.size());
  std::vector<double> best(fine.charts.size(), 0.0);
  for (std::size_t m = 0; m < fine.meshes.size(); ++m) {
    const AtlasMeshUv &fm = fine.meshes[m], &cm = coarse.meshes[m];
    if (fm.triangle_chart != cm.triangle_chart || fm.indices.size() != cm.indices.size())
      return mismatch("cut mesh " + std::to_string(m) + " into different charts");
    for (std::size_t t = 0; t < fm.triangle_chart.size(); ++t) {
      const std::uint32_t c = fm.triangle_chart[t];
      glm::dvec2 f[3], k[3];
      for (int v = 0; v < 3; ++v) {
        f[v] = texel_coords(fine, fm, fm.indices[3 * t + static_cast<std::size_t>(v)]);
        k[v] = texel_coords(coarse, cm, cm.indices[3 * t + static_cast<std::size_t>(v)]);
      }
      const glm::dmat2 fe(f[1] - f[0], f[2] - f[0]);
      const double det = std::fabs(glm::determinant(fe));
      if (!(det > best[c])) continue;
      best[c] = det;
      maps[c] = {glm::dmat2(k[1] - k[0], k[2] - k[0]) * glm::inverse(fe), f[0], k[0], true};
    }
  }
  return maps;
}

}  // namespace

// Long because the read of one fine texel is found in one pass: its chart's map, the four
// bilinear neighbours kept when they lie in the chart's footprint and hold values, and the
// nearest filled texel of the footprint when none does.
engine::Result<PaneUpsampler> PaneUpsampler::build(const AtlasLayout& coarse,
                                                   std::span<const std::uint32_t> coarse_filled,
                                                   const AtlasLayout& fine, const AtlasTexels& fine_texels,
                                                   int gutter_rings) {
  auto maps = chart_maps(coarse, fine);
  if (!maps) return maps.error();
  if (fine_texels.width != fine.width || fine_texels.height != fine.height)
    return engine::Error{.message = "PRM pane upsampling: the atlas texels are not of the atlas layout"};
  PaneUpsampler up;
  up.fine_width_ = fine.width;
  up.coarse_width_ = coarse.width;
  up.fine_size_ = static_cast<std::size_t>(fine.width) * static_cast<std::size_t>(fine.height);
  up.coarse_size_ = static_cast<std::size_t>(coarse.width) * static_cast<std::size_t>(coarse.height);
  std::vector<std::uint8_t> filled(up.coarse_size_, 0);
  for (std::uint32_t t : coarse_filled)
    if (t < filled.size()) filled[t] = 1;
  for (std::size_t i = 0; i < fine_texels.valid.size(); ++i) {
    if (!fine_texels.valid[i] || fine_texels.chart[i] < 0) continue;
    const auto c = static_cast<std::size_t>(fine_texels.chart[i]);
    const ChartMap& map = (*maps)[c];
    const AtlasChart& box = coarse.charts[c];
    const glm::dvec2 centre(static_cast<double>(i % static_cast<std::size_t>(fine.width)) + 0.5,
                            static_cast<double>(i / static_cast<std::size_t>(fine.width)) + 0.5);
    const glm::dvec2 q = map.c0 + map.a * (centre - map.f0) - 0.5;
    const auto inside = [&](int x, int y) {
      return x >= box.origin.x && y >= box.origin.y && x < box.origin.x + box.size.x && y < box.origin.y + box.size.y &&
             filled[static_cast<std::size_t>(y) * coarse.width + x];
    };
    const int x0 = static_cast<int>(std::floor(q.x)), y0 = static_cast<int>(std::floor(q.y));
    const double ax = q.x - x0, ay = q.y - y0;
    Read read{.fine = static_cast<std::uint32_t>(i), .origin = {x0, y0}, .weight = {}};
    std::array<double, 4> w{};
    double sum = 0.0;
    for (int k = 0; k < 4; ++k) {
      const double wk = ((k & 1) ? ax : 1.0 - ax) * ((k >> 1) ? ay : 1.0 - ay);
      if (!map.known || !inside(x0 + (k & 1), y0 + (k >> 1)) || !(wk > 0.0)) continue;
      w[static_cast<std::size_t>(k)] = wk;
      sum += wk;
    }
    if (sum > 0.0) {
      for (std::size_t k = 0; k < 4; ++k)
        read.weight[k] = std::round(static_cast<float>(w[k] / sum) * kWeightSteps) / kWeightSteps;
    } else {
      double nearest = std::numeric_limits<double>::infinity();
      for (int y = box.origin.y; y < box.origin.y + box.size.y; ++y)
        for (int x = box.origin.x; x < box.origin.x + box.size.x; ++x) {
          const double d2 = (x - q.x) * (x - q.x) + (y - q.y) * (y - q.y);
          if (inside(x, y) && d2 < nearest) nearest = d2, read.origin = {x, y};
        }
      if (nearest == std::numeric_limits<double>::infinity()) {
        ++up.orphans_;
        read.origin = {x0, y0};
      } else {
        read.weight[0] = 1.0f;
      }
    }
    up.reads_.push_back(read);
  }
  up.add_gutter_rings(fine.height, gutter_rings);
  return up;
}

// gi::dilate's rings (dilation is linear): a ring texel reads the mean of its 8-neighbours
// filled before that ring, applied ring by ring after the reads.
void PaneUpsampler::add_gutter_rings(int height, int rings) {
  const int width = fine_width_;
  std::vector<std::int32_t> ring_of(fine_size_, -1);  // fine texel -> the ring that filled it (0: a read)
  for (const Read& r : reads_) ring_of[r.fine] = 0;
  for (int ring = 1; ring <= rings; ++ring) {
    const auto filled = [&](int x, int y) {
      if (x < 0 || y < 0 || x >= width || y >= height) return false;
      const std::int32_t r = ring_of[static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + x];
      return r >= 0 && r < ring;
    };
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + x;
        if (ring_of[i] >= 0) continue;
        std::uint32_t mask = 0;
        for (std::size_t k = 0; k < kNeighbour.size(); ++k)
          if (filled(x + kNeighbour[k].x, y + kNeighbour[k].y)) mask |= 1u << k;
        if (mask == 0) continue;
        ring_of[i] = ring;
        ring_texels_.push_back({static_cast<std::uint32_t>(i), mask});
      }
    ring_first_.push_back(static_cast<std::uint32_t>(ring_texels_.size()));
  }
}

std::vector<std::uint32_t> PaneUpsampler::fine_texels() const {
  std::vector<std::uint32_t> out;
  out.reserve(reads_.size() + ring_texels_.size());
  for (const Read& r : reads_) out.push_back(r.fine);
  for (const RingTexel& r : ring_texels_) out.push_back(r.fine);
  return out;
}

std::vector<glm::vec3> PaneUpsampler::apply(std::span<const glm::vec3> coarse_image) const {
  if (coarse_image.size() != coarse_size_) return {};
  std::vector<glm::vec3> out(fine_size_, glm::vec3(0.0f));
  const auto coarse_at = [&](int x, int y) {
    if (x < 0 || y < 0 || x >= coarse_width_) return glm::vec3(0.0f);
    const std::size_t t = static_cast<std::size_t>(y) * static_cast<std::size_t>(coarse_width_) + x;
    return t < coarse_size_ ? coarse_image[t] : glm::vec3(0.0f);
  };
  for (const Read& r : reads_) {
    glm::vec3 v(0.0f);
    for (int k = 0; k < 4; ++k)
      if (r.weight[static_cast<std::size_t>(k)] > 0.0f)
        v += r.weight[static_cast<std::size_t>(k)] * coarse_at(r.origin.x + (k & 1), r.origin.y + (k >> 1));
    out[r.fine] = v;
  }
  const auto w = static_cast<std::size_t>(fine_width_);
  for (const RingTexel& r : ring_texels_) {
    glm::vec3 v(0.0f);
    float n = 0.0f;
    for (std::size_t k = 0; k < kNeighbour.size(); ++k)
      if (r.neighbours & (1u << k)) {
        const std::size_t x = r.fine % w, y = r.fine / w;
        v += out[(y + static_cast<std::size_t>(kNeighbour[k].y)) * w + x + static_cast<std::size_t>(kNeighbour[k].x)];
        n += 1.0f;
      }
    out[r.fine] = v / n;
  }
  return out;
}

}  // namespace gi
