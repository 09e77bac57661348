#include "transport/vpl_set.h"

#include "raytrace/material_lookup.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "core/random.h"
#include "uv/chart_builder.h"

namespace gi {

namespace {

// One chart in its plane: the 2-D triangles and a bucket grid over them for point location.
class ChartPlane {
 public:
  ChartPlane(const Chart& chart, const ReferenceSceneIndex& index, std::uint32_t first_triangle)
      : chart_(chart), first_(first_triangle) {
    for (std::uint32_t t : chart.triangles) {
      const ShadingTriangle& tri = index.triangles[first_ + t];
      tris_.push_back({chart.project_m(tri.p0), chart.project_m(tri.p0 + tri.e1), chart.project_m(tri.p0 + tri.e2)});
    }
    cells_ = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(tris_.size()))));
    buckets_.resize(static_cast<std::size_t>(cells_ * cells_));
    for (std::uint32_t k = 0; k < tris_.size(); ++k) {
      const auto& t = tris_[k];
      const glm::vec2 lo = glm::min(t[0], glm::min(t[1], t[2]));
      const glm::vec2 hi = glm::max(t[0], glm::max(t[1], t[2]));
      const glm::ivec2 c0 = cell(lo), c1 = cell(hi);
      for (int y = c0.y; y <= c1.y; ++y)
        for (int x = c0.x; x <= c1.x; ++x) buckets_[static_cast<std::size_t>(y * cells_ + x)].push_back(k);
    }
  }

  /// The chart triangle (index into chart.triangles) containing 2-D point q, with the
  /// barycentrics (u, v) of its e1, e2 edges; false when q lies outside the chart.
  bool locate(glm::vec2 q, std::uint32_t& triangle, glm::vec2& uv) const {
    const glm::ivec2 c = cell(q);
    for (std::uint32_t k : buckets_[static_cast<std::size_t>(c.y * cells_ + c.x)]) {
      const auto& t = tris_[k];
      const glm::vec2 e1 = t[1] - t[0], e2 = t[2] - t[0], d = q - t[0];
      const float det = e1.x * e2.y - e1.y * e2.x;
      if (std::fabs(det) <= 0.0f) continue;
      const float u = (d.x * e2.y - d.y * e2.x) / det;
      const float v = (e1.x * d.y - e1.y * d.x) / det;
      if (u >= 0.0f && v >= 0.0f && u + v <= 1.0f) {
        triangle = k;
        uv = {u, v};
        return true;
      }
    }
    return false;
  }

 private:
  glm::ivec2 cell(glm::vec2 q) const {
    const glm::vec2 size = glm::max(chart_.size_m, glm::vec2(1e-12f));
    const glm::ivec2 c(glm::floor(q / size * static_cast<float>(cells_)));
    return glm::clamp(c, glm::ivec2(0), glm::ivec2(cells_ - 1));
  }

  const Chart& chart_;
  std::uint32_t first_;
  std::vector<std::array<glm::vec2, 3>> tris_;
  int cells_ = 1;
  std::vector<std::vector<std::uint32_t>> buckets_;
};

struct Sample {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 plane;  // chart coordinates, metres
  std::uint32_t material;
  std::uint32_t triangle;  // index.triangles entry it lies on
  glm::vec2 bary;          // its barycentrics there (the material lookup's point)
};

