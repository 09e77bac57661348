#include "brf/brf_runtime.h"

#include <algorithm>
#include <cmath>

#include "brf/spherical_harmonics.h"
#include "raytrace/embree_ray_caster.h"

namespace gi {
namespace {


// Weights (per channel) of radiosity values over an object's vertices.
std::array<std::vector<float>, 3> fit_rgb(const BrfBasis& basis, const std::vector<glm::vec3>& radiosity) {
  std::array<std::vector<float>, 3> w;
  std::vector<float> channel(radiosity.size());
  for (int c = 0; c < 3; ++c) {
    for (std::size_t j = 0; j < radiosity.size(); ++j) channel[j] = radiosity[j][c];
    w[static_cast<std::size_t>(c)] = basis.fit(channel);
  }
  return w;
}

}  // namespace

BrfResult update_brf(std::span<const BrfObject> objects, std::span<const PointEmitter> lights,
                     const BrfUpdateSettings& settings) {
  BrfResult out;
  const std::size_t n = objects.size();
  out.direct.resize(n);
  out.indirect.resize(n);
  if (n == 0) return out;

  // All objects in one ray caster for shadows.
  RtSceneData data;
  for (std::size_t o = 0; o < n; ++o) {
    data.geometries.push_back({objects[o].mesh->positions, objects[o].mesh->indices});
    data.instances.push_back({static_cast<std::uint32_t>(o), objects[o].object_to_world, true, o});
  }
  auto caster = make_embree_ray_caster(data);
  if (!caster) return out;

  // World-space vertices and normals.
  std::vector<std::vector<glm::vec3>> wp(n), wn(n);
  for (std::size_t o = 0; o < n; ++o) {
    const glm::mat4& m = objects[o].object_to_world;
    const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(m)));
    for (std::size_t j = 0; j < objects[o].mesh->positions.size(); ++j) {
      wp[o].push_back(glm::vec3(m * glm::vec4(objects[o].mesh->positions[j], 1.0f)));
      wn[o].push_back(glm::normalize(nm * objects[o].mesh->normals[j]));
    }
  }

  // 1. Direct light.
  for (std::size_t o = 0; o < n; ++o) {
    out.direct[o].assign(wp[o].size(), glm::vec3(0.0f));
    out.indirect[o].assign(wp[o].size(), glm::vec3(0.0f));
    for (std::size_t j = 0; j < wp[o].size(); ++j)
      for (const PointEmitter& l : lights) {
        const glm::vec3 e = emitter_irradiance(l, wp[o][j], wn[o][j], 0.0f);
        if (e != glm::vec3(0.0f) && emitter_visible(**caster, l, wp[o][j], wn[o][j])) out.direct[o][j] += e;
      }
  }

  // Pair culling (§5.4): the bound irradiance of each source at each receiver's centre,
  // evaluated once with the source's mean weights.
  std::vector<std::vector<glm::vec3>> light(n);  // radiosity leaving each vertex this bounce
  for (std::size_t o = 0; o < n; ++o) {
    light[o].resize(wp[o].size());
    for (std::size_t j = 0; j < wp[o].size(); ++j) light[o][j] = objects[o].albedo * out.direct[o][j];
  }
  std::vector<float> coeffs;
  for (int bounce = 0; bounce < settings.bounces; ++bounce) {
    std::vector<std::array<std::vector<float>, 3>> w(n);
    for (std::size_t s = 0; s < n; ++s) w[s] = fit_rgb(*objects[s].basis, light[s]);
    // Bound contributions I_c of every pair for culling.
    std::vector<float> bound(n * n, 0.0f);
    float largest = 0.0f;
    for (std::size_t s = 0; s < n; ++s)
      for (std::size_t r = 0; r < n; ++r) {
        if (s == r) continue;
        const BasisRadianceField& f = *objects[s].field;
        const glm::mat4 to_source = glm::inverse(objects[s].object_to_world);
        const glm::vec3 centre_r = glm::vec3(objects[r].object_to_world * glm::vec4(objects[r].basis->centre, 1.0f));
        const glm::vec3 p = glm::vec3(to_source * glm::vec4(centre_r, 1.0f));
        coeffs.assign(static_cast<std::size_t>(f.basis_count * f.coefficient_count()), 0.0f);
        f.sample(p, coeffs);
        // Irradiance on the plane facing the source (the receiver's best case), per channel max.
        const glm::vec3 facing = glm::normalize(f.centre - p);
        const auto lobe = sh_clamped_cosine(glm::length(facing) > 0.0f ? facing : glm::vec3(0, 1, 0), f.sh_bands);
        float b = 0.0f;
        for (int c = 0; c < 3; ++c) {
          float e = 0.0f;
          for (int i = 0; i < f.basis_count; ++i)
            e += w[s][static_cast<std::size_t>(c)][static_cast<std::size_t>(i)] *
                 sh_dot(std::span<const float>(coeffs).subspan(static_cast<std::size_t>(i * f.coefficient_count())), lobe,
                        static_cast<std::size_t>(f.coefficient_count()));
          b = std::max(b, std::fabs(e));
        }
        bound[s * n + r] = b;
        largest = std::max(largest, b);
      }
    std::vector<std::vector<glm::vec3>> gathered(n);
    for (std::size_t r = 0; r < n; ++r) gathered[r].assign(wp[r].size(), glm::vec3(0.0f));
    for (std::size_t s = 0; s < n; ++s) {
      const BasisRadianceField& f = *objects[s].field;
      const glm::mat4 to_source = glm::inverse(objects[s].object_to_world);
      const glm::mat3 rot = glm::mat3(to_source);
      const auto cc = static_cast<std::size_t>(f.coefficient_count());
      for (std::size_t r = 0; r < n; ++r) {
        if (s == r) continue;
        if (bound[s * n + r] <= settings.cull_threshold * largest) {
          ++out.pairs_culled;
          continue;
        }
        ++out.pairs_evaluated;
        coeffs.assign(static_cast<std::size_t>(f.basis_count) * cc, 0.0f);
        for (std::size_t j = 0; j < wp[r].size(); ++j) {
          const glm::vec3 p = glm::vec3(to_source * glm::vec4(wp[r][j], 1.0f));
          const glm::vec3 nrm = glm::normalize(rot * wn[r][j]);
          f.sample(p, coeffs);
          const auto lobe = sh_clamped_cosine(nrm, f.sh_bands);
          glm::vec3 e(0.0f);
          for (int i = 0; i < f.basis_count; ++i) {
            const float phi = sh_dot(std::span<const float>(coeffs).subspan(static_cast<std::size_t>(i) * cc), lobe, cc);
            for (int c = 0; c < 3; ++c) e[c] += w[s][static_cast<std::size_t>(c)][static_cast<std::size_t>(i)] * phi;
          }
          gathered[r][j] += glm::max(e, glm::vec3(0.0f));  // SH ringing must not make light negative
        }
      }
    }
    for (std::size_t r = 0; r < n; ++r)
      for (std::size_t j = 0; j < wp[r].size(); ++j) {
        out.indirect[r][j] += gathered[r][j];
        light[r][j] = objects[r].albedo * gathered[r][j];
      }
  }
  return out;
}

}  // namespace gi
