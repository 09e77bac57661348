// gi-reference: renders a scene's camera with the reference path tracer (linear EXR, and a
// tonemapped PNG on request), or the ground-truth irradiance of its light-atlas texels.
//   gi-reference --scene assets/cornell_box.gltf --width 256 --height 256 --spp 256 --out cbox.exr
//   gi-reference --scene assets/cornell_box.gltf --atlas-density 64 --spp 256 --atlas-out out/cbox_atlas
//   gi-reference --scene Avocado.glb --sky 0.8,0.9,1.0 --width 256 --height 256 --out avocado.exr
//   gi-reference --scene sponza.gltf --sun 'direction:0.25,-1,0.15;irradiance:700,650,600' --sky SKY
//                --atlas-density 8 --spp 256 --atlas-out out/truth
//   gi-reference --scene level.gltf --atlas-density 32 --spp 1024 --atlas-out out/truth --shard 3/8  # one shard
//   gi-reference --scene level.gltf --atlas-density 32 --spp 1024 --atlas-out out/truth --merge      # the 8 merged
// Sharded runs (docs/distributed-bake.md) split the pixels and atlas texels into blocks of 64;
// the merge writes files byte-identical to one process's.
// Exit codes: tools/common/tool_main.h.
#include <engine/display_transform.h>
#include <engine/gltf.h>
#include <engine/image.h>
#include <engine/scene.h>
#include <gi/reference.h>
#include <gi/reference_shard.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <CLI/CLI.hpp>

#include "console_progress.h"
#include "sun_option.h"
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

// Writes through "<path>.partial" renamed over `path`: a run that fails or is killed while
// writing leaves no half-written output.
template <class Save>
engine::Status save_atomically(const std::filesystem::path& path, Save save) {
  std::filesystem::path partial = path;
  partial += ".partial";
  if (auto ok = save(partial); !ok) {
    std::error_code ec;
    std::filesystem::remove(partial, ec);
    return ok;
  }
  std::error_code ec;
  std::filesystem::rename(partial, path, ec);
  if (ec) {
    std::filesystem::remove(partial, ec);
    return engine::Error{path.string(), "", "cannot move the written file into place: " + ec.message()};
  }
  return {};
}

struct Options {
  std::string scene_path, out_path, png_path, atlas_out, camera_name, sky, sun;
  int width = 256, height = 256, spp = 64, bounces = -1;
  unsigned threads = 0;
  std::uint64_t seed = 1;
  float exposure = 1.0f, atlas_density = 0.0f;
  std::string shard, shard_dir;
  bool merge = false;
  std::uint32_t shard_index = 0, shard_count = 0;  // from --shard
};

void add_options(CLI::App& app, Options& o) {
  app.add_option("--scene", o.scene_path, "glTF scene (.gltf/.glb)")->required();
  app.add_option("--camera", o.camera_name, "camera node name (default: the first camera)");
  app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 16384));
  app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 16384));
  app.add_option("--spp", o.spp, "samples per pixel (or per atlas texel)")->check(CLI::Range(1, 1 << 20));
  app.add_option("--bounces", o.bounces, "indirect bounces (-1: unlimited, 0: direct only)")
      ->check(CLI::Range(-1, 1000));
  app.add_option("--threads", o.threads, "worker threads (0: all); the result does not depend on it");
  app.add_option("--seed", o.seed, "random seed");
  app.add_option("--out", o.out_path, "linear OpenEXR of the camera image");
  app.add_option("--png", o.png_path, "tonemapped PNG of the camera image (the renderer's display transform)");
  app.add_option("--exposure", o.exposure, "exposure for --png");
  app.add_option("--atlas-density", o.atlas_density, "light-atlas texels per metre (enables the atlas output)");
  app.add_option("--sky", o.sky,
                 "R,G,B (uniform) or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B' (gradient): a sky replacing the "
                 "scene's gi.sky (as gi-bake --sky)");
  app.add_option("--sun", o.sun,
                 "'direction:dx,dy,dz;irradiance:R,G,B[;angular_radius_deg:D]': a sun replacing the scene's gi.sun "
                 "(as gi-bake --sun)");
  app.add_option("--atlas-out", o.atlas_out, "folder for atlas_direct.exr, atlas_indirect.exr, atlas_total.exr");
  // Distributed references (docs/distributed-bake.md).
  app.add_option("--shard", o.shard,
                 "I/N: compute only shard I (0-based) of N (blocks of 64 pixels / atlas texels) into the shard "
                 "directory; no image or atlas is written");
  app.add_flag("--merge", o.merge, "write the outputs from the N shard files in the shard directory");
  app.add_option("--shard-dir", o.shard_dir,
                 "shard directory (default: <atlas-out>.shards, else <out>.shards, else <png>.shards)");
}

