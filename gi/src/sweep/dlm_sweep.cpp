#include "sweep/dlm_sweep.h"

#include "sweep/glossy_texels.h"

#include <gi/methods.h>

#include "raytrace/material_lookup.h"

#include <engine/directional_radiance.h>
#include <engine/scene.h>
#include <gi/error_metrics.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "dlm/dlm.h"
#include "transport/static_scene.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"

namespace gi {
namespace {

engine::Result<RgbField> glossy_specular_reference(const ReferenceJob& job) {
  return glossy_specular_truth(job, LobeRadiance::Reflected);
}

// Long because it is one table, one entry per knob with its grid and range, read as a list.
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
      {.name = "roughness",
       .description = "roughness of the glossy materials (those below 0.35 in the scene: glossy_room's floor)",
       .kind = KnobKind::Real,
       .default_grid = {"0.15"},
       .min_value = 0.05,
       .max_value = 0.9},
      {.name = "placement",
       .description = "where the texels are measured: raster (the default, its references' keys unchanged) or "
                      "visible_surface (off the lines where walls begin, as the reflection probes are measured)",
       .kind = KnobKind::Choice,
       .default_grid = {"raster"},
       .choices = {"raster", "visible_surface"}},
      {.name = "bins",
       .description = "global (one set of directions, the renderer's) or tangent (per texel about its normal, "
                      "the renderer reads both: docs/dlm.md, 'Tangent-frame bins in the renderer')",
       .kind = KnobKind::Choice,
       .default_grid = {"global"},
       .choices = {"global", "tangent"}},
      {.name = "warp",
       .description = "tangent-frame bins: their z raised to this power (1: equal areas, the preset; 2: cells near "
                      "the horizon about half as tall)",
       .kind = KnobKind::Real,
       .default_grid = {"1"},
       .min_value = 1,
       .max_value = 4},
      {.name = "surfaces",
       .description = "which glossy texels are compared: all (the default) or floors (normal within 26 degrees of +y: "
                      "the demo level's corridor floor without the crate room's cut-out grille)",
       .kind = KnobKind::Choice,
       .default_grid = {"all"},
       .choices = {"all", "floors"}},
      {.name = "view",
       .description = "where the eye is: camera0 (the default, its references' keys unchanged) or above (1.7 m above "
                      "the glossy texels' centroid: the view bands camera 0 does not see, e.g. the demo corridor's)",
       .kind = KnobKind::Choice,
       .default_grid = {"camera0"},
       .choices = {"camera0", "above"}},
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
  char roughness[32];
  std::snprintf(roughness, sizeof roughness, "%g", k.real("roughness"));
  r.params = {{"texels_per_m", density},
              {"spp", std::to_string(k.integer("ref_spp"))},
              {"floor_roughness", roughness},
              {"camera", "0"}};
  if (k.text("placement") == "visible_surface") r.params.emplace_back("placement", "visible_surface");
  if (k.text("view") == "above") r.params.emplace_back("view", "above");
  return r;
}

// Mean bias per band of cos(theta_v) (view angle to the texel's normal) of `values`: sum of the
// values / sum of the reference's - 1 over the band's glossy texels (the reference's noise
// averages out in the sums), as extras "<prefix>bias_cos<lo>_<hi>".
void add_view_band_bias(const GlossyTexels& g, const std::vector<std::uint8_t>& mask,
                        const std::vector<glm::vec3>& values, const char* prefix, const RgbField& reference,
                        std::vector<std::pair<std::string, double>>& extras) {
  constexpr double kBands[] = {0.1, 0.3, 0.6, 1.01};
  for (int b = 0; b < 3; ++b) {
    double sd = 0.0, sr = 0.0;
    for (std::size_t t = 0; t < values.size(); ++t) {
      if (!g.glossy[t] || !mask[t] || !reference.is_valid(t)) continue;
      const glm::vec3 v = glm::normalize(g.eye - g.s.texels.position[t]);
      const double c = static_cast<double>(glm::dot(g.s.texels.normal[t], v));
      if (c < kBands[b] || c >= kBands[b + 1]) continue;
      sd += static_cast<double>(values[t].x + values[t].y + values[t].z);
      sr += static_cast<double>(reference.rgb[3 * t] + reference.rgb[3 * t + 1] + reference.rgb[3 * t + 2]);
    }
    char name[64];
    std::snprintf(name, sizeof name, "%sbias_cos%.1f_%.1f", prefix, kBands[b], std::min(kBands[b + 1], 1.0));
    extras.emplace_back(name, sr > 0.0 ? sd / sr - 1.0 : std::nan(""));
  }
}

// The bake's settings from the run's knobs.
DlmSettings dlm_settings(const RunContext& ctx, double floor_roughness) {
  DlmSettings s;
  s.directions = static_cast<int>(ctx.knobs.integer("directions"));
  s.photons = static_cast<std::uint64_t>(ctx.knobs.integer("kphotons")) * 1000u;
  s.texels_per_metre = static_cast<float>(ctx.knobs.real("density"));
  s.splat_radius_texels = static_cast<float>(ctx.knobs.real("splat"));
  s.glossy_roughness = static_cast<float>(glossy_threshold(floor_roughness));
  s.tangent_frame_bins = ctx.knobs.text("bins") == "tangent";
  s.horizon_warp = ctx.knobs.real("warp");
  s.seed = ctx.seed;
  s.threads = ctx.threads;
  s.progress = ctx.progress;
  return s;
}

// The renderer's evaluation (engine::directional_specular) at every stored glossy texel of
// `g` (only the floors' with `floors_only`), and the direction-less alternative on the same
// texels: the maps' own irradiance E = sum_k L_k C_k reflected as E / pi x the specular albedo
// (what the renderer draws without DLM from a perfect atlas): the "atlas_rel_rmse" extra.
// The same bins are also read with more lobe samples (kLookupVariants; 4096 integrate the lobe
// over the cells almost exactly): the lookup's quadrature error apart from the bins' (docs/dlm.md,
// "The grazing band's bias, split and removed"); and with a smooth kernel across the cells' edges
// (15, 20 or 25 degrees; the 64 tangent-frame cells are about 18 degrees apart).
struct LookupVariant {
  const char* name;
  int samples;
  float kernel_radius;  ///< radians; 0: the nearest bin
};
constexpr LookupVariant kLookupVariants[] = {
    {"lookup32_", 32, 0.0f},         {"lookup64_", 64, 0.0f},         {"lookup4096_", 4096, 0.0f},
    {"smooth15x16_", 16, 0.26f},     {"smooth15x4096_", 4096, 0.26f}, {"smooth20x16_", 16, 0.35f},
    {"smooth20x4096_", 4096, 0.35f}, {"smooth25x16_", 16, 0.44f},
};
constexpr std::size_t kExactLookup = 2;  ///< lookup4096_
struct EvaluatedMaps {
  std::vector<glm::vec3> values, atlas_values;
  std::vector<std::vector<glm::vec3>> lookup_values;  ///< per kLookupVariants
  std::vector<std::uint8_t> mask;
};
EvaluatedMaps evaluate_maps(const Dlm& dlm, const GlossyTexels& g, bool floors_only) {
  const AtlasTexels& tex = g.s.texels;
  EvaluatedMaps out{.values = std::vector<glm::vec3>(tex.valid.size(), glm::vec3(0.0f)),
                    .atlas_values = std::vector<glm::vec3>(tex.valid.size(), glm::vec3(0.0f)),
                    .lookup_values = std::vector<std::vector<glm::vec3>>(
                        std::size(kLookupVariants), std::vector<glm::vec3>(tex.valid.size(), glm::vec3(0.0f))),
                    .mask = std::vector<std::uint8_t>(tex.valid.size(), 0)};
  std::vector<glm::vec3> l(dlm.directions.size());
  // Tangent-frame bins: the same C_k at every normal (as the bake computes them).
  const std::vector<float> tangent_weights =
      dlm.settings.tangent_frame_bins
          ? dlm_bin_cosine_weights(dlm.directions, glm::vec3(0.0f, 0.0f, 1.0f), kDlmTangentQuadrature)
          : std::vector<float>{};
  for (std::size_t i = 0; i < dlm.texels.size(); ++i) {
    const std::uint32_t t = dlm.texels[i];
    if (!g.glossy[t]) continue;
    if (floors_only && !(tex.normal[t].y > 0.9f)) continue;
    for (std::size_t k = 0; k < l.size(); ++k) {
      const float* v = &dlm.radiance[(k * dlm.texels.size() + i) * 3];
      l[k] = glm::vec3(v[0], v[1], v[2]);
    }
    const glm::vec3 v = glm::normalize(g.eye - tex.position[t]);
    // As the renderer reads them: tangent-frame bins in the frame of the texel's normal.
    const glm::vec3* bin_normal = dlm.settings.tangent_frame_bins ? &tex.normal[t] : nullptr;
    out.values[t] = engine::directional_specular(g.brdf[t], tex.normal[t], v, dlm.directions, l, bin_normal);
    for (std::size_t j = 0; j < std::size(kLookupVariants); ++j)
      out.lookup_values[j][t] =
          engine::directional_specular_sampled(g.brdf[t], tex.normal[t], v, dlm.directions, l, bin_normal,
                                               kLookupVariants[j].samples, kLookupVariants[j].kernel_radius);
    const std::vector<float> c =
        dlm.settings.tangent_frame_bins ? tangent_weights : dlm_bin_cosine_weights(dlm.directions, tex.normal[t]);
    glm::vec3 e(0.0f);
    for (std::size_t k = 0; k < l.size(); ++k) e += c[k] * l[k];
    out.atlas_values[t] =
        e / 3.14159265f * engine::gltf_directional_albedo(g.brdf[t], glm::dot(tex.normal[t], v)).specular;
    out.mask[t] = 1;
  }
  return out;
}

// The lookup variants' truth rel RMSE and band bias: extras "<variant name>truth_rel_rmse", ...
void add_lookup_extras(const GlossyTexels& g, const std::vector<std::uint8_t>& mask,
                       const std::vector<glm::vec3>& renderer_values,
                       const std::vector<std::vector<glm::vec3>>& lookup_values, const RgbField& reference,
                       std::vector<std::pair<std::string, double>>& extras) {
  const AtlasTexels& tex = g.s.texels;
  // The lookup's own quadrature error: each reading against the lobe integrated over the cells (4096 samples).
  const RgbField exact = RgbField::from_texels(tex.width, tex.height, lookup_values[kExactLookup], mask);
  extras.emplace_back("lookup16_vs_exact_rel_rmse",
                      relative_rmse(RgbField::from_texels(tex.width, tex.height, renderer_values, mask), exact));
  for (std::size_t j = 0; j < lookup_values.size(); ++j) {
    const std::string prefix = kLookupVariants[j].name;
    const RgbField field = RgbField::from_texels(tex.width, tex.height, lookup_values[j], mask);
    extras.emplace_back(prefix + "truth_rel_rmse", compare_rgb(field, reference).truth_rel_rmse);
    extras.emplace_back(prefix + "vs_exact_rel_rmse", relative_rmse(field, exact));
    add_view_band_bias(g, mask, lookup_values[j], prefix.c_str(), reference, extras);
  }
}

engine::Result<MethodOutput> run_dlm(const RunContext& ctx) {
  const double floor_roughness = ctx.knobs.real("roughness");
  const DlmSettings s = dlm_settings(ctx, floor_roughness);
  const engine::Scene scene = engine::instantiate(with_floor_roughness(ctx.scene.asset, floor_roughness));
  auto dlm = bake_dlm(bake_input_from(scene), s);
  if (!dlm) return dlm.error();
  if (dlm->width != ctx.reference.width || dlm->height != ctx.reference.height)
    return engine::Error{.message = "the maps' atlas size differs from the reference's"};
  const TexelPlacement placement =
      ctx.knobs.text("placement") == "visible_surface" ? TexelPlacement::VisibleSurface : TexelPlacement::Raster;
  const GlossyView view = ctx.knobs.text("view") == "above" ? GlossyView::Above : GlossyView::Camera0;
  auto g = glossy_texels(ctx.scene, ctx.knobs.real("density"), floor_roughness, nullptr, placement, view);
  if (!g) return g.error();
  const AtlasTexels& tex = g->s.texels;
  auto [values, atlas_values, lookup_values, mask] = evaluate_maps(*dlm, *g, ctx.knobs.text("surfaces") == "floors");
  const std::vector<std::uint8_t> band_mask = mask;
  MethodOutput out;
  const RgbField atlas_field = RgbField::from_texels(tex.width, tex.height, atlas_values, mask);
  out.field = RgbField::from_texels(tex.width, tex.height, values, std::move(mask));
  out.costs.bake_seconds = dlm->stats.total_seconds;
  // What the runtime uploads: texels x directions x 8 B + the R32I index map.
  out.costs.bytes = static_cast<std::uint64_t>(dlm->texels.size()) * dlm->directions.size() * 8u +
                    static_cast<std::uint64_t>(dlm->width) * static_cast<std::uint64_t>(dlm->height) * 4u;
  out.extras = {{"atlas_rel_rmse", relative_rmse(atlas_field, ctx.reference)},
                {"atlas_truth_rel_rmse", compare_rgb(atlas_field, ctx.reference).truth_rel_rmse},
                {"glossy_texels", static_cast<double>(dlm->stats.glossy_texels)},
                {"deposits", static_cast<double>(dlm->stats.deposits)}};
  add_view_band_bias(*g, band_mask, values, "", ctx.reference, out.extras);
  add_view_band_bias(*g, band_mask, atlas_values, "atlas_", ctx.reference, out.extras);
  add_lookup_extras(*g, band_mask, values, lookup_values, ctx.reference, out.extras);
  return out;
}

}  // namespace

void register_dlm_sweep(SweepRegistry& registry) {
  registry.add_reference_provider(
      {.kind = "atlas_glossy_specular", .version = "pt-3", .compute = glossy_specular_reference});

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
