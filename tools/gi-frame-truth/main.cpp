// gi-frame-truth: a scene's frame with its GI against the path tracer's truth of the same
// state, per world region the pixels show and over the frame (gi/frame_truth.h). Lights the
// scene in memory (sun, sky; optionally without its own lights and textures), bakes it at
// each --preset (gi::bake_bundle) and/or takes --bundle NAME=DIR, renders one truth per view
// and compares every bake's frame with it; writes each view's images (truth, regions, and per
// bake the frame and the luminance ratio) and the table (Markdown, CSV). docs/real_level.md.
//   gi-frame-truth --scene ../shared/external-assets/dabrovic-sponza/sponza.gltf --untextured
//       --sky 'zenith:10,16,30;horizon:28,30,34;ground:6,6,6'
//       --sun 'direction:0.25,-1,0.15;irradiance:700,650,600' --camera courtyard=-10,1.7,-2,8,4,4.5,60
//       --region courtyard:-11.6,-1,-3.18,11.6,4.75,3.18 --preset preview --preset medium
//       --width 240 --height 135 --spp 512 --out out/level --md out/level/table.md
// Without --camera, the scene's first glTF camera. Progress on stderr, the table and the
// costs on stdout. Exit codes: tools/common/tool_main.h.
#include <sys/resource.h>
#include <engine/gltf.h>
#include <engine/gpu/context.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/frame_truth.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>

#include "console_progress.h"
#include "frame_truth_output.h"
#include "sun_option.h"
#include "tool_main.h"
#include "view_options.h"