// Jittered grid of spacing h over the chart's rectangle: one candidate per cell, kept when it
// falls on the chart.
std::vector<Sample> jittered_points(const Chart& chart, const ChartPlane& plane, const ReferenceSceneIndex& index,
                                    std::uint32_t first_triangle, float h, Pcg32& rng) {
  std::vector<Sample> out;
  const float offset_y = rng.next_float() * h;  // drawn first: see random.h
  const glm::vec2 offset(rng.next_float() * h, offset_y);
  const int nx = static_cast<int>(std::ceil((chart.size_m.x + offset.x) / h));
  const int ny = static_cast<int>(std::ceil((chart.size_m.y + offset.y) / h));
  for (int y = 0; y < ny; ++y) {
    for (int x = 0; x < nx; ++x) {
      const float jx = rng.next_float(), jy = rng.next_float();
      const glm::vec2 q = glm::vec2(static_cast<float>(x) + jx, static_cast<float>(y) + jy) * h - offset;
      std::uint32_t k = 0;
      glm::vec2 uv;
      if (!plane.locate(q, k, uv)) continue;
      const ShadingTriangle& tri = index.triangles[first_triangle + chart.triangles[k]];
      out.push_back({tri.p0 + uv.x * tri.e1 + uv.y * tri.e2, tri.face_normal, q, tri.material,
                     first_triangle + chart.triangles[k], uv});
    }
  }
  return out;
}

// Seeds bucketed on a grid of their spacing in chart coordinates; nearest() searches rings
// of cells outwards until no closer seed can exist.
class SeedGrid {
 public:
  SeedGrid(const std::vector<Sample>& seeds, float cell) : seeds_(seeds), cell_(cell) {
    lo_ = hi_ = seeds.front().plane;
    for (const Sample& s : seeds) lo_ = glm::min(lo_, s.plane), hi_ = glm::max(hi_, s.plane);
    dims_ = glm::ivec2(glm::floor((hi_ - lo_) / cell_)) + 1;
    buckets_.resize(static_cast<std::size_t>(dims_.x) * static_cast<std::size_t>(dims_.y));
    for (std::uint32_t i = 0; i < seeds.size(); ++i) buckets_[bucket(cell_of(seeds[i].plane))].push_back(i);
  }

  std::uint32_t nearest(glm::vec2 q) const {
    const glm::ivec2 c = cell_of(q);
    std::uint32_t best = 0;
    float best_d2 = std::numeric_limits<float>::infinity();
    const int max_ring = std::max(dims_.x, dims_.y);
    for (int r = 0; r <= max_ring; ++r) {
      for (int y = c.y - r; y <= c.y + r; ++y) {
        for (int x = c.x - r; x <= c.x + r; ++x) {
          if (std::max(std::abs(x - c.x), std::abs(y - c.y)) != r) continue;  // ring only
          if (x < 0 || y < 0 || x >= dims_.x || y >= dims_.y) continue;
          for (std::uint32_t i : buckets_[bucket({x, y})]) {
            const glm::vec2 d = seeds_[i].plane - q;
            const float d2 = glm::dot(d, d);
            if (d2 < best_d2 || (d2 == best_d2 && i < best)) best_d2 = d2, best = i;
          }
        }
      }
      // Cells beyond ring r are at least r cells away from q's cell.
      const float reach = static_cast<float>(r) * cell_;
      if (best_d2 < reach * reach) break;
    }
    return best;
  }

 private:
  glm::ivec2 cell_of(glm::vec2 q) const {
    return glm::clamp(glm::ivec2(glm::floor((q - lo_) / cell_)), glm::ivec2(0), dims_ - 1);
  }
  std::size_t bucket(glm::ivec2 c) const {
    return static_cast<std::size_t>(c.y) * static_cast<std::size_t>(dims_.x) + static_cast<std::size_t>(c.x);
  }

  const std::vector<Sample>& seeds_;
  float cell_;
  glm::vec2 lo_, hi_;
  glm::ivec2 dims_;
  std::vector<std::vector<std::uint32_t>> buckets_;
};

// A static instance as an atlas-input mesh (three vertices per triangle; charting welds them).
struct StaticMesh {
  AtlasInputMesh mesh;
  std::uint32_t first_triangle = 0;
};

