// gi-bake: bakes the GI data of a scene into a bake bundle (gi::bake_bundle, gi/bake.h).
//   gi-bake --scene assets/cornell_box.gltf --methods light_atlas --preset high --out out/cornell_box.gibake
//   gi-bake --plan assets/demo_level.gltf --preset preview    # print the effect plan, bake nothing
//   gi-bake --scene level.gltf --preset medium --export-uv1 out/level_uv1.gltf   # the lightmap UVs
//   gi-bake --scene Avocado.glb --sky 0.8,0.9,1.0 --out out/avocado.gibake      # lit by a uniform sky
//   gi-bake --scene level.gltf --sun 'direction:0.3,-1,0.2;irradiance:700,650,600'  # and a sun
//   gi-bake --scene level.gltf --out out/level.gibake --shard 3/8   # one shard of a distributed bake
//   gi-bake --scene level.gltf --out out/level.gibake --merge       # the bundle from all 8 shards
// Without --methods it bakes what gi::plan (gi/plan.h) calls for and says what it skips;
// the plan goes into the manifest either way. Exit codes: tools/common/tool_main.h.
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/bake.h>
#include <gi/light_atlas_uv.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>
#include <CLI/CLI.hpp>

#include "console_progress.h"
#include "sun_option.h"
#include "tool_main.h"