namespace {

constexpr const char* kTool = "gi-frame-truth";
namespace fs = std::filesystem;
using frame_truth_tool::RunInfo;

/// Peak resident memory of this process so far, MB (getrusage: ru_maxrss is in KiB on Linux).
double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

/// The scene's first glTF camera as a FrameCamera (its world position, looking along -Z).
std::optional<gi::FrameCamera> scene_camera(const engine::SceneAsset& asset) {
  const engine::Scene scene = engine::instantiate(asset);
  const engine::Entity e = engine::find_camera(scene.registry);
  if (e.is_null()) return std::nullopt;
  const glm::mat4& m = scene.registry.get<engine::WorldTransform>(e).matrix;
  const glm::vec3 position(m[3]);
  const glm::vec3 forward = -glm::normalize(glm::vec3(m[2]));
  return gi::FrameCamera{.name = "scene",
                         .position_m = position,
                         .target_m = position + forward,
                         .yfov_rad = scene.registry.get<engine::Camera>(e).yfov_rad};
}

/// Removes every light and emission the scene carries (a Cornell box without its lamp).
void drop_lights(engine::SceneAsset& a) {
  for (engine::Node& n : a.nodes) n.light = -1;
  a.lights.clear();
  a.environment.sun_light = a.environment.sun_node = -1;
  for (engine::Material& m : a.materials) m.emissive = glm::vec3(0.0f);
}

bool append(const std::string& path, const std::string& header, const std::string& rows) {
  const bool fresh = !fs::exists(path) || fs::file_size(path) == 0;
  std::ofstream out(path, std::ios::app);
  out << (fresh ? header : "") << rows;
  return static_cast<bool>(out);
}

/// A GI to compare: its name in the table and its bundle.
struct NamedBundle {
  std::string name;
  std::string dir;
};

/// Bakes `asset` at each preset into <out>/<label>_<preset>.gibake; appends a summary line
/// (wall time, the process's peak RSS so far) per bake.
engine::Result<std::vector<NamedBundle>> bake_presets(const engine::SceneAsset& asset,
                                                      const std::vector<std::string>& presets, const std::string& out,
                                                      const std::string& label, unsigned threads,
                                                      tools::ConsoleProgress& bar, std::string& summary) {
  std::vector<NamedBundle> out_bundles;
  const gi::BakeInput input = gi::bake_input_from(asset);
  for (const std::string& preset : presets) {
    const std::string dir = (fs::path(out) / (label + "_" + preset + ".gibake")).string();
    const auto t0 = std::chrono::steady_clock::now();
    auto baked =
        gi::bake_bundle(input, dir, {.preset = preset, .threads = threads}, {.progress = bar.stages(), .log = {}});
    bar.finish();
    if (!baked) return baked.error();
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    char line[256];
    std::snprintf(line, sizeof line, "%s: bake %s: %.1f s wall; peak RSS of the process so far %.0f MB\n",
                  label.c_str(), preset.c_str(), seconds, peak_rss_mb());
    summary += line;
    out_bundles.push_back({preset, dir});
  }
  return out_bundles;
}

std::string cost_lines(const std::string& label, const std::string& gi, const gi::FrameTruthReport& r,
                       const std::string& gi_label) {
  char line[512];
  std::snprintf(line, sizeof line,
                "%s, %s, %s, %dx%d: frame %.1f ms (median; %.1f-%.1f; first %.1f ms) with %s; truth %.1f s; %zu "
                "background, %zu non-finite pixels\n",
                label.c_str(), gi.c_str(), r.camera.c_str(), r.frame.width, r.frame.height, r.cost.frame_ms,
                r.cost.frame_ms_min, r.cost.frame_ms_max, r.cost.first_frame_ms, gi_label.c_str(), r.truth_seconds,
                r.background_pixels, r.nonfinite_pixels);
  std::string out = line;
  for (const engine::PassTiming& p : r.cost.frame) {
    std::snprintf(line, sizeof line, "    %s: %.2f ms\n", p.name.c_str(), p.ms);
    out += line;
  }
  return out;
}

struct Options {
  std::string scene_path, sky, sun, out_dir, md_path, csv_path, label;
  std::vector<std::string> camera_texts, region_texts, bundle_texts, presets;
  bool untextured = false, no_lights = false;
  float exposure = 0.0f;
  gi::FrameTruthSettings settings;
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--scene", o.scene_path, "glTF/GLB scene")->required()->check(CLI::ExistingFile);
  app.add_flag("--untextured", o.untextured,
               "Drop the materials' textures in memory (the bakers and the path tracer do not read them yet)");
  app.add_flag("--no-lights", o.no_lights, "Drop the scene's own lights and emission (before --sun)");
  app.add_option("--sky", o.sky, "R,G,B or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B', as gi-bake --sky");
  app.add_option("--sun", o.sun,
                 "'direction:dx,dy,dz;irradiance:R,G,B[;angular_radius_deg:D]': a sun replacing the scene's (as "
                 "gi-bake --sun)");
  app.add_option("--camera", o.camera_texts,
                 "NAME=px,py,pz,tx,ty,tz[,yfov_deg]: a view from p looking at t (repeatable; default: the scene's "
                 "first camera)");
  app.add_option("--region", o.region_texts,
                 "NAME:minx,miny,minz,maxx,maxy,maxz: a world box (repeatable; the first that holds a pixel's first "
                 "hit wins; the rest is 'other')");
  app.add_option("--bundle", o.bundle_texts,
                 "[NAME=]DIR: an existing bake bundle of this scene as lit here (repeatable)");
  app.add_option("--preset", o.presets,
                 "Bake at this preset and compare (repeatable; default preview without --bundle)");
  app.add_option("--width", o.settings.width, "Image width")->check(CLI::Range(8, 4096));
  app.add_option("--height", o.settings.height, "Image height")->check(CLI::Range(8, 4096));
  app.add_option("--spp", o.settings.samples_per_pixel, "The truth's samples per pixel (two halves)")
      ->check(CLI::Range(2, 1 << 20));
  app.add_option("--seed", o.settings.seed, "The truth's seed (its halves: seed, seed + 1)");
  app.add_option("--threads", o.settings.threads, "Path tracer and bake threads (0: all)");
  app.add_option("--exposure", o.exposure, "Exposure of the PNGs (0: per view, from the truth's mean)");
  app.add_option("--out", o.out_dir, "Folder for the bundles baked here and each view's images")->required();
  app.add_option("--label", o.label, "The run's name in the table and image names (default: the scene's stem)");
  app.add_option("--md", o.md_path, "Markdown file to append the table to (header when new)");
  app.add_option("--csv", o.csv_path, "CSV file to append the rows to (header when new)");
}

// The views, regions and bundles of the command line (preview baked when none is named); the
// exit code when one is malformed.
std::optional<int> parse_views(Options& o, std::vector<gi::FrameCamera>& cameras, std::vector<NamedBundle>& gis) {
  if (o.label.empty()) o.label = fs::path(o.scene_path).stem().string();
  for (const std::string& t : o.camera_texts) {
    const auto c = frame_truth_tool::parse_camera(t);
    if (!c) return tools::fail(kTool, "--camera wants NAME=px,py,pz,tx,ty,tz[,yfov_deg], got '" + t + "'", 2);
    cameras.push_back(*c);
  }
  for (const std::string& t : o.region_texts) {
    const auto r = frame_truth_tool::parse_region(t);
    if (!r) return tools::fail(kTool, "--region wants NAME:minx,miny,minz,maxx,maxy,maxz, got '" + t + "'", 2);
    o.settings.regions.push_back(*r);
  }
  for (const std::string& t : o.bundle_texts) {
    const std::size_t eq = t.find('=');
    const std::string dir = eq == std::string::npos ? t : t.substr(eq + 1);
    gis.push_back({eq == std::string::npos ? fs::path(dir).stem().string() : t.substr(0, eq), dir});
  }
  if (gis.empty() && o.presets.empty()) o.presets.push_back("preview");
  return std::nullopt;
}

// The scene as lit here (textures, lights, sky and sun as the options say), with its first
// camera when no --camera was given; the exit code on failure.
std::optional<int> lit_scene(const Options& o, engine::SceneAsset& asset, std::vector<gi::FrameCamera>& cameras) {
  auto loaded = engine::load_gltf(o.scene_path);
  if (!loaded) return tools::fail(kTool, loaded.error());
  asset = std::move(loaded).value();
  if (o.untextured) asset = gi::without_textures(std::move(asset));
  if (o.no_lights) drop_lights(asset);
  if (!o.sky.empty() && !tools::set_sky(asset.environment, o.sky))
    return tools::fail(kTool, std::string(tools::kSkyUsage) + ", got '" + o.sky + "'", tools::kExitUsage);
  if (!o.sun.empty() && !tools::set_sun(asset, o.sun))
    return tools::fail(kTool, std::string(tools::kSunUsage) + ", got '" + o.sun + "'", tools::kExitUsage);
  if (cameras.empty()) {
    const auto c = scene_camera(asset);
    if (!c) return tools::fail(kTool, o.scene_path + " has no camera: give --camera", tools::kExitUsage);
    cameras.push_back(*c);
  }
  return std::nullopt;
}

// The table's rows of every view and bundle, and their images.
struct Tables {
  std::string md, csv;
};

// Per view one truth, compared with every bundle's frame; the exit code on failure.
std::optional<int> compare_views(const Options& o, const std::vector<gi::FrameCamera>& cameras,
                                 const std::vector<NamedBundle>& gis,
                                 const std::vector<std::unique_ptr<gi::FrameTruthBench>>& benches,
                                 tools::ConsoleProgress& bar, Tables& tables, std::string& summary) {
  for (const gi::FrameCamera& camera : cameras) {
    auto truth = benches.front()->render_truth(camera, bar.stages());
    bar.finish();
    if (!truth) return tools::fail(kTool, truth.error());
    const std::string stem = o.label + "_" + camera.name;
    if (auto ok = frame_truth_tool::write_truth_images(o.out_dir, stem, *truth, o.exposure); !ok)
      return tools::fail(kTool, ok.error());
    for (std::size_t g = 0; g < gis.size(); ++g) {
      auto report = benches[g]->compare(*truth);
      if (!report) return tools::fail(kTool, report.error());
      if (auto ok =
              frame_truth_tool::write_frame_images(o.out_dir, stem + "_" + gis[g].name, *report, *truth, o.exposure);
          !ok)
        return tools::fail(kTool, ok.error());
      const RunInfo run{.label = o.label,
                        .gi = gis[g].name,
                        .width = o.settings.width,
                        .height = o.settings.height,
                        .samples_per_pixel = truth->samples_per_pixel};
      tables.md += frame_truth_tool::markdown_rows(run, *report);
      tables.csv += frame_truth_tool::csv_rows(run, *report);
      summary += cost_lines(o.label, gis[g].name, *report, benches[g]->gi_label());
    }
  }
  return std::nullopt;
}

}  // namespace

