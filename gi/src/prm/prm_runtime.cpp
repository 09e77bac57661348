#include "prm/prm_runtime.h"

#include <algorithm>
#include <numeric>

#include "transport/vpl_transport.h"

namespace gi {

namespace {

// Directions traced per punctual light to check its flux (64^2).
constexpr int kFluxSide = 64;

// Irradiance of entry points from one punctual light by its traced hits: each hit's flux
// goes to the nearest entry point that faces the same way, if one lies within twice the
// entry spacing there (an entry stands for the surface around it).
void deposit_hits(const Prm& prm, const PointEmitter& light, const std::vector<LitDirection>& hits,
                  std::vector<glm::vec3>& out) {
  for (const LitDirection& h : hits) {
    std::size_t best = prm.entries.size();
    float best_d2 = 0.0f;
    for (std::size_t k = 0; k < prm.entries.size(); ++k) {
      if (glm::dot(prm.entries[k].normal, h.normal) < 0.7f) continue;
      const glm::vec3 d = prm.entries[k].position - h.point;
      const float d2 = glm::dot(d, d);
      if (best == prm.entries.size() || d2 < best_d2) best = k, best_d2 = d2;
    }
    if (best == prm.entries.size() || best_d2 > 4.0f * prm.entries[best].area_m2) continue;
    out[best] += light.radiant * (h.solid_angle_sr / prm.entries[best].area_m2);
  }
}

}  // namespace

std::vector<glm::vec3> entry_irradiance(const Prm& prm, std::span<const PointEmitter> lights, const RayCaster& caster,
                                        ThreadPool* pool) {
  std::vector<glm::vec3> out(prm.entries.size(), glm::vec3(0.0f));
  std::vector<glm::vec3> one(prm.entries.size());
  std::vector<std::uint32_t> lit;  // entries the light reaches unshadowed, ascending
  std::vector<Ray> rays;
  std::vector<std::uint8_t> blocked;
  for (const PointEmitter& l : lights) {
    std::fill(one.begin(), one.end(), glm::vec3(0.0f));
    lit.clear();
    rays.clear();
    for (std::size_t k = 0; k < prm.entries.size(); ++k) {
      const PrmEntryPoint& e = prm.entries[k];
      one[k] = emitter_irradiance(l, e.position, e.normal, e.area_m2);
      if (one[k] == glm::vec3(0.0f)) continue;
      lit.push_back(static_cast<std::uint32_t>(k));
      rays.push_back(emitter_shadow_ray(l, e.position, e.normal));
    }
    // The shadow rays of one emitter converge on it: traced together (packets), the same
    // answers as emitter_visible one by one.
    blocked.resize(rays.size());
    caster.occluded_coherent(rays, blocked);
    double sampled = 0.0;  // in entry order, as before
    for (std::size_t i = 0; i < lit.size(); ++i) {
      const PrmEntryPoint& e = prm.entries[lit[i]];
      if (blocked[i]) {
        one[lit[i]] = glm::vec3(0.0f);
        continue;
      }
      sampled += static_cast<double>(e.area_m2) * static_cast<double>(luminance(one[lit[i]]));
    }
    if (l.kind == PointEmitter::Kind::Punctual) {
      // The entry points sample the light's irradiance; the flux they account for must be
      // what the light sends onto the scene (point_emitters.h). A light touching a surface
      // puts its flux between the entry points: then the traced hits are deposited instead.
      std::vector<LitDirection> hits;
      const double traced =
          static_cast<double>(luminance(l.radiant)) * punctual_lit_solid_angle(l, caster, kFluxSide, &hits, pool);
      if (sampled > 0.25 * traced) {
        const auto scale = static_cast<float>(std::clamp(traced / sampled, 0.25, 4.0));
        for (glm::vec3& v : one) v *= scale;
      } else {
        std::fill(one.begin(), one.end(), glm::vec3(0.0f));
        deposit_hits(prm, l, hits, one);
      }
    }
    for (std::size_t k = 0; k < out.size(); ++k) out[k] += one[k];
  }
  return out;
}

std::vector<glm::vec3> cluster_weights(const Prm& prm, std::span<const glm::vec3> entry_irradiance) {
  std::vector<glm::dvec3> sum(static_cast<std::size_t>(prm.cluster_count), glm::dvec3(0.0));
  for (std::size_t k = 0; k < prm.entries.size() && k < entry_irradiance.size(); ++k)
    sum[prm.entries[k].cluster] += glm::dvec3(entry_irradiance[k]);
  std::vector<glm::vec3> out(sum.size(), glm::vec3(0.0f));
  for (std::size_t c = 0; c < sum.size(); ++c)
    if (prm.cluster_size[c] > 0) out[c] = glm::vec3(sum[c] / static_cast<double>(prm.cluster_size[c]));
  return out;
}

std::vector<ClusterWeight> select_clusters(std::span<const glm::vec3> weights, int k) {
  std::vector<std::uint32_t> order;
  for (std::uint32_t c = 0; c < weights.size(); ++c)
    if (luminance(weights[c]) > 0.0f) order.push_back(c);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) { return luminance(weights[a]) > luminance(weights[b]); });
  if (k > 0 && order.size() > static_cast<std::size_t>(k)) order.resize(static_cast<std::size_t>(k));
  std::vector<ClusterWeight> out;
  for (std::uint32_t c : order) out.push_back({c, weights[c]});
  return out;
}

std::vector<ClusterWeight> relight_clusters(const Prm& prm, std::span<const ReferenceLight> lights,
                                            const RayCaster& caster, int k) {
  const std::vector<PointEmitter> emitters = light_point_emitters(lights, 16, prm.settings.seed);
  return select_clusters(cluster_weights(prm, entry_irradiance(prm, emitters, caster)), k);
}

std::vector<glm::vec3> sum_panes(const Prm& prm, std::span<const ClusterWeight> selected) {
  std::vector<glm::vec3> out(static_cast<std::size_t>(prm.width) * static_cast<std::size_t>(prm.height),
                             glm::vec3(0.0f));
  // Only the blocks each selected cluster stores: the work follows the lit tiles.
  const PrmPanes& p = prm.panes;
  for (const ClusterWeight& cw : selected) {
    if (cw.cluster >= p.cluster_count()) continue;
    for (std::uint32_t b = p.cluster_first[cw.cluster]; b < p.cluster_first[cw.cluster + 1]; ++b) {
      const std::uint32_t* element = p.tiles.elements.data() + p.tiles.first[p.blocks[b]];
      const float* v = p.values.data() + p.block_value[b] * 3;
      for (std::uint32_t j = 0; j < p.tiles.size(p.blocks[b]); ++j)
        out[prm.texels[element[j]]] += cw.weight * glm::vec3(v[3 * j], v[3 * j + 1], v[3 * j + 2]);
    }
  }
  // Coarse panes: the upsampling is linear, so the sum is read at the atlas once.
  if (prm.atlas && prm.atlas->upsampler) return prm.atlas->upsampler->apply(out);
  return out;
}

}  // namespace gi
