// The light atlas's baker (bake/method_bakers.h): bake or merge the shards, log, save.
#include <chrono>
#include <string>

#include "bake/bake_options.h"
#include "bake/bake_sharding.h"
#include "bake/bake_stage.h"
#include "bake/method_bakers.h"
#include "light_atlas/light_atlas.h"
#include "light_atlas/light_atlas_io.h"

namespace gi {

engine::Status bake_light_atlas_method(const MethodBake& job) {
  const BakeInput& input = job.input;
  const BakeOptions& o = job.options;
  const BakeStage stage{job.host, std::string(effect_name(EffectMethod::LightAtlas))};
  const MergedParts* merged = job.merged;
  auto settings = atlas_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(format_line("light atlas of %s, preset %s: %d VPLs x %d samples, %d bounces, %g texels/m",
                        scene_file_name(input).c_str(), o.preset.c_str(), settings->vpl_count,
                        settings->samples_per_vpl, settings->bounces, double{settings->texels_per_metre}));
  auto bake = merged ? merge_light_atlas(input, *settings, merged->atlas) : bake_light_atlas(input, *settings);
  if (!bake) return bake.error();
  const LightAtlasStats& st = bake->stats;
  stage.log(format_line(
      "  atlas %dx%d at %g texels/m, %zu texels lit; %zu VPLs, %zu sample points, %zu light points, %zu shots",
      bake->width, bake->height, double{bake->layout.texels_per_metre}, st.valid_texels, st.vpls, st.sample_points,
      st.light_points, st.shots));
  stage.log(format_line(
      "  time: VPLs %.2f s, direct %.2f s, propagation %.2f s, final shooting %.2f s; total %.2f s; %.1f M rays",
      st.vpl_seconds, st.direct_seconds, st.propagate_seconds, st.final_seconds, st.total_seconds,
      static_cast<double>(st.rays) * 1e-6));
  job.timings = {{"vpl_seconds", st.vpl_seconds},
                 {"direct_seconds", st.direct_seconds},
                 {"propagate_seconds", st.propagate_seconds},
                 {"final_seconds", st.final_seconds},
                 {"total_seconds", st.total_seconds}};
  return save_light_atlas(job.dir, *bake, input);
}

}  // namespace gi