namespace {

constexpr const char* kTool = "gi-bake";

std::vector<std::string> split(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

// The command line beside gi::BakeOptions.
struct ToolOptions {
  std::string scene_path, positional_scene, out_dir, methods, export_uv1, sky, sun, shard;
  bool plan_only = false, untextured = false;
};

void add_scene_options(CLI::App& app, ToolOptions& t) {
  app.add_option("--scene", t.scene_path, "glTF/GLB scene")->check(CLI::ExistingFile);
  app.add_option("scene", t.positional_scene, "glTF/GLB scene (instead of --scene)")->check(CLI::ExistingFile);
  app.add_flag("--untextured", t.untextured,
               "Bake the scene's materials without their textures and alpha (factors alone, gi::without_textures; "
               "docs/materials-in-bakes.md)");
  app.add_flag("--plan", t.plan_only, "Print the effect plan with estimates for --preset and exit (docs/plan.md)");
  app.add_option("--export-uv1", t.export_uv1,
                 "Write the scene with the light-atlas UVs of --preset/--density as TEXCOORD_1 to this .gltf/.glb "
                 "(bakes nothing unless --out is given too)");
  app.add_option("--sky", t.sky,
                 "R,G,B: a uniform sky of this radiance, W/(m^2 sr), or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B' "
                 "a gradient over the elevation, for scenes that carry none (replaces the scene's gi.sky; "
                 "docs/scene-format.md)");
  app.add_option("--sun", t.sun,
                 "'direction:dx,dy,dz;irradiance:R,G,B[;angular_radius_deg:D]': a sun replacing the scene's gi.sun "
                 "(docs/scene-format.md)");
  app.add_option("--out", t.out_dir, "Bundle directory (default: out/<scene>.gibake)");
}

void add_bake_options(CLI::App& app, ToolOptions& t, gi::BakeOptions& o) {
  app.add_option(
      "--methods", t.methods,
      "Comma-separated methods to bake: light_atlas, prm, dlm, brf, antiradiance (default: what the plan calls for)");
  app.add_option("--preset", o.preset, "Quality preset: preview, medium, high (docs/sweeps/README.md)");
  app.add_option("--vpls", o.vpls, "Override the preset's VPL count")->check(CLI::PositiveNumber);
  app.add_option("--bounces", o.bounces, "Override the preset's indirect bounces")->check(CLI::Range(1, 64));
  app.add_option("--density", o.texels_per_metre, "Override the preset's atlas texels per metre")
      ->check(CLI::PositiveNumber);
  app.add_option("--samples", o.samples_per_vpl, "Override the sample points per VPL")->check(CLI::Range(1, 1024));
  app.add_option("--brf-basis", o.brf_basis, "Override the preset's BRF basis functions N")->check(CLI::Range(1, 1024));
  app.add_option("--brf-spheres", o.brf_spheres, "Override the preset's BRF field spheres")->check(CLI::Range(1, 256));
  app.add_option("--dlm-directions", o.dlm_directions, "Override the DLM's direction count")->check(CLI::Range(8, 256));
  app.add_option("--dlm-photons", o.dlm_photons, "Override the DLM's photon paths")->check(CLI::PositiveNumber);
  app.add_option("--dlm-bins", o.dlm_bins, "Override the DLM's bins: tangent (each texel's frame) or global")
      ->check(CLI::IsMember({"tangent", "global"}));
  app.add_flag("--include-direct", o.include_direct,
               "Bake the static lights' direct light into the atlas too (the renderer then draws none of theirs on "
               "the static world); without it the atlas holds the indirect light and the sky's shadowed direct light");
  app.add_option("--threads", o.threads, "Worker threads (0: all); the result does not depend on it");
  app.add_option("--seed", o.seed, "Random seed");
  // Distributed bakes (docs/distributed-bake.md).
  app.add_option("--shard", t.shard,
                 "I/N: bake only shard I (0-based) of N of the light atlas and PRM into <out>.shards/ "
                 "(docs/distributed-bake.md)");
  app.add_flag("--merge", o.merge_shards,
               "Write the bundle from the shards in <out>.shards/ (every one of 0..N-1 once, of this scene and "
               "options), baking the other methods here");
}

// --shard I/N into the options; the exit code when it is malformed.
std::optional<int> parse_shard(const std::string& shard, gi::BakeOptions& o) {
  if (shard.empty()) return std::nullopt;
  unsigned index = 0, count = 0;
  char tail = 0;
  if (o.merge_shards || std::sscanf(shard.c_str(), "%u/%u%c", &index, &count, &tail) != 2 || count == 0 ||
      index >= count || count > 65536)
    return tools::fail(kTool, "--shard takes I/N with 0 <= I < N <= 65536 and no --merge, got '" + shard + "'",
                       tools::kExitUsage);
  o.shard_index = index;
  o.shard_count = count;
  return std::nullopt;
}

// Writes the scene with the light-atlas UVs as TEXCOORD_1 (--export-uv1); the exit code on failure.
std::optional<int> export_uv1(const engine::SceneAsset& asset, const ToolOptions& t, const gi::BakeOptions& o) {
  auto uv = gi::with_light_atlas_uv1(asset, {.preset = o.preset, .texels_per_metre = o.texels_per_metre});
  if (!uv) return tools::fail(kTool, uv.error());
  const bool glb = std::filesystem::path(t.export_uv1).extension() == ".glb";
  if (auto written = engine::write_gltf(uv->scene, t.export_uv1, {.binary = glb}); !written)
    return tools::fail(kTool, written.error());
  std::printf("%s: wrote %s: TEXCOORD_1 of the static meshes, %zu charts in a %dx%d atlas at %g texels/m\n", kTool,
              t.export_uv1.c_str(), uv->charts, uv->width, uv->height, double{uv->texels_per_metre});
  return std::nullopt;
}

// Bakes the bundle with a progress bar and the bake's log on the console, and reports what it wrote.
int bake(const gi::BakeInput& input, const std::string& out_dir, const gi::BakeOptions& o) {
  tools::install_interrupt_handler();
  tools::ConsoleProgress bar;
  const gi::BakeHost host{.progress = bar.stages(), .log = [&](gi::LogLevel level, std::string_view line) {
                            bar.finish();
                            if (level == gi::LogLevel::Info)
                              std::printf("%s: %.*s\n", kTool, static_cast<int>(line.size()), line.data());
                            else
                              std::fprintf(stderr, "%s: %s: %.*s\n", kTool,
                                           std::string(gi::log_level_name(level)).c_str(),
                                           static_cast<int>(line.size()), line.data());
                            std::fflush(stdout);
                          }};
  auto report = gi::bake_bundle(input, out_dir, o, host);
  bar.finish();
  if (!report) return tools::fail(kTool, report.error());
  if (o.shard_count > 0 && !o.merge_shards) return tools::kExitOk;  // the bake's log named the shard file
  if (report->baked.empty()) {
    std::printf("%s: the plan calls for nothing this build can bake; no bundle written (gi-bake --plan says why)\n",
                kTool);
    return tools::kExitOk;
  }
  for (const gi::BakedMethod& m : report->baked)
    std::printf("%s: %s: %.2f s, %.1f MB\n", kTool, m.method.c_str(), m.seconds, static_cast<double>(m.bytes) / 1e6);
  std::printf("%s: wrote %s\n", kTool, out_dir.c_str());
  return tools::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Bakes a scene's GI data into a bake bundle (manifest.json + one file per method)"};
  ToolOptions t;
  gi::BakeOptions o;
  add_scene_options(app, t);
  add_bake_options(app, t, o);
  if (auto rc = tools::parse(app, kTool, argc, argv)) return *rc;
  if (auto rc = parse_shard(t.shard, o)) return *rc;
  if (t.scene_path.empty()) t.scene_path = t.positional_scene;
  if (t.scene_path.empty()) return tools::fail(kTool, "no scene (--scene FILE or FILE)", tools::kExitUsage);
  o.methods = split(t.methods);

  auto asset = engine::load_gltf(t.scene_path);
  if (!asset) return tools::fail(kTool, asset.error());
  if (!t.sky.empty()) {
    if (!tools::set_sky(asset->environment, t.sky))
      return tools::fail(kTool, std::string(tools::kSkyUsage) + ", got '" + t.sky + "'", tools::kExitUsage);
  }
  if (!t.sun.empty() && !tools::set_sun(*asset, t.sun))
    return tools::fail(kTool, std::string(tools::kSunUsage) + ", got '" + t.sun + "'", tools::kExitUsage);
  if (!t.export_uv1.empty()) {
    if (auto rc = export_uv1(*asset, t, o)) return *rc;
    if (t.out_dir.empty() && !t.plan_only) return tools::kExitOk;
  }
  const engine::Scene scene = engine::instantiate(std::move(asset).value());
  const gi::BakeInput input =
      t.untextured ? gi::without_textures(gi::bake_input_from(scene)) : gi::bake_input_from(scene);

  if (t.plan_only) {
    std::fputs(gi::format_plan(gi::plan(input, {.preset = o.preset,
                                                .texels_per_metre = o.texels_per_metre,
                                                .vpls = o.vpls,
                                                .samples_per_vpl = o.samples_per_vpl,
                                                .bounces = o.bounces}))
                   .c_str(),
               stdout);
    return tools::kExitOk;
  }
  if (t.out_dir.empty())
    t.out_dir =
        (std::filesystem::path("out") / (std::filesystem::path(t.scene_path).stem().string() + ".gibake")).string();
  return bake(input, t.out_dir, o);
}
