#include "sweep/dlm_sweep.h"

#include <gi/methods.h>

#include "raytrace/material_lookup.h"

#include <engine/directional_radiance.h>
#include <engine/scene.h>
#include <gi/error_metrics.h>

#include <cmath>
#include <string>

#include "core/random.h"
#include "core/thread_pool.h"
#include "dlm/dlm.h"
#include "raytrace/path_tracer.h"
#include "raytrace/ray_offset.h"
#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace gi {
namespace {

// Other random streams than any bake's (see reference_sweep.cpp).
constexpr std::uint64_t kReferenceSeed = 0x646c6d7265666572ULL;

engine::Error request_error(const ReferenceRequest& r, const std::string& message) {
  return engine::Error{"<sweep>", r.key(), message};
}

// The static scene at the layout of `density`, the camera 0 position, and per texel whether
// its triangle is glossy (roughness below `roughness`, the bake's rule) and its BRDF.
struct GlossyTexels {
  StaticBakeScene s;
  glm::vec3 eye{0.0f};
  std::vector<std::uint8_t> glossy;  // per atlas texel: glossy and facing the camera
  std::vector<engine::GltfBrdf> brdf;
};

engine::Result<GlossyTexels> glossy_texels(const SweepScene& scene, double density, double roughness,
                                           const ReferenceRequest* request) {
  const engine::Scene live = engine::instantiate(scene.asset);
  engine::Entity camera{};
  for (std::size_t n = 0; n < live.assets.nodes.size(); ++n)
    if (live.assets.nodes[n].camera == 0) camera = live.node_entities[n];
  if (camera.is_null())
    return request ? request_error(*request, "the scene has no camera 0")
                   : engine::Error{.message = "the scene has no camera 0"};
  const BakeInput input = bake_input_from(live);
  auto layout = build_atlas_layout(atlas_inputs_from(input), {.texels_per_metre = static_cast<float>(density)});
  if (!layout) return layout.error();
  auto prepared = prepare_static_scene(input, *layout, BakeLights::Static);
  if (!prepared) return prepared.error();
  GlossyTexels g{
      std::move(prepared).value(), glm::vec3(live.registry.get<engine::WorldTransform>(camera).matrix[3]), {}, {}};
  const AtlasTexels& tex = g.s.texels;
  g.glossy.assign(tex.valid.size(), 0);
  g.brdf.resize(tex.valid.size());
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
    if (!(glm::dot(tex.normal[t], g.eye - tex.position[t]) > 0.0f)) continue;
    g.glossy[t] = 1;
    g.brdf[t] = brdf;
  }
  return g;
}

engine::Result<RgbField> glossy_specular_reference(const ReferenceJob& job) {
  const ReferenceRequest& r = job.request;
  auto g = glossy_texels(job.scene, std::stod(r.param("texels_per_m")), std::stod(r.param("roughness")), &r);
  if (!g) return g.error();
  const int spp = std::stoi(r.param("spp"));
  const AtlasTexels& tex = g->s.texels;
  PathTracer pt(g->s.scene, g->s.index, *g->s.caster, {});
  std::vector<glm::vec3> out(tex.valid.size(), glm::vec3(0.0f));
  ThreadPool pool(job.threads);
  const bool done = pool.parallel_for_with_progress(tex.valid.size(), job.progress, [&](std::size_t t) {
    if (!g->glossy[t]) return;
    const glm::vec3 p = tex.position[t], n = tex.normal[t], v = glm::normalize(g->eye - p);
    const ReferenceBrdf f{.normal = n, .material = g->brdf[t]};
    Pcg32 rng = Pcg32::for_item(kReferenceSeed, t);
    glm::dvec3 sum(0.0);
    for (int j = 0; j < spp; ++j) {
      const float ul = rng.next_float(), u1 = rng.next_float(), u2 = rng.next_float();
      BrdfSample s;
      if (!f.sample(v, ul, u1, u2, s) || !(s.pdf > 0.0f)) continue;
      const glm::vec3 spec = engine::gltf_eval_cos(g->brdf[t], n, v, s.wi).specular / s.pdf;
      if (spec == glm::vec3(0.0f)) continue;
      sum += glm::dvec3(spec * pt.reflected_radiance(Ray{offset_ray_origin(p, n), 0.0f, s.wi}, rng));
    }
    out[t] = glm::vec3(sum / static_cast<double>(spp));
  });
  if (!done) return engine::cancelled_error("glossy specular reference");
  return RgbField::from_texels(tex.width, tex.height, out, g->glossy);
}

std::vector<KnobSpec> dlm_knobs() {
  return {
      {.name = "directions",
       .description = "directions in the global set Omega",
       .kind = KnobKind::Integer,
       .default_grid = {"16", "32", "64"},
       .min_value = 8,
       .max_value = 256},
      {.name = "kphotons",
       .description = "photon paths from the static lights, thousands",
       .kind = KnobKind::Integer,
       .default_grid = {"250", "1000", "4000"},
       .min_value = 1,
       .max_value = 4'000'000},
      {.name = "density",
       .description = "atlas texels per metre",
       .kind = KnobKind::Real,
       .default_grid = {"8"},
       .min_value = 0.01,
       .max_value = 1e4},
      {.name = "splat",
       .description = "tent kernel radius, texels",
       .kind = KnobKind::Real,
       .default_grid = {"2"},
       .min_value = 0.5,
       .max_value = 16},
      {.name = "ref_spp",
       .description = "specular-lobe samples per texel of the path-traced reference",
       .kind = KnobKind::Integer,
       .default_grid = {"1024"},
       .min_value = 1,
       .max_value = 1 << 20},
  };
}

