// gi-sweep: measures a GI method's error against the reference over a grid of its quality
// knobs and writes CSV, a Markdown summary with the Pareto front and presets, and plots
// (gi::run_sweep, gi/sweep.h). Exit codes: tools/common/tool_main.h (130: interrupted,
// the files hold the runs done).
//   gi-sweep --list
//   gi-sweep --method pathtracer --scene assets/cornell_box.gltf --knob spp=1,4,16 --out out/sweeps
//   gi-sweep --method light_atlas --scene sponza.gltf --untextured --sky
//   'zenith:10,16,30;horizon:28,30,34;ground:6,6,6'
//            --sun 'direction:0.25,-1,0.15;irradiance:700,650,600' --split-truth 256 --knob density=8 --out out/sponza
#include <engine/scene_asset.h>
#include <engine/sun.h>
#include <gi/sweep.h>

#include <cstdio>
#include <optional>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>

#include "console_progress.h"
#include "plot_command.h"
#include "sun_option.h"
#include "tool_main.h"

namespace {

constexpr const char* kTool = "gi-sweep";

void print_list() {
  for (const gi::SweepMethodInfo& m : gi::sweep_methods()) {
    std::printf("%s  %s\n", m.name.c_str(), m.description.c_str());
    for (const gi::SweepKnobInfo& k : m.knobs)
      std::printf("  --knob %s=%s   (%s %s) %s\n", k.name.c_str(), k.default_grid.c_str(), k.kind.c_str(),
                  k.range.c_str(), k.description.c_str());
  }
  const std::vector<std::string> providers = gi::sweep_reference_providers();
  if (providers.empty()) return;
  std::printf("reference providers:");
  for (const std::string& p : providers) std::printf(" %s", p.c_str());
  std::printf("\n");
}

// Runs the sweep with a progress bar and reports the files, the failures and the plots.
// --sky and --sun (the syntax and parsing of gi-bake's) into the request's scene edit; the
// exit code when one is malformed.
std::optional<int> scene_lighting(const std::string& sky, const std::string& sun, gi::SweepRequest& request) {
  auto quoted = [](const std::string& s) { return "'" + s + "'"; };
  engine::Environment sky_env;
  if (!sky.empty() && !tools::set_sky(sky_env, sky))
    return tools::fail(kTool, std::string(tools::kSkyUsage) + ", got '" + sky + "'", tools::kExitUsage);
  const std::optional<engine::Sun> parsed_sun = sun.empty() ? std::nullopt : tools::parse_sun(sun);
  if (!sun.empty() && !parsed_sun)
    return tools::fail(kTool, std::string(tools::kSunUsage) + ", got '" + sun + "'", tools::kExitUsage);
  if (sky.empty() && sun.empty()) return std::nullopt;
  request.edit_scene = [sky, parsed_sun](engine::SceneAsset& asset) {
    if (!sky.empty()) tools::set_sky(asset.environment, sky);  // checked above
    if (parsed_sun) engine::set_sun(asset, *parsed_sun);
  };
  request.edit_scene_args = (sky.empty() ? "" : "--sky " + quoted(sky)) + (sky.empty() || sun.empty() ? "" : " ") +
                            (sun.empty() ? "" : "--sun " + quoted(sun));
  return std::nullopt;
}

int run_and_report(const gi::SweepRequest& request, bool no_plot) {
  tools::install_interrupt_handler();
  tools::ConsoleProgress bar;
  const gi::SweepHost host{
      .progress =
          [&](const gi::SweepStatus& s) {
            char detail[64];
            std::snprintf(detail, sizeof detail, "%zu/%zu", s.units_done, s.units_total);
            return bar.update("sweep", s.fraction(), std::string(detail) + "  " + s.current);
          },
      .log =
          [&](gi::LogLevel level, std::string_view line) {
            bar.finish();
            std::fprintf(stderr, "%s: %s%.*s\n", kTool,
                         level == gi::LogLevel::Info ? "" : "warning: ", static_cast<int>(line.size()), line.data());
          }};
  auto report = gi::run_sweep(request, host);
  bar.finish();
  if (!report) return tools::fail(kTool, report.error());
  for (const std::string& f : report->failures) std::fprintf(stderr, "%s: run %s\n", kTool, f.c_str());
  std::fprintf(stderr, "%s: wrote %s and %s (%zu run(s), %zu failed; references: %zu computed, %zu from cache)\n",
               kTool, report->csv.c_str(), report->markdown.c_str(), report->runs, report->failures.size(),
               report->references_computed, report->references_from_cache);
  std::fprintf(stderr, "%s\n",
               (no_plot ? "plots: skipped; to plot, run:\n  " + gi_sweep::plot_command(report->csv, request.frame_cost)
                        : gi_sweep::plot_sweep_csv(report->csv, request.frame_cost))
                   .c_str());
  if (report->cancelled) {
    std::fprintf(stderr, "%s: interrupted; the files hold the runs completed so far\n", kTool);
    return tools::kExitCancelled;
  }
  return tools::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Measures a GI method's accuracy (vs the reference) and cost over a grid of its quality knobs"};
  gi::SweepRequest request;
  std::string scene, out_dir, cache_dir, cost = "bake", sky, sun;
  std::vector<double> presets;
  bool list = false, no_plot = false;
  app.add_option("--method", request.method, "Sweep method (see --list)");
  app.add_option("--scene", scene, "glTF/GLB scene file")->check(CLI::ExistingFile);
  app.add_option("--knob", request.knobs, "Override a knob's values: name=v1,v2,... (repeatable)");
  app.add_option("--out", out_dir, "Output folder for <method>_<scene>.csv/.md/.png (created when missing)");
  app.add_option("--cache", cache_dir, "Reference cache folder (default: <out>/reference-cache)");
  app.add_option("--threads", request.threads, "Worker threads for methods and references (0: all)");
  app.add_option("--seed", request.seed, "Random seed passed to the methods");
  app.add_option("--cost", cost, "Cost axis of the Pareto front: bake (seconds) or frame (ms)")
      ->check(CLI::IsMember({"bake", "frame"}));
  app.add_option("--presets", presets, "Relative-RMSE targets of the presets preview,medium,high")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--exposure", request.exposure, "Exposure before tonemapping, for PSNR")->check(CLI::PositiveNumber);
  app.add_option("--sky", sky,
                 "R,G,B: a uniform sky of this radiance, W/(m^2 sr), or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B' "
                 "a gradient over the elevation, replacing the scene's (as gi-bake --sky); the references see it too");
  app.add_option("--sun", sun,
                 "'direction:dx,dy,dz;irradiance:R,G,B[;angular_radius_deg:D]': a sun replacing the scene's (as "
                 "gi-bake --sun); the references see it too");
  app.add_flag("--untextured", request.untextured,
               "Sweep the scene without its textures (as gi-bake --untextured); the references see it too");
  app.add_option("--split-truth", request.split_truth_spp,
                 "SPP: judge the light-atlas runs against two path-traced atlases of SPP samples per texel (their "
                 "indirect and total), adding the indirect-dominated and whole-lightmap errors")
      ->check(CLI::Range(1, 1 << 20));
  app.add_flag("--no-plot", no_plot, "Do not run the plot script (print its command)");
  app.add_flag("--list", list, "List the sweep methods, their knobs and default grids, and exit");
  if (auto rc = tools::parse(app, kTool, argc, argv)) return *rc;
  if (list) {
    print_list();
    return tools::kExitOk;
  }
  if (request.method.empty() || scene.empty() || out_dir.empty())
    return tools::fail(kTool, "give --method NAME --scene FILE --out DIR (or --list)", tools::kExitUsage);
  request.scene = scene;
  request.out_dir = out_dir;
  request.cache_dir = cache_dir;
  request.frame_cost = cost == "frame";
  if (auto rc = scene_lighting(sky, sun, request)) return *rc;
  if (!presets.empty())
    for (int i = 0; i < 3; ++i) request.preset_targets[i] = presets[static_cast<std::size_t>(i)];

  return run_and_report(request, no_plot);
}