// The static instances as meshes, and their total area (m^2) in *total_area.
std::vector<StaticMesh> static_meshes(const ReferenceScene& scene, const ReferenceSceneIndex& index,
                                      double& total_area) {
  std::vector<StaticMesh> meshes;
  const auto& instances = scene.geometry.instances;
  for (std::size_t k = 0; k < instances.size(); ++k) {
    if (instances[k].dynamic) continue;
    const auto [first, end] = instance_triangles(index, k);
    StaticMesh m;
    m.first_triangle = first;
    for (std::uint32_t t = first; t < end; ++t) {
      const ShadingTriangle& tri = index.triangles[t];
      const auto base = static_cast<std::uint32_t>(m.mesh.positions.size());
      m.mesh.positions.insert(m.mesh.positions.end(), {tri.p0, tri.p0 + tri.e1, tri.p0 + tri.e2});
      m.mesh.indices.insert(m.mesh.indices.end(), {base, base + 1, base + 2});
      total_area += static_cast<double>(tri.area_m2);
    }
    if (!m.mesh.indices.empty()) meshes.push_back(std::move(m));
  }
  return meshes;
}

// A sample's albedo: its material's, or with textures the material lookup's at its point
// for a footprint of the sample spacing (the samples of a patch together average the
// texture over the patch).
class SampleAlbedo {
 public:
  SampleAlbedo(const ReferenceScene& scene, const ReferenceSceneIndex& index, double sample_spacing)
      : scene_(scene), index_(index), hs_(sample_spacing) {}
  glm::vec3 operator()(const Sample& sample) {
    const std::uint32_t m = sample.material;
    if (scene_.materials[m].textured())
      return albedo_at(scene_, index_.triangles[sample.triangle], sample.bary, static_cast<float>(hs_));
    auto it = cache_.find(m);
    if (it == cache_.end())
      it = cache_.emplace(m, engine::gltf_hemispherical_albedo(scene_.materials[m].brdf).sum()).first;
    return it->second;
  }

 private:
  const ReferenceScene& scene_;
  const ReferenceSceneIndex& index_;
  double hs_;
  std::unordered_map<std::uint32_t, glm::vec3> cache_;
};

// One VPL per Voronoi patch: every sample joins its nearest seed (in the chart's plane);
// one Lloyd step then puts the VPL at the patch sample nearest the patch's centroid.
void add_patch_vpls(const std::vector<Sample>& samples, const std::vector<Sample>& seeds, double h, double sample_area,
                    SampleAlbedo& albedo, VplSet& out) {
  const SeedGrid grid(seeds, static_cast<float>(h));
  std::vector<std::vector<std::uint32_t>> members(seeds.size());
  for (std::uint32_t s = 0; s < samples.size(); ++s) members[grid.nearest(samples[s].plane)].push_back(s);
  for (const auto& patch : members) {
    if (patch.empty()) continue;
    glm::dvec3 centroid(0.0), normal(0.0), rho(0.0);
    for (std::uint32_t s : patch) {
      centroid += glm::dvec3(samples[s].position);
      normal += glm::dvec3(samples[s].normal);
      rho += glm::dvec3(albedo(samples[s]));
    }
    centroid /= static_cast<double>(patch.size());
    std::uint32_t nearest = patch.front();
    double nearest_d = std::numeric_limits<double>::infinity();
    for (std::uint32_t s : patch) {
      const glm::dvec3 d = glm::dvec3(samples[s].position) - centroid;
      if (glm::dot(d, d) < nearest_d) nearest_d = glm::dot(d, d), nearest = s;
    }
    out.position.push_back(samples[nearest].position);
    out.normal.push_back(glm::length(normal) > 0.0 ? glm::vec3(glm::normalize(normal)) : samples[nearest].normal);
    out.albedo.push_back(glm::vec3(rho / static_cast<double>(patch.size())));
    out.area_m2.push_back(static_cast<float>(sample_area * static_cast<double>(patch.size())));
    for (std::uint32_t s : patch) {
      out.sample_position.push_back(samples[s].position);
      out.sample_normal.push_back(samples[s].normal);
      out.sample_area_m2.push_back(static_cast<float>(sample_area));
    }
    out.sample_first.push_back(static_cast<std::uint32_t>(out.sample_position.size()));
  }
}

