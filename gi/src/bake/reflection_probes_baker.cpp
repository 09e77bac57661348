// The reflection probes' baker (bake/method_bakers.h): read the light atlas the bundle
// holds (its baker ran first), place, capture and prefilter the probes, log, save.
#include <string>

#include "bake/bake_stage.h"
#include "bake/method_bakers.h"
#include "light_atlas/light_atlas_io.h"
#include "reflection_probes/reflection_probes.h"
#include "reflection_probes/reflection_probes_io.h"

namespace gi {

engine::Status bake_reflection_probes_method(const MethodBake& job) {
  const BakeInput& input = job.input;
  const BakeStage stage{job.host, std::string(effect_name(EffectMethod::ReflectionProbes))};
  auto settings = reflection_probe_preset(job.options.preset);
  if (!settings) return settings.error();
  settings->threads = job.options.threads;
  settings->seed = job.options.seed;
  auto atlas = load_light_atlas(job.dir, input);
  if (!atlas) {
    engine::Error e = atlas.error();
    e.message =
        "reflection probes read the static surfaces' light from the light atlas (bake light_atlas too): " + e.message;
    return e;
  }
  const ProbeAtlas source{&atlas->layout, atlas->width, atlas->height, atlas->irradiance,
                          atlas->settings.include_direct};
  stage.log(format_line("reflection probes of %s, preset %s: %dx%d faces, cells of %g m",
                        scene_file_name(input).c_str(), job.options.preset.c_str(), settings->resolution,
                        settings->resolution, double{settings->placement.cell_m}));
  auto probes = bake_reflection_probes(input, source, *settings);
  if (!probes) return probes.error();
  const ReflectionProbeStats& st = probes->stats;
  stage.log(
      format_line("  %zu probes; time: placement %.2f s, capture %.2f s, prefilter %.2f s; total %.2f s; %.1f M rays",
                  probes->probes.size(), st.place_seconds, st.capture_seconds, st.prefilter_seconds, st.total_seconds,
                  static_cast<double>(st.rays) * 1e-6));
  job.timings = {{"place_seconds", st.place_seconds},
                 {"capture_seconds", st.capture_seconds},
                 {"prefilter_seconds", st.prefilter_seconds},
                 {"total_seconds", st.total_seconds}};
  return save_reflection_probes(job.dir, *probes, input);
}

}  // namespace gi
