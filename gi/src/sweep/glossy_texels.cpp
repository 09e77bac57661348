#include "sweep/glossy_texels.h"

#include "raytrace/material_lookup.h"

#include <engine/scene.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/random.h"
#include "core/thread_pool.h"
#include "raytrace/path_tracer.h"
#include "raytrace/ray_offset.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace gi {
namespace {

// Other random streams than any bake's (see reference_sweep.cpp).
constexpr std::uint64_t kReferenceSeed = 0x646c6d7265666572ULL;

// The roughness below which a material counts as the floor (the planner's old threshold).
constexpr double kGlossyOriginal = 0.35;

engine::Error request_error(const ReferenceRequest& r, const std::string& message) {
  return engine::Error{"<sweep>", r.key(), message};
}

}  // namespace

engine::SceneAsset with_floor_roughness(const engine::SceneAsset& asset, double floor_roughness) {
  engine::SceneAsset out = asset;
  for (engine::Material& m : out.materials)
    if (static_cast<double>(m.roughness) < kGlossyOriginal) m.roughness = static_cast<float>(floor_roughness);
  return out;
}
double glossy_threshold(double floor_roughness) { return std::max(kGlossyOriginal, floor_roughness + 0.05); }

engine::Result<GlossyTexels> glossy_texels(const SweepScene& scene, double density, double floor_roughness,
                                           const ReferenceRequest* request, TexelPlacement placement, GlossyView view) {
  const double roughness = glossy_threshold(floor_roughness);
  const engine::Scene live = engine::instantiate(with_floor_roughness(scene.asset, floor_roughness));
  engine::Entity camera{};
  for (std::size_t n = 0; n < live.assets.nodes.size(); ++n)
    if (live.assets.nodes[n].camera == 0) camera = live.node_entities[n];
  if (camera.is_null())
    return request ? request_error(*request, "the scene has no camera 0")
                   : engine::Error{.message = "the scene has no camera 0"};
  const BakeInput input = bake_input_from(live);
  auto layout = build_atlas_layout(atlas_inputs_from(input), {.texels_per_metre = static_cast<float>(density)});
  if (!layout) return layout.error();
  auto prepared = prepare_static_scene(input, *layout, BakeLights::Static, placement);
  if (!prepared) return prepared.error();
  GlossyTexels g{
      std::move(prepared).value(), glm::vec3(live.registry.get<engine::WorldTransform>(camera).matrix[3]), {}, {}};
  const AtlasTexels& tex = g.s.texels;
  g.glossy.assign(tex.valid.size(), 0);
  g.brdf.resize(tex.valid.size());
  std::vector<std::uint8_t> glossy_material(tex.valid.size(), 0);
  for (std::size_t t = 0; t < tex.valid.size(); ++t) {
    if (!tex.valid[t] || tex.mesh[t] < 0) continue;
    const std::uint32_t inst = g.s.static_instance[static_cast<std::size_t>(tex.mesh[t])];
    const ShadingTriangle& tri =
        g.s.index.triangles[g.s.index.instance_first[inst] + static_cast<std::uint32_t>(tex.triangle[t])];
    // Textured: the material's mean over the texel's footprint (material_lookup.h).
    const engine::GltfBrdf brdf = [&] {
      if (!g.s.scene.materials[tri.material].textured()) return g.s.scene.materials[tri.material].brdf;
      const TexelFootprint f = texel_footprint(*layout, tex.mesh[t], tex.triangle[t], t);
      return footprint_brdf(g.s.scene, tri, f.centre, f.axis_u, f.axis_v);
    }();
    if (!(static_cast<double>(std::sqrt(brdf.alpha)) < roughness)) continue;
    glossy_material[t] = 1;
    g.brdf[t] = brdf;
  }
  if (view == GlossyView::Above) {
    glm::dvec3 centre(0.0), normal(0.0);
    double count = 0.0;
    for (std::size_t t = 0; t < tex.valid.size(); ++t) {
      if (!glossy_material[t]) continue;
      centre += glm::dvec3(tex.position[t]);
      normal += glm::dvec3(tex.normal[t]);
      count += 1.0;
    }
    if (count > 0.0 && glm::length(normal) > 0.0) g.eye = glm::vec3(centre / count + 1.7 * glm::normalize(normal));
  }
  for (std::size_t t = 0; t < tex.valid.size(); ++t)
    g.glossy[t] = glossy_material[t] && glm::dot(tex.normal[t], g.eye - tex.position[t]) > 0.0f ? 1 : 0;
  return g;
}

engine::Result<RgbField> glossy_specular_truth(const ReferenceJob& job, LobeRadiance what) {
  const ReferenceRequest& r = job.request;
  const TexelPlacement placement =
      r.param("placement") == "visible_surface" ? TexelPlacement::VisibleSurface : TexelPlacement::Raster;
  auto g = glossy_texels(job.scene, std::stod(r.param("texels_per_m")), std::stod(r.param("floor_roughness")), &r,
                         placement, r.param("view") == "above" ? GlossyView::Above : GlossyView::Camera0);
  if (!g) return g.error();
  const int spp = std::stoi(r.param("spp"));
  const AtlasTexels& tex = g->s.texels;
  // The tracer indexes the scene's triangles by the caster's instance ids: the static
  // world's caster numbers only its static instances (snapshot_id_caster, static_scene.h).
  const std::unique_ptr<RayCaster> caster = snapshot_id_caster(g->s);
  PathTracer pt(g->s.scene, g->s.index, *caster, {});
  std::vector<glm::vec3> out(tex.valid.size(), glm::vec3(0.0f)), variance(tex.valid.size(), glm::vec3(0.0f));
  ThreadPool pool(job.threads);
  const bool done = pool.parallel_for_with_progress(tex.valid.size(), job.progress, [&](std::size_t t) {
    if (!g->glossy[t]) return;
    const glm::vec3 p = tex.position[t], n = tex.normal[t], v = glm::normalize(g->eye - p);
    const ReferenceBrdf f{.normal = n, .material = g->brdf[t]};
    Pcg32 rng = Pcg32::for_item(kReferenceSeed, t);
    glm::dvec3 sum(0.0), sum2(0.0);
    for (int j = 0; j < spp; ++j) {
      const float ul = rng.next_float(), u1 = rng.next_float(), u2 = rng.next_float();
      BrdfSample s;
      if (!f.sample(v, ul, u1, u2, s) || !(s.pdf > 0.0f)) continue;
      const glm::vec3 spec = engine::gltf_eval_cos(g->brdf[t], n, v, s.wi).specular / s.pdf;
      if (spec == glm::vec3(0.0f)) continue;
      const Ray ray{offset_ray_origin(p, n), 0.0f, s.wi};
      const glm::dvec3 x(spec * (what == LobeRadiance::Full ? pt.radiance(ray, rng) : pt.reflected_radiance(ray, rng)));
      sum += x, sum2 += x * x;
    }
    const glm::dvec3 mean = sum / static_cast<double>(spp);
    out[t] = glm::vec3(mean);
    // The sampling variance of the mean, so that compare_rgb removes the reference's noise.
    variance[t] = glm::vec3(glm::max(sum2 / static_cast<double>(spp) - mean * mean, glm::dvec3(0.0)) /
                            static_cast<double>(std::max(spp - 1, 1)));
  });
  if (!done) return engine::cancelled_error("glossy specular reference");
  return RgbField::from_texels(tex.width, tex.height, out, g->glossy, variance);
}

}  // namespace gi