// The VPLs of one chart: jittered samples of spacing hs, seeds of spacing h, their patches.
void add_chart_vpls(const Chart& chart, const StaticMesh& sm, const ReferenceSceneIndex& index,
                    const VplDistributionSettings& settings, double h, double hs, Pcg32& rng, SampleAlbedo& albedo,
                    VplSet& out) {
  const ChartPlane plane(chart, index, sm.first_triangle);
  std::vector<Sample> samples = jittered_points(chart, plane, index, sm.first_triangle, static_cast<float>(hs), rng);
  double sample_area = samples.empty() ? 0.0 : chart.area_m2 / static_cast<double>(samples.size());
  if (samples.empty()) {
    // A chart smaller than a sample cell: one sample with probability area / hs^2 and
    // area hs^2, so the expected area is kept (the chart's texels still receive light).
    if (static_cast<double>(rng.next_float()) >= chart.area_m2 / (hs * hs)) return;
    const ShadingTriangle& tri = index.triangles[sm.first_triangle + chart.triangles.front()];
    samples.push_back({tri.p0 + (tri.e1 + tri.e2) / 3.0f,
                       tri.face_normal,
                       {},
                       tri.material,
                       sm.first_triangle + chart.triangles.front(),
                       glm::vec2(1.0f / 3.0f)});
    sample_area = hs * hs;
  }

  // One sample per VPL: every sample is its own VPL (a second grid of the same spacing
  // would leave about a third of its seeds without a sample).
  std::vector<Sample> seeds = settings.samples_per_vpl == 1
                                  ? samples
                                  : jittered_points(chart, plane, index, sm.first_triangle, static_cast<float>(h), rng);
  if (seeds.empty()) seeds.push_back(samples[samples.size() / 2]);
  add_patch_vpls(samples, seeds, h, sample_area, albedo, out);
}

}  // namespace

engine::Result<VplSet> distribute_vpls(const ReferenceScene& scene, const ReferenceSceneIndex& index,
                                       const VplDistributionSettings& settings) {
  if (settings.vpl_count < 1 || settings.vpl_count > 10'000'000)
    return engine::Error{.message = "VPL count " + std::to_string(settings.vpl_count) + " is outside 1..10^7"};
  if (settings.samples_per_vpl < 1 || settings.samples_per_vpl > 1024)
    return engine::Error{.message =
                             "samples per VPL " + std::to_string(settings.samples_per_vpl) + " is outside 1..1024"};

  double total_area = 0.0;
  const std::vector<StaticMesh> meshes = static_meshes(scene, index, total_area);
  if (!(total_area > 0.0) || !std::isfinite(total_area))
    return engine::Error{.message = "the scene has no static surface area to place VPLs on"};

  const double h = std::sqrt(total_area / settings.vpl_count);                     // VPL spacing
  const double hs = h / std::sqrt(static_cast<double>(settings.samples_per_vpl));  // sample spacing
  SampleAlbedo albedo(scene, index, hs);

  VplSet out;
  out.sample_first.push_back(0);
  std::uint64_t chart_id = 0;
  for (std::size_t mi = 0; mi < meshes.size(); ++mi) {
    const StaticMesh& sm = meshes[mi];
    for (const Chart& chart : build_charts(sm.mesh, static_cast<std::uint32_t>(mi), ChartingSettings{})) {
      Pcg32 rng = Pcg32::for_item(settings.seed, chart_id++);
      if (!(chart.area_m2 > 0.0)) continue;
      add_chart_vpls(chart, sm, index, settings, h, hs, rng, albedo, out);
    }
  }
  if (out.size() == 0) return engine::Error{.message = "no VPL could be placed on the static surfaces"};
  return out;
}

}  // namespace gi
