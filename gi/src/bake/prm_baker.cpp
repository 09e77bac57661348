// The PRM's baker (bake/method_bakers.h): bake or merge the shards, log, save.
#include <chrono>
#include <string>

#include "bake/bake_options.h"
#include "bake/bake_sharding.h"
#include "bake/bake_stage.h"
#include "bake/method_bakers.h"
#include "prm/prm.h"
#include "prm/prm_io.h"

namespace gi {

engine::Status bake_prm_method(const MethodBake& job) {
  const BakeInput& input = job.input;
  const BakeOptions& o = job.options;
  const BakeStage stage{job.host, std::string(effect_name(EffectMethod::Prm))};
  const MergedParts* merged = job.merged;
  auto settings = prm_settings(o, stage);
  if (!settings) return settings.error();
  stage.log(format_line("PRM of %s, preset %s: %d entry points, %d clusters, splitting %g, %g texels/m (panes at %g)",
                        scene_file_name(input).c_str(), o.preset.c_str(), settings->entry_points, settings->clusters,
                        double{settings->splitting}, double{settings->texels_per_metre},
                        double{pane_density(*settings)}));
  auto prm = merged ? merge_prm(input, *settings, merged->prm) : bake_prm(input, *settings);
  if (!prm) return prm.error();
  const PrmStats& st = prm->stats;
  stage.log(format_line(
      "  panes %dx%d, %zu texels each, %d clusters; %zu blocks of %d^2 texels kept (threshold %g): %.1f MB as "
      "half floats (dense %.1f MB); %zu paths, %zu virtual lights",
      prm->width, prm->height, prm->pane_size(), prm->cluster_count, prm->panes.blocks.size(),
      prm->panes.blocks_settings.tile_texels, double{prm->panes.blocks_settings.threshold},
      static_cast<double>(prm->panes.stored_elements()) * 6.0 / 1e6,
      static_cast<double>(prm->pane_size()) * prm->cluster_count * 6.0 / 1e6, st.paths, st.path_nodes));
  stage.log(format_line("  time: walks %.2f s, panes %.2f s; total %.2f s; %.1f M rays", st.walk_seconds,
                        st.pane_seconds, st.total_seconds, static_cast<double>(st.rays) * 1e-6));
  job.timings = {
      {"walk_seconds", st.walk_seconds}, {"pane_seconds", st.pane_seconds}, {"total_seconds", st.total_seconds}};
  return save_prm(job.dir, *prm, input);
}

}  // namespace gi
