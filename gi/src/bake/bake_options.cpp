#include "bake/bake_options.h"

#include <cstdint>

#include "io/content_hash.h"

namespace gi {

engine::Result<LightAtlasSettings> atlas_settings(const BakeOptions& o, const BakeStage& stage) {
  auto settings = light_atlas_preset(o.preset);
  if (!settings) return settings.error();
  if (o.vpls > 0) settings->vpl_count = o.vpls;
  if (o.bounces > 0) settings->bounces = o.bounces;
  if (o.texels_per_metre > 0.0f) settings->texels_per_metre = o.texels_per_metre;
  if (o.samples_per_vpl > 0) settings->samples_per_vpl = o.samples_per_vpl;
  settings->include_direct = o.include_direct;
  settings->threads = o.threads;
  settings->seed = o.seed;
  settings->progress = stage.progress();
  return settings;
}

engine::Result<PrmSettings> prm_settings(const BakeOptions& o, const BakeStage& stage) {
  auto settings = prm_preset(o.preset);
  if (!settings) return settings.error();
  if (o.texels_per_metre > 0.0f) set_prm_atlas_density(*settings, o.texels_per_metre);
  settings->threads = o.threads;
  settings->seed = o.seed;
  settings->progress = stage.progress();
  return settings;
}

engine::Result<DlmSettings> dlm_settings(const BakeOptions& o, const BakeStage& stage) {
  auto settings = dlm_preset(o.preset);
  if (!settings) return settings.error();
  if (o.texels_per_metre > 0.0f) settings->texels_per_metre = o.texels_per_metre;
  if (o.dlm_directions > 0) settings->directions = o.dlm_directions;
  if (o.dlm_photons > 0) settings->photons = o.dlm_photons;
  if (!o.dlm_bins.empty() && o.dlm_bins != "tangent" && o.dlm_bins != "global")
    return engine::invalid_request("DLM bins '" + o.dlm_bins + "' (tangent or global)");
  if (!o.dlm_bins.empty()) settings->tangent_frame_bins = o.dlm_bins == "tangent";
  settings->threads = o.threads;
  settings->seed = o.seed;
  settings->progress = stage.progress();
  return settings;
}

engine::Result<BrfSettings> brf_settings(const BakeOptions& o) {
  auto settings = brf_preset(o.preset);
  if (!settings) return settings.error();
  if (o.brf_basis > 0) settings->basis.basis = o.brf_basis;
  if (o.brf_spheres > 0) settings->field.spheres = o.brf_spheres;
  settings->field.threads = o.threads;
  return settings;
}

AntiradianceSettings antiradiance_settings(const BakeOptions& o) {
  AntiradianceSettings s = antiradiance_preset(o.preset);
  s.seed = o.seed;
  return s;
}

std::string bake_settings_hash(const BakeOptions& o) {
  ContentHash h;
  h.add_string("gi-bake settings v1");
  h.add_string(o.preset);
  h.add_value(static_cast<std::uint64_t>(o.methods.size()));
  for (const std::string& m : o.methods) h.add_string(m);
  h.add_value(o.texels_per_metre);
  h.add_value(o.vpls);
  h.add_value(o.bounces);
  h.add_value(o.samples_per_vpl);
  h.add_value(o.brf_basis);
  h.add_value(o.brf_spheres);
  h.add_value(o.dlm_directions);
  h.add_value(o.dlm_photons);
  h.add_string(o.dlm_bins);
  h.add_value(static_cast<std::uint8_t>(o.include_direct ? 1 : 0));
  h.add_value(static_cast<std::uint64_t>(o.moving_lights.size()));
  for (const std::string& l : o.moving_lights) h.add_string(l);
  h.add_value(o.seed);
  return h.hex();
}

}  // namespace gi
