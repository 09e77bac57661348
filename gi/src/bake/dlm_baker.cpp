// The directional light maps' baker (bake/method_bakers.h): bake, log, save.
#include <algorithm>
#include <chrono>
#include <string>

#include "bake/bake_options.h"
#include "bake/bake_stage.h"
#include "bake/method_bakers.h"
#include "dlm/dlm.h"
#include "dlm/dlm_io.h"
#include "reflection_probes/reflection_probes.h"

namespace gi {

engine::Status bake_dlm_method(const MethodBake& job) {
  const BakeInput& input = job.input;
  const BakeOptions& o = job.options;
  const BakeStage stage{job.host, std::string(effect_name(EffectMethod::DirectionalLightMaps))};
  auto settings = dlm_settings(o, stage);
  if (!settings) return settings.error();
  // Baked beside the reflection probes, the maps leave the probes' surfaces (roughness below
  // kReflectionProbeMaxRoughness) to them: the forward pass draws the probes' specular there, so
  // maps for them would never be drawn (docs/plan.md, "Routing"). Alone, the maps cover their whole range.
  const auto& methods = job.methods;
  if (std::find(methods.begin(), methods.end(), method_descriptor(EffectMethod::ReflectionProbes).key) != methods.end())
    settings->glossy_roughness_min = std::max(settings->glossy_roughness_min, kReflectionProbeMaxRoughness);
  stage.log(format_line(
      "directional light maps of %s, preset %s: %d directions, %llu photons, splat radius %g texels, "
      "%g texels/m, roughness in [%g, %g)",
      scene_file_name(input).c_str(), o.preset.c_str(), settings->directions,
      static_cast<unsigned long long>(settings->photons), double{settings->splat_radius_texels},
      double{settings->texels_per_metre}, double{settings->glossy_roughness_min}, double{settings->glossy_roughness}));
  auto dlm = bake_dlm(input, *settings);
  if (!dlm) return dlm.error();
  const DlmStats& st = dlm->stats;
  stage.log(format_line(
      "  %zu glossy texels, %zu stored (%.2f MB as halves, %zu B per texel); %llu deposits, %.1f M rays",
      st.glossy_texels, dlm->texel_count(), static_cast<double>(dlm->radiance.size()) * 2.0 / 1e6,
      dlm->directions.size() * 6, static_cast<unsigned long long>(st.deposits), static_cast<double>(st.rays) * 1e-6));
  stage.log(format_line("  time: photons %.2f s; total %.2f s", st.trace_seconds, st.total_seconds));
  job.timings = {{"trace_seconds", st.trace_seconds}, {"total_seconds", st.total_seconds}};
  return save_dlm(job.dir, *dlm, input);
}

}  // namespace gi