// The order in one place: options, the scene lit in memory, the bakes, then per view one
// truth compared with every bake, and the outputs.
int main(int argc, char** argv) {
  CLI::App app{"A scene's frame with its GI against the path tracer's truth, per world region and over the frame"};
  Options o;
  add_options(app, o);
  if (auto rc = tools::parse(app, kTool, argc, argv)) return *rc;
  std::vector<gi::FrameCamera> cameras;
  std::vector<NamedBundle> gis;
  if (auto rc = parse_views(o, cameras, gis)) return *rc;
  engine::SceneAsset asset;
  if (auto rc = lit_scene(o, asset, cameras)) return *rc;

  tools::install_interrupt_handler();
  tools::ConsoleProgress bar;
  std::string summary;
  auto baked = bake_presets(asset, o.presets, o.out_dir, o.label, o.settings.threads, bar, summary);
  if (!baked) return tools::fail(kTool, baked.error());
  gis.insert(gis.end(), baked->begin(), baked->end());

  auto gpu = engine::GpuContext::create_headless();
  if (!gpu) return tools::fail(kTool, gpu.error());
  std::vector<std::unique_ptr<gi::FrameTruthBench>> benches;
  for (const NamedBundle& g : gis) {
    auto bench = gi::FrameTruthBench::create(asset, g.dir, o.settings);
    if (!bench) return tools::fail(kTool, bench.error());
    benches.push_back(std::move(bench).value());
  }
  Tables tables;
  if (auto rc = compare_views(o, cameras, gis, benches, bar, tables, summary)) return *rc;
  std::fputs((frame_truth_tool::markdown_header() + tables.md + "\n" + summary).c_str(), stdout);
  if (!o.md_path.empty() && !append(o.md_path, frame_truth_tool::markdown_header(), tables.md))
    return tools::fail(kTool, "cannot write " + o.md_path, tools::kExitFailure);
  if (!o.csv_path.empty() && !append(o.csv_path, frame_truth_tool::csv_header(), tables.csv))
    return tools::fail(kTool, "cannot write " + o.csv_path, tools::kExitFailure);
  return tools::kExitOk;
}