// Checks the options that depend on each other and fills the shard index, count and
// directory; the exit code when they are wrong.
std::optional<int> check_options(Options& o) {
  if (!o.shard.empty()) {
    unsigned index = 0, count = 0;
    char tail = 0;
    if (o.merge || std::sscanf(o.shard.c_str(), "%u/%u%c", &index, &count, &tail) != 2 || count == 0 ||
        index >= count || count > 65536)
      return tools::fail(kTool, "--shard takes I/N with 0 <= I < N <= 65536 and no --merge, got '" + o.shard + "'",
                         tools::kExitUsage);
    o.shard_index = index;
    o.shard_count = count;
  }
  if (o.out_path.empty() && o.png_path.empty() && o.atlas_out.empty())
    return tools::fail(kTool, "nothing to do: give --out, --png or --atlas-out", tools::kExitUsage);
  if (!o.atlas_out.empty() && !(o.atlas_density > 0.0f))
    return tools::fail(kTool, "--atlas-out needs --atlas-density > 0", tools::kExitUsage);
  if (o.shard_dir.empty()) {
    std::filesystem::path main_output = !o.atlas_out.empty()  ? o.atlas_out
                                        : !o.out_path.empty() ? o.out_path
                                                              : o.png_path;
    if (!main_output.has_filename()) main_output = main_output.parent_path();  // "out/truth/"
    o.shard_dir = main_output.string() + ".shards";
  }
  return std::nullopt;
}

// The camera image's job: the named camera, else the first; the exit code when there is none.
std::optional<int> set_image_job(const Options& o, const engine::Scene& scene, gi::ReferenceJob& job) {
  const engine::Entity camera =
      o.camera_name.empty() ? engine::find_camera(scene.registry) : engine::find_by_name(scene.registry, o.camera_name);
  if (camera.is_null() || !scene.registry.has<engine::Camera>(camera) ||
      !scene.registry.has<engine::WorldTransform>(camera))
    return tools::fail(kTool, o.scene_path + ": no camera" + (o.camera_name.empty() ? "" : " named " + o.camera_name),
                       tools::kExitUsage);
  const engine::Camera& cam = scene.registry.get<engine::Camera>(camera);
  job.image =
      gi::ReferenceImageJob{.camera = {.camera_to_world = scene.registry.get<engine::WorldTransform>(camera).matrix,
                                       .yfov_rad = cam.yfov_rad,
                                       .aspect = cam.aspect},
                            .width = o.width,
                            .height = o.height};
  return std::nullopt;
}

// Renders the camera image and the atlas truth the job asks for in this process (not sharded).
std::optional<int> render_locally(const Options& o, const gi::BakeInput& input, const gi::ReferenceJob& job,
                                  tools::ConsoleProgress& bar, gi::ReferenceOutputs& outputs) {
  if (job.image) {
    gi::ReferenceJob part{.image = job.image, .atlas = {}, .settings = job.settings};
    part.settings.progress = bar.stage("render");
    const auto start = Clock::now();
    auto image = gi::render_reference_job(input, part);
    bar.finish();
    if (!image) return tools::fail(kTool, image.error());
    const double secs = seconds_since(start);
    std::printf("rendered %dx%d at %d spp in %.2f s (%.3f Mpaths/s)\n", o.width, o.height, o.spp, secs,
                static_cast<double>(o.width) * o.height * o.spp / secs * 1e-6);
    outputs.image = std::move(image->image);
  }
  if (job.atlas) {
    gi::ReferenceJob part{.image = {}, .atlas = job.atlas, .settings = job.settings};
    part.settings.progress = bar.stage("atlas");
    const auto start = Clock::now();
    auto truth = gi::render_reference_job(input, part);
    bar.finish();
    if (!truth) return tools::fail(kTool, truth.error());
    std::size_t valid = 0;
    for (std::uint8_t v : truth->atlas->valid) valid += v;
    std::printf("atlas %dx%d at %.1f texels/m (%zu valid texels) at %d spp in %.2f s\n", truth->atlas->width,
                truth->atlas->height, static_cast<double>(truth->atlas->texels_per_metre), valid, o.spp,
                seconds_since(start));
    outputs.atlas = std::move(truth->atlas);
  }
  return std::nullopt;
}

