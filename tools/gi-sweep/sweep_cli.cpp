#include "sweep_cli.h"

#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cctype>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "plot_command.h"
#include "io/atomic_file.h"
#include "sweep/knob_grid.h"
#include "sweep/knob_spec.h"
#include "sweep/sweep_csv.h"
#include "sweep/sweep_progress_bar.h"
#include "sweep/sweep_runner.h"
#include "sweep/sweep_scene.h"
#include "sweep/sweep_summary.h"

namespace gi_sweep {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;
extern "C" void on_sigint(int) { g_interrupted = 1; }

const char* kind_name(gi::KnobKind k) {
  switch (k) {
    case gi::KnobKind::Integer:
      return "integer";
    case gi::KnobKind::Real:
      return "real";
    case gi::KnobKind::Choice:
      return "choice";
  }
  return "?";
}

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

void print_list(const gi::SweepRegistry& registry) {
  if (registry.methods().empty()) {
    std::printf(
        "No sweep methods are registered yet. Methods and the reference path tracer register in\n"
        "gi/src/sweep/builtin_methods.cpp (register_builtin_sweep_methods).\n");
  }
  for (const gi::SweepMethod& m : registry.methods()) {
    std::printf("%s  %s\n", m.name.c_str(), m.description.c_str());
    for (const gi::KnobSpec& k : m.knobs) {
      std::string range;
      if (k.kind == gi::KnobKind::Choice) {
        range = "{" + join(k.choices, ", ") + "}";
      } else {
        range = "[" + gi::format_number(k.min_value) + ", " + gi::format_number(k.max_value) + "]";
      }
      std::printf("  --knob %s=%s   (%s %s) %s\n", k.name.c_str(), join(k.default_grid, ",").c_str(), kind_name(k.kind),
                  range.c_str(), k.description.c_str());
    }
  }
  if (!registry.providers().empty()) {
    std::printf("reference providers:");
    for (const gi::ReferenceProvider& p : registry.providers())
      std::printf(" %s@%s", p.kind.c_str(), p.version.c_str());
    std::printf("\n");
  }
}

engine::Result<gi::PresetTargets> parse_targets(const std::string& text) {
  gi::KnobSpec spec{.name = "presets", .kind = gi::KnobKind::Real, .min_value = 0.0};
  engine::Result<std::vector<std::string>> v = gi::parse_knob_values(spec, text);
  if (!v) return engine::Error{"--presets", "", v.error().message};
  if (v->size() != 3) return engine::Error{"--presets", "", "expected three error targets: preview,medium,high"};
  return gi::PresetTargets{std::stod((*v)[0]), std::stod((*v)[1]), std::stod((*v)[2])};
}

std::string file_stem_safe(std::string s) {
  for (char& c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) c = '_';
  return s;
}

}  // namespace