ReferenceRequest dlm_reference_request(const SweepScene&, const KnobSetting& k) {
  ReferenceRequest r;
  r.kind = "atlas_glossy_specular";
  char density[32];
  std::snprintf(density, sizeof density, "%g", k.real("density"));
  r.params = {
      {"texels_per_m", density}, {"spp", std::to_string(k.integer("ref_spp"))}, {"roughness", "0.35"}, {"camera", "0"}};
  return r;
}

engine::Result<MethodOutput> run_dlm(const RunContext& ctx) {
  DlmSettings s;
  s.directions = static_cast<int>(ctx.knobs.integer("directions"));
  s.photons = static_cast<std::uint64_t>(ctx.knobs.integer("kphotons")) * 1000u;
  s.texels_per_metre = static_cast<float>(ctx.knobs.real("density"));
  s.splat_radius_texels = static_cast<float>(ctx.knobs.real("splat"));
  s.glossy_roughness = 0.35f;
  s.seed = ctx.seed;
  s.threads = ctx.threads;
  s.progress = ctx.progress;
  const engine::Scene scene = engine::instantiate(ctx.scene.asset);
  auto dlm = bake_dlm(bake_input_from(scene), s);
  if (!dlm) return dlm.error();
  if (dlm->width != ctx.reference.width || dlm->height != ctx.reference.height)
    return engine::Error{.message = "the maps' atlas size differs from the reference's"};
  auto g = glossy_texels(ctx.scene, ctx.knobs.real("density"), 0.35, nullptr);
  if (!g) return g.error();
  // The renderer's evaluation (engine::directional_specular) at every stored glossy texel.
  const AtlasTexels& tex = g->s.texels;
  std::vector<glm::vec3> values(tex.valid.size(), glm::vec3(0.0f));
  // The direction-less alternative on the same texels: the maps' own irradiance
  // E = sum_k L_k C_k reflected as E / pi x the specular albedo (what the renderer draws
  // without DLM from a perfect atlas): the "atlas_rel_rmse" extra.
  std::vector<glm::vec3> atlas_values(tex.valid.size(), glm::vec3(0.0f));
  std::vector<std::uint8_t> mask(tex.valid.size(), 0);
  std::vector<glm::vec3> l(dlm->directions.size());
  for (std::size_t i = 0; i < dlm->texels.size(); ++i) {
    const std::uint32_t t = dlm->texels[i];
    if (!g->glossy[t]) continue;
    for (std::size_t k = 0; k < l.size(); ++k) {
      const float* v = &dlm->radiance[(k * dlm->texels.size() + i) * 3];
      l[k] = glm::vec3(v[0], v[1], v[2]);
    }
    const glm::vec3 v = glm::normalize(g->eye - tex.position[t]);
    values[t] = engine::directional_specular(g->brdf[t], tex.normal[t], v, dlm->directions, l);
    const std::vector<float> c = dlm_bin_cosine_weights(dlm->directions, tex.normal[t]);
    glm::vec3 e(0.0f);
    for (std::size_t k = 0; k < l.size(); ++k) e += c[k] * l[k];
    atlas_values[t] =
        e / 3.14159265f * engine::gltf_directional_albedo(g->brdf[t], glm::dot(tex.normal[t], v)).specular;
    mask[t] = 1;
  }
  MethodOutput out;
  const RgbField atlas_field = RgbField::from_texels(tex.width, tex.height, atlas_values, mask);
  out.field = RgbField::from_texels(tex.width, tex.height, values, std::move(mask));
  out.costs.bake_seconds = dlm->stats.total_seconds;
  // What the runtime uploads: texels x directions x 8 B + the R32I index map.
  out.costs.bytes = static_cast<std::uint64_t>(dlm->texels.size()) * dlm->directions.size() * 8u +
                    static_cast<std::uint64_t>(dlm->width) * static_cast<std::uint64_t>(dlm->height) * 4u;
  out.extras = {{"atlas_rel_rmse", relative_rmse(atlas_field, ctx.reference)},
                {"glossy_texels", static_cast<double>(dlm->stats.glossy_texels)},
                {"deposits", static_cast<double>(dlm->stats.deposits)}};
  return out;
}

}  // namespace

void register_dlm_sweep(SweepRegistry& registry) {
  registry.add_reference_provider(
      {.kind = "atlas_glossy_specular", .version = "pt-1", .compute = glossy_specular_reference});

  SweepMethod m;
  m.name = method_descriptor(EffectMethod::DirectionalLightMaps).key;  // gi/methods.h
  m.description =
      "directional light maps (Hey 2002): directions x photons x density vs the path-traced specular indirect "
      "radiance of the glossy texels towards camera 0";
  m.knobs = dlm_knobs();
  m.reference_for = dlm_reference_request;
  m.run = run_dlm;
  registry.add_method(std::move(m));
}

}  // namespace gi