// Writes the outputs computed: the EXR and PNG of the image, the three atlas EXRs.
std::optional<int> write_outputs(const Options& o, const gi::ReferenceOutputs& outputs) {
  if (outputs.image) {
    const engine::ImageRgbaF& image = *outputs.image;
    if (!o.out_path.empty())
      if (auto ok = save_atomically(o.out_path, [&](const auto& p) { return engine::save_exr(p, image); }); !ok)
        return tools::fail(kTool, ok.error());
    if (!o.png_path.empty()) {
      engine::ImageRgba8 ldr{image.width, image.height, std::vector<std::uint8_t>(image.pixels.size())};
      for (std::size_t i = 0; i < image.pixels.size(); ++i)
        ldr.pixels[i] = i % 4 == 3
                            ? 255
                            : static_cast<std::uint8_t>(std::lround(
                                  255.0 * engine::display_tonemap(static_cast<double>(image.pixels[i]), o.exposure)));
      if (auto ok = save_atomically(o.png_path, [&](const auto& p) { return engine::save_png(p, ldr); }); !ok)
        return tools::fail(kTool, ok.error());
    }
  }
  if (outputs.atlas) {
    const gi::AtlasReference& truth = *outputs.atlas;
    std::error_code ec;
    std::filesystem::create_directories(o.atlas_out, ec);
    if (ec) return tools::fail(kTool, o.atlas_out + ": cannot create folder: " + ec.message(), tools::kExitFailure);
    const std::pair<const char*, const std::vector<glm::vec3>*> files[] = {{"atlas_direct.exr", &truth.direct},
                                                                           {"atlas_indirect.exr", &truth.indirect},
                                                                           {"atlas_total.exr", &truth.total}};
    for (const auto& [name, values] : files) {
      const auto path = std::filesystem::path(o.atlas_out) / name;
      const engine::ImageRgbaF img = rgb_image(truth.width, truth.height, *values, truth.valid);
      if (auto ok = save_atomically(path, [&](const auto& p) { return engine::save_exr(p, img); }); !ok)
        return tools::fail(kTool, ok.error());
    }
  }
  return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Reference path tracer: camera images and light-atlas ground truth"};
  Options o;
  add_options(app, o);
  if (auto rc = tools::parse(app, kTool, argc, argv)) return *rc;
  if (auto rc = check_options(o)) return *rc;
  const bool distributed = o.shard_count > 0 || o.merge;

  auto asset = engine::load_gltf(o.scene_path);
  if (!asset) return tools::fail(kTool, asset.error());
  if (!o.sky.empty()) {
    if (!tools::set_sky(asset->environment, o.sky))
      return tools::fail(kTool, std::string(tools::kSkyUsage) + ", got '" + o.sky + "'", tools::kExitUsage);
  }
  if (!o.sun.empty() && !tools::set_sun(*asset, o.sun))
    return tools::fail(kTool, std::string(tools::kSunUsage) + ", got '" + o.sun + "'", tools::kExitUsage);
  engine::Scene scene = engine::instantiate(std::move(asset).value());
  tools::install_interrupt_handler();
  tools::ConsoleProgress bar;

  gi::ReferenceSettings settings;
  settings.samples_per_pixel = o.spp;
  settings.max_bounces = o.bounces;
  settings.threads = o.threads;
  settings.seed = o.seed;

  gi::ReferenceJob job;
  job.settings = settings;
  if (!o.out_path.empty() || !o.png_path.empty())
    if (auto rc = set_image_job(o, scene, job)) return *rc;
  if (!o.atlas_out.empty()) job.atlas = gi::ReferenceAtlasJob{.texels_per_metre = o.atlas_density};
  const gi::BakeInput input = gi::bake_input_from(scene);

  // Shard I of N: its blocks into the shard directory, nothing else written.
  if (o.shard_count > 0) {
    const auto start = Clock::now();
    job.settings.progress = bar.stage("shard");
    auto path = gi::reference_shard(input, job, o.shard_index, o.shard_count, o.shard_dir);
    bar.finish();
    if (!path) return tools::fail(kTool, path.error());
    std::printf("shard %u/%u at %d spp in %.2f s: %s\n", o.shard_index, o.shard_count, o.spp, seconds_since(start),
                path->string().c_str());
    return tools::kExitOk;
  }

  // Everything is computed (or merged and checked) before any file is written.
  gi::ReferenceOutputs outputs;
  if (o.merge) {
    job.settings.progress = bar.stage("merge");
    auto merged = gi::merge_reference_shards(input, job, o.shard_dir);
    bar.finish();
    if (!merged) return tools::fail(kTool, merged.error());
    outputs = std::move(merged).value();
    std::printf("merged the shards in %s\n", o.shard_dir.c_str());
  }
  if (!distributed)
    if (auto rc = render_locally(o, input, job, bar, outputs)) return *rc;
  if (auto rc = write_outputs(o, outputs)) return *rc;
  return tools::kExitOk;
}