int run_cli(int argc, char** argv, const gi::SweepRegistry& registry) {
  CLI::App app{"Measures a GI method's accuracy (vs the reference) and cost over a grid of its quality knobs"};
  std::string method_name, scene_file, out_dir, cache_dir, cost = "bake", presets = "0.2,0.05,0.01";
  std::vector<std::string> knobs;
  unsigned threads = 0;
  std::uint64_t seed = 1;
  double exposure = 1.0;
  bool list = false, no_plot = false;
  app.add_option("--method", method_name, "Registered method to sweep (see --list)");
  app.add_option("--scene", scene_file, "glTF/GLB scene file")->check(CLI::ExistingFile);
  app.add_option("--knob", knobs, "Override a knob's values: name=v1,v2,... (repeatable)");
  app.add_option("--out", out_dir, "Output folder for <method>_<scene>.csv/.md/.png (created when missing)");
  app.add_option("--cache", cache_dir, "Reference cache folder (default: <out>/reference-cache)");
  app.add_option("--threads", threads, "Worker threads for methods and references (0: all)");
  app.add_option("--seed", seed, "Random seed passed to the methods");
  app.add_option("--cost", cost, "Cost axis of the Pareto front: bake (seconds) or frame (ms)")
      ->check(CLI::IsMember({"bake", "frame"}));
  app.add_option("--presets", presets, "Relative-RMSE targets of the presets preview,medium,high");
  app.add_option("--exposure", exposure, "Exposure before tonemapping, for PSNR")->check(CLI::PositiveNumber);
  app.add_flag("--no-plot", no_plot, "Do not run the plot script (print its command)");
  app.add_flag("--list", list, "List the registered methods, their knobs and default grids, and exit");
  CLI11_PARSE(app, argc, argv);

  if (list) {
    print_list(registry);
    return 0;
  }
  if (method_name.empty() || scene_file.empty() || out_dir.empty()) {
    std::cerr << "gi-sweep: give --method NAME --scene FILE --out DIR (or --list)\n";
    return 2;
  }
  const gi::SweepMethod* method = registry.find_method(method_name);
  if (method == nullptr) {
    std::vector<std::string> names;
    for (const gi::SweepMethod& m : registry.methods()) names.push_back(m.name);
    std::cerr << "gi-sweep: unknown method '" << method_name
              << "' (registered: " << (names.empty() ? std::string("none yet") : join(names, ", ")) << ")\n";
    return 2;
  }
  engine::Result<gi::KnobGrid> grid = gi::make_knob_grid(*method, knobs);
  if (!grid) {
    std::cerr << "gi-sweep: " << grid.error().to_string() << '\n';
    return 2;
  }
  engine::Result<gi::PresetTargets> targets = parse_targets(presets);
  if (!targets) {
    std::cerr << "gi-sweep: " << targets.error().to_string() << '\n';
    return 2;
  }
  engine::Result<gi::SweepScene> scene = gi::load_sweep_scene(scene_file);
  if (!scene) {
    std::cerr << "gi-sweep: cannot load the scene: " << scene.error().to_string() << '\n';
    return 1;
  }
  std::error_code ec;
  std::filesystem::create_directories(out_dir, ec);
  if (ec) {
    std::cerr << "gi-sweep: " << out_dir << ": cannot create the output folder: " << ec.message() << '\n';
    return 1;
  }

  const std::vector<gi::KnobSetting> settings = grid->settings();
  std::cerr << "gi-sweep: " << method->name << " on " << scene->display_name() << " (" << scene->content_hash
            << "): " << settings.size() << " run(s)\n";
  gi::SweepOptions options;
  options.cache_dir =
      cache_dir.empty() ? std::filesystem::path(out_dir) / "reference-cache" : std::filesystem::path(cache_dir);
  options.threads = threads;
  options.seed = seed;
  options.metrics.exposure = exposure;

  std::signal(SIGINT, on_sigint);
  gi::SweepProgressBar bar(std::cerr, ::isatty(2) != 0);
  engine::Result<gi::SweepResult> result = gi::run_sweep(
      registry, *method, *scene, settings, options,
      [&](const gi::SweepProgress& p) {
        if (g_interrupted) bar.request_cancel();
        return bar.update(p);
      },
      [&](const std::string& warning) {
        bar.finish();
        std::cerr << "gi-sweep: warning: " << warning << '\n';
      });
  bar.finish();
  std::signal(SIGINT, SIG_DFL);
  if (!result) {
    std::cerr << "gi-sweep: " << result.error().to_string() << '\n';
    return 1;
  }

  const std::filesystem::path stem =
      std::filesystem::path(out_dir) / file_stem_safe(method->name + "_" + scene->path.stem().string());
  const std::filesystem::path csv = std::filesystem::path(stem).concat(".csv");
  const std::filesystem::path md = std::filesystem::path(stem).concat(".md");
  const gi::SweepSummary summary = gi::summarize_sweep(
      result->rows,
      {.cost = cost == "bake" ? gi::SweepCost::BakeSeconds : gi::SweepCost::FrameMs, .targets = *targets});
  for (const auto& [path, text] : {std::pair{csv, gi::sweep_csv(result->rows)},
                                   std::pair{md, gi::sweep_summary_markdown(result->rows, summary)}}) {
    if (engine::Status s = gi::write_file_atomically(path, text); !s) {
      std::cerr << "gi-sweep: " << s.error().to_string() << '\n';
      return 1;
    }
  }
  std::size_t failed = 0;
  for (const gi::SweepRow& r : result->rows) {
    if (!r.ok()) {
      ++failed;
      std::cerr << "gi-sweep: run " << r.knobs.label() << ": " << r.status << '\n';
    }
  }
  std::cerr << "gi-sweep: wrote " << csv.string() << " and " << md.string() << " (" << result->rows.size()
            << " run(s), " << failed << " failed; references: " << result->references_computed << " computed, "
            << result->references_from_cache << " from cache)\n";
  std::cerr << (no_plot ? "plots: skipped; to plot, run:\n  " + plot_command(csv) : plot_sweep_csv(csv)) << '\n';
  if (result->cancelled) {
    std::cerr << "gi-sweep: interrupted; the files hold the runs completed so far\n";
    return 130;
  }
  return 0;
}

}  // namespace gi_sweep
