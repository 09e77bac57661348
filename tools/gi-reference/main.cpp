// gi-reference: renders a scene's camera with the reference path tracer (linear EXR, and a
// tonemapped PNG on request), or the ground-truth irradiance of its light-atlas texels.
//   gi-reference --scene assets/cornell_box.gltf --width 256 --height 256 --spp 256 --out cbox.exr
//   gi-reference --scene assets/cornell_box.gltf --atlas-density 64 --spp 256 --atlas-out out/cbox_atlas
//   gi-reference --scene Avocado.glb --sky 0.8,0.9,1.0 --width 256 --height 256 --out avocado.exr
// Exit codes: tools/common/tool_main.h.
#include <engine/display_transform.h>
#include <engine/gltf.h>
#include <engine/image.h>
#include <engine/scene.h>
#include <gi/reference.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "console_progress.h"
#include "tool_main.h"

namespace {

constexpr const char* kTool = "gi-reference";
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

engine::ImageRgbaF rgb_image(int w, int h, const std::vector<glm::vec3>& v, const std::vector<std::uint8_t>& valid) {
  engine::ImageRgbaF img;
  img.width = w;
  img.height = h;
  img.pixels.resize(v.size() * 4);
  for (std::size_t i = 0; i < v.size(); ++i) {
    img.pixels[4 * i + 0] = v[i].x;
    img.pixels[4 * i + 1] = v[i].y;
    img.pixels[4 * i + 2] = v[i].z;
    img.pixels[4 * i + 3] = valid[i] ? 1.0f : 0.0f;  // alpha: texel covered by a triangle
  }
  return img;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Reference path tracer: camera images and light-atlas ground truth"};
  std::string scene_path, out_path, png_path, atlas_out, camera_name, sky;
  int width = 256, height = 256, spp = 64, bounces = -1;
  unsigned threads = 0;
  std::uint64_t seed = 1;
  float exposure = 1.0f, atlas_density = 0.0f;
  app.add_option("--scene", scene_path, "glTF scene (.gltf/.glb)")->required();
  app.add_option("--camera", camera_name, "camera node name (default: the first camera)");
  app.add_option("--width", width, "image width")->check(CLI::Range(1, 16384));
  app.add_option("--height", height, "image height")->check(CLI::Range(1, 16384));
  app.add_option("--spp", spp, "samples per pixel (or per atlas texel)")->check(CLI::Range(1, 1 << 20));
  app.add_option("--bounces", bounces, "indirect bounces (-1: unlimited, 0: direct only)")->check(CLI::Range(-1, 1000));
  app.add_option("--threads", threads, "worker threads (0: all); the result does not depend on it");
  app.add_option("--seed", seed, "random seed");
  app.add_option("--out", out_path, "linear OpenEXR of the camera image");
  app.add_option("--png", png_path, "tonemapped PNG of the camera image (the renderer's display transform)");
  app.add_option("--exposure", exposure, "exposure for --png");
  app.add_option("--atlas-density", atlas_density, "light-atlas texels per metre (enables the atlas output)");
  app.add_option("--sky", sky,
                 "R,G,B (uniform) or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B' (gradient): a sky replacing the "
                 "scene's gi.sky (as gi-bake --sky)");
  app.add_option("--atlas-out", atlas_out, "folder for atlas_direct.exr, atlas_indirect.exr, atlas_total.exr");
  if (auto rc = tools::parse(app, kTool, argc, argv)) return *rc;
  if (out_path.empty() && png_path.empty() && atlas_out.empty())
    return tools::fail(kTool, "nothing to do: give --out, --png or --atlas-out", tools::kExitUsage);
  if (!atlas_out.empty() && !(atlas_density > 0.0f))
    return tools::fail(kTool, "--atlas-out needs --atlas-density > 0", tools::kExitUsage);

  auto asset = engine::load_gltf(scene_path);
  if (!asset) return tools::fail(kTool, asset.error());
  if (!sky.empty()) {
    if (!tools::set_sky(asset->environment, sky))
      return tools::fail(kTool, std::string(tools::kSkyUsage) + ", got '" + sky + "'", tools::kExitUsage);
  }
  engine::Scene scene = engine::instantiate(std::move(asset).value());
  tools::install_interrupt_handler();
  tools::ConsoleProgress bar;

  gi::ReferenceSettings settings;
  settings.samples_per_pixel = spp;
  settings.max_bounces = bounces;
  settings.threads = threads;
  settings.seed = seed;

  if (!out_path.empty() || !png_path.empty()) {
    const engine::Entity camera =
        camera_name.empty() ? engine::find_camera(scene.registry) : engine::find_by_name(scene.registry, camera_name);
    if (camera.is_null())
      return tools::fail(kTool, scene_path + ": no camera" + (camera_name.empty() ? "" : " named " + camera_name),
                         tools::kExitUsage);
    settings.progress = bar.stage("render");
    const auto start = Clock::now();
    auto image = gi::render_reference_image(scene, camera, width, height, settings);
    bar.finish();
    if (!image) return tools::fail(kTool, image.error());
    const double secs = seconds_since(start);
    std::printf("rendered %dx%d at %d spp in %.2f s (%.3f Mpaths/s)\n", width, height, spp, secs,
                static_cast<double>(width) * height * spp / secs * 1e-6);
    if (!out_path.empty())
      if (auto ok = engine::save_exr(out_path, *image); !ok) return tools::fail(kTool, ok.error());
    if (!png_path.empty()) {
      engine::ImageRgba8 ldr{image->width, image->height, std::vector<std::uint8_t>(image->pixels.size())};
      for (std::size_t i = 0; i < image->pixels.size(); ++i)
        ldr.pixels[i] = i % 4 == 3
                            ? 255
                            : static_cast<std::uint8_t>(std::lround(
                                  255.0 * engine::display_tonemap(static_cast<double>(image->pixels[i]), exposure)));
      if (auto ok = engine::save_png(png_path, ldr); !ok) return tools::fail(kTool, ok.error());
    }
  }

  if (!atlas_out.empty()) {
    const auto start = Clock::now();
    settings.progress = bar.stage("atlas");
    auto truth = gi::reference_atlas(gi::bake_input_from(scene), atlas_density, settings);
    bar.finish();
    if (!truth) return tools::fail(kTool, truth.error());
    std::size_t valid = 0;
    for (std::uint8_t v : truth->valid) valid += v;
    std::printf("atlas %dx%d at %.1f texels/m (%zu valid texels) at %d spp in %.2f s\n", truth->width, truth->height,
                static_cast<double>(truth->texels_per_metre), valid, spp, seconds_since(start));
    std::error_code ec;
    std::filesystem::create_directories(atlas_out, ec);
    if (ec) return tools::fail(kTool, atlas_out + ": cannot create folder: " + ec.message(), tools::kExitFailure);
    const std::pair<const char*, const std::vector<glm::vec3>*> files[] = {{"atlas_direct.exr", &truth->direct},
                                                                           {"atlas_indirect.exr", &truth->indirect},
                                                                           {"atlas_total.exr", &truth->total}};
    for (const auto& [name, values] : files) {
      const auto path = std::filesystem::path(atlas_out) / name;
      if (auto ok = engine::save_exr(path, rgb_image(truth->width, truth->height, *values, truth->valid)); !ok)
        return tools::fail(kTool, ok.error());
    }
  }
  return tools::kExitOk;
}
