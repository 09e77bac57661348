// gi-replay-quality: one recorded session replayed with GI bakes of different quality, each
// frame timed and selected frames compared with the reference path tracer rendering the same
// state (docs/replay_quality.md).
//   gi-replay-quality --session tests/sessions/walk_flashlight.girec --bundle none
//       --bundle preview=out/dl_preview.gibake --bundle medium=out/dl_medium.gibake
//       --frames 150,300,450 --spp 256 --out docs/replay_quality.md [--images out/rq]
// --images DIR also writes each compared frame as linear half-float EXR and a PNG at the
// demo's exposure (ref_f<N>, <name>_f<N>) and each row's luminance ratio to the reference
// (<name>_f<N>_diff.png), to see where a row's error lies.
// "none" is the renderer's constant-ambient stand-in. The error is the relative RMSE of linear
// radiance over the frame (the renderer's HDR target against the path tracer's image), so it
// includes the rasterizer's own approximations (shadow maps, light falloff), which the
// stand-in row shows on its own. The path tracer's camera rays pass through the pixel centres,
// as the rasterizer's do (no anti-aliasing on either side: an edge of the bright ceiling
// panel would otherwise count as error). Each error is also given against the noise-free truth the
// path tracer estimates (its per-pixel variance removed, gi/error_metrics.h): at a few hundred
// samples per pixel the reference's own noise is a large part of the plain figure in rooms lit
// only indirectly.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <engine/gpu/context.h>
#include <engine/image.h>
#include <engine/renderer.h>
#include <game_demo/replay.h>
#include <game_demo/session_file.h>
#include <game_demo/simulation.h>
#include <gi/error_metrics.h>
#include <gi/gi_system.h>
#include <gi/reference.h>
#include <gi/rgb_field.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <sstream>
#include <CLI/CLI.hpp>

#include "tool_main.h"

namespace {

constexpr const char* kTool = "gi-replay-quality";

// Non-finite pixels are masked out (and counted): one NaN would make the whole frame's error NaN.
gi::RgbField field_of(const engine::ImageRgbaF& image, std::size_t* non_finite = nullptr) {
  std::vector<glm::vec3> v(static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height));
  std::vector<std::uint8_t> valid(v.size(), 1);
  for (std::size_t i = 0; i < v.size(); ++i) {
    v[i] = {image.pixels[4 * i], image.pixels[4 * i + 1], image.pixels[4 * i + 2]};
    if (!std::isfinite(v[i].x) || !std::isfinite(v[i].y) || !std::isfinite(v[i].z)) {
      v[i] = glm::vec3(0.0f);
      valid[i] = 0;
      if (non_finite) {
        if (*non_finite < 3)
          std::fprintf(stderr, "  non-finite pixel at (%zu, %zu)\n", i % static_cast<std::size_t>(image.width),
                       i / static_cast<std::size_t>(image.width));
        ++*non_finite;
      }
    }
  }
  return gi::RgbField::from_texels(image.width, image.height, v, valid);
}

// The reference's mask applied to a render too (and the render's own non-finite pixels).
gi::RgbField masked(gi::RgbField f, const gi::RgbField& reference) {
  for (std::size_t i = 0; i < f.valid.size() && i < reference.valid.size(); ++i)
    if (!reference.is_valid(i)) f.valid[i] = 0;
  return f;
}

struct Row {
  std::string name, bundle;
  double mean_ms = 0.0, p95_ms = 0.0;
  std::vector<double> errors;        ///< Relative RMSE against the reference, per compared frame.
  std::vector<double> truth_errors;  ///< The same against the noise-free truth (the reference's variance removed).
  std::uint64_t gi_idle = 0, gi_frames = 0;
};

// Writes DIR/<name>_f<frame>.exr (linear) and .png (the demo's exposure, clamped, sRGB) when
// --images is given; false (after saying why) on failure.
bool save_frame(const std::string& dir, const std::string& name, std::uint64_t frame, const engine::ImageRgbaF& image) {
  if (dir.empty()) return true;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::filesystem::path base = std::filesystem::path(dir) / (name + "_f" + std::to_string(frame));
  engine::ImageRgba8 png{.width = image.width, .height = image.height, .pixels = {}};
  png.pixels.resize(image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const float v = i % 4 == 3 ? 1.0f : std::clamp(image.pixels[i] * game_demo::kDemoExposure, 0.0f, 1.0f);
    const float srgb = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
    png.pixels[i] = static_cast<std::uint8_t>(std::lround(255.0f * (std::isfinite(srgb) ? srgb : 0.0f)));
  }
  for (const engine::Status& st :
       {engine::save_exr(base.string() + ".exr", image), engine::save_png(base.string() + ".png", png)})
    if (!st) {
      std::cerr << "gi-replay-quality: " << st.error().to_string() << '\n';
      return false;
    }
  return true;
}

// DIR/<name>_f<frame>_diff.png: each pixel's luminance against the reference's, log2 ratio
// from -1 (blue: half as bright) through white to +1 (red: twice as bright).
bool save_difference(const std::string& dir, const std::string& name, std::uint64_t frame,
                     const engine::ImageRgbaF& mine, const gi::RgbField& ref) {
  if (dir.empty()) return true;
  engine::ImageRgba8 png{.width = mine.width, .height = mine.height, .pixels = {}};
  png.pixels.assign(mine.pixels.size(), 255);
  for (std::size_t p = 0; p * 4 < mine.pixels.size() && 3 * p + 2 < ref.rgb.size(); ++p) {
    const float* m = &mine.pixels[4 * p];
    const float lm = 0.2126f * m[0] + 0.7152f * m[1] + 0.0722f * m[2];
    const float* r = &ref.rgb[3 * p];
    const float lr = 0.2126f * r[0] + 0.7152f * r[1] + 0.0722f * r[2];
    const float t = std::clamp(std::log2((lm + 1e-3f) / (lr + 1e-3f)), -1.0f, 1.0f);
    const auto fade = static_cast<std::uint8_t>(std::lround(255.0f * (1.0f - std::fabs(t))));
    std::uint8_t* o = &png.pixels[4 * p];
    o[0] = t < 0.0f ? fade : 255;
    o[1] = fade;
    o[2] = t > 0.0f ? fade : 255;
  }
  const std::filesystem::path path = std::filesystem::path(dir) / (name + "_f" + std::to_string(frame) + "_diff.png");
  if (const engine::Status st = engine::save_png(path, png); !st) {
    std::cerr << "gi-replay-quality: " << st.error().to_string() << '\n';
    return false;
  }
  return true;
}

// The tool's command line.
struct Options {
  std::string session_path, out_path, images_dir, frames_text = "150,300,450";
  std::vector<std::string> bundles;
  int width = 320, height = 180, spp = 256;
};

// The frames of "--frames a,b,c", sorted; nullopt when one is not a number.
std::optional<std::vector<std::uint64_t>> parse_frames(const std::string& frames_text) {
  std::vector<std::uint64_t> picked;
  std::stringstream ss(frames_text);
  for (std::string f; std::getline(ss, f, ',');) {
    std::uint64_t frame = 0;
    const auto [end, ec] = std::from_chars(f.data(), f.data() + f.size(), frame);
    if (ec != std::errc{} || end != f.data() + f.size()) return std::nullopt;
    picked.push_back(frame);
  }
  std::sort(picked.begin(), picked.end());
  return picked;
}

// The reference of one frame: the path tracer's mean of two independent halves (seeds 1 and
// 2) with, per pixel, (a - b)^2 / 4 as its sampling variance (an unbiased estimate, so the
// table can also give each row's error against the noise-free truth: gi::compare_rgb,
// truth_rel_rmse). Returns the process's exit code on failure, 0 when done.
int render_reference_frame(const game_demo::Simulation& sim, const Options& o, std::uint64_t f,
                           std::map<std::uint64_t, gi::RgbField>& reference) {
  const auto t0 = std::chrono::steady_clock::now();
  engine::ImageRgbaF half[2];
  for (int h = 0; h < 2; ++h) {
    gi::ReferenceSettings rs;
    rs.samples_per_pixel = std::max(1, o.spp / 2);
    rs.seed = static_cast<std::uint64_t>(h + 1);
    rs.jitter_pixels = false;  // through the pixel centres, as the rasterizer samples: light, not aliasing
    rs.progress = [](double) { return !tools::interrupted(); };
    auto image = gi::render_reference_image(sim.scene(), sim.context().camera, o.width, o.height, rs);
    if (!image) return tools::fail(kTool, image.error());
    half[h] = std::move(image).value();
  }
  engine::ImageRgbaF image = half[0];
  for (std::size_t i = 0; i < image.pixels.size(); ++i)
    image.pixels[i] = 0.5f * (half[0].pixels[i] + half[1].pixels[i]);
  if (!save_frame(o.images_dir, "ref", f, image)) return 1;
  std::size_t bad = 0;
  gi::RgbField field = field_of(image, &bad);
  field.variance.assign(field.rgb.size(), 0.0f);
  for (std::size_t p = 0; 4 * p < image.pixels.size(); ++p)
    for (std::size_t c = 0; c < 3; ++c) {
      const float d = half[0].pixels[4 * p + c] - half[1].pixels[4 * p + c];
      field.variance[3 * p + c] = std::isfinite(d) ? 0.25f * d * d : 0.0f;
    }
  reference.emplace(f, std::move(field));
  std::printf("reference frame %llu: %.1f s, %zu non-finite pixels masked\n", static_cast<unsigned long long>(f),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), bad);
  std::fflush(stdout);
  return 0;
}

// A row's "NAME=DIR[,light-reach=...][,area-shadows=...][,area-shadow-res=...]", split.
struct RowSpec {
  Row row;
  engine::AreaShadowRes area_shadow_res = engine::AreaShadowRes::Half;
  bool area_soft_shadows = true;
  bool light_reach = true;
};

// The spec of one --bundle; returns the process's exit code on failure (after saying why), 0 when done.
int parse_row_spec(const std::string& spec, RowSpec& out) {
  Row& row = out.row;
  const std::size_t eq = spec.find('=');
  row.name = eq == std::string::npos ? spec : spec.substr(0, eq);
  row.bundle = eq == std::string::npos ? "" : spec.substr(eq + 1);
  // ",area-shadow-res=full|half" (RenderSettings::area_shadow_res, default half), last.
  if (const std::size_t opt = row.bundle.find(",area-shadow-res="); opt != std::string::npos) {
    const std::string value = row.bundle.substr(opt + 17);
    if (value != "full" && value != "half") {
      std::cerr << "gi-replay-quality: area-shadow-res must be full or half, not '" << value << "'\n";
      return 2;
    }
    out.area_shadow_res = value == "half" ? engine::AreaShadowRes::Half : engine::AreaShadowRes::Full;
    row.bundle = row.bundle.substr(0, opt);
  }
  // Renderer choices after the bundle: ",area-shadows=centre" (RenderSettings::area_soft_shadows off).
  if (const std::size_t opt = row.bundle.find(",area-shadows="); opt != std::string::npos) {
    const std::string value = row.bundle.substr(opt + 14);
    if (value != "soft" && value != "centre") {
      std::cerr << "gi-replay-quality: area-shadows must be soft or centre, not '" << value << "'\n";
      return 2;
    }
    out.area_soft_shadows = value == "soft";
    row.bundle = row.bundle.substr(0, opt);
  }
  // ",light-reach=off" (RenderSettings::light_reach_culling off), before ",area-shadows=".
  if (const std::size_t opt = row.bundle.find(",light-reach="); opt != std::string::npos) {
    const std::string value = row.bundle.substr(opt + 13);
    if (value != "on" && value != "off") {
      std::cerr << "gi-replay-quality: light-reach must be on or off, not '" << value << "'\n";
      return 2;
    }
    out.light_reach = value == "on";
    row.bundle = row.bundle.substr(0, opt);
  }
  if (row.bundle == "none") row.bundle.clear();
  return 0;
}

// Replays the session with one row's bundle and renderer choices, timing every frame and
// comparing the picked ones with the reference. Returns the process's exit code on failure, 0 when done.
int replay_row(const game_demo::Session& session, const Options& o, std::uint64_t last,
               const std::map<std::uint64_t, gi::RgbField>& reference, RowSpec& spec,
               std::map<std::uint64_t, double>& reference_noise) {
  Row& row = spec.row;
  auto sim = game_demo::simulation_for_session(session, o.session_path);
  if (!sim) {
    std::cerr << "gi-replay-quality: " << sim.error().to_string() << '\n';
    return 1;
  }
  std::unique_ptr<gi::GISystem> gi;
  if (!row.bundle.empty()) {
    auto loaded = gi::GISystem::load(row.bundle, sim->scene());
    if (!loaded) {
      std::cerr << "gi-replay-quality: " << loaded.error().to_string() << '\n';
      return 1;
    }
    gi = std::move(loaded).value();
  }
  auto renderer =
      engine::Renderer::create(sim->scene().assets, engine::RenderSettings{.width = o.width,
                                                                           .height = o.height,
                                                                           .exposure = game_demo::kDemoExposure,
                                                                           .area_soft_shadows = spec.area_soft_shadows,
                                                                           .area_shadow_res = spec.area_shadow_res,
                                                                           .light_reach_culling = spec.light_reach});
  if (!renderer) {
    std::cerr << "gi-replay-quality: " << renderer.error().to_string() << '\n';
    return 1;
  }
  (*renderer)->set_indirect_light(gi.get());
  std::vector<double> ms;
  for (std::uint64_t f = 0; f <= last; ++f) {
    if (tools::interrupted()) return tools::kExitCancelled;
    sim->step(session.frames[f].input);
    const auto t0 = std::chrono::steady_clock::now();
    (*renderer)->render(sim->registry(), sim->context().camera);
    glFinish();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    if (const auto it = reference.find(f); it != reference.end()) {
      const engine::ImageRgbaF hdr = (*renderer)->read_hdr();
      if (!save_frame(o.images_dir, row.name, f, hdr)) return 1;
      std::size_t bad = 0;
      gi::RgbField mine = masked(field_of(hdr, &bad), it->second);
      if (!save_difference(o.images_dir, row.name, f, hdr, it->second)) return 1;
      gi::RgbField ref = it->second;
      for (std::size_t i = 0; i < ref.valid.size(); ++i)
        if (!mine.is_valid(i)) ref.valid[i] = 0;
      if (bad > 0)
        std::printf("%s frame %llu: %zu non-finite pixels masked\n", row.name.c_str(),
                    static_cast<unsigned long long>(f), bad);
      const gi::ErrorReport e = gi::compare_rgb(mine, ref);
      row.errors.push_back(e.rel_rmse);
      row.truth_errors.push_back(e.truth_rel_rmse);
      reference_noise[f] = e.reference_noise;
    }
  }
  row.mean_ms = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(ms.size());
  std::sort(ms.begin(), ms.end());
  row.p95_ms = ms[static_cast<std::size_t>(0.95 * static_cast<double>(ms.size() - 1))];
  if (gi) row.gi_idle = gi->stats().idle_frames, row.gi_frames = gi->stats().frames;
  return 0;
}

// The Markdown table. Each cell: relative RMSE against the path tracer's image, and in
// brackets against the truth it estimates (its sampling noise removed; see gi/error_metrics.h).
std::string markdown_table(const std::vector<Row>& rows, const std::vector<std::uint64_t>& picked,
                           const std::map<std::uint64_t, double>& reference_noise, int spp) {
  std::ostringstream md;
  md << "| GI | frame ms (mean / p95) | GI idle frames |";
  for (std::uint64_t f : picked) md << " rel RMSE f" << f << " (truth) |";
  md << " mean rel RMSE (truth) |\n|---|---|---|";
  for (std::size_t i = 0; i < picked.size(); ++i) md << "---|";
  md << "---|\n";
  for (const Row& r : rows) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "| %s | %.1f / %.1f | %llu of %llu |", r.name.c_str(), r.mean_ms, r.p95_ms,
                  static_cast<unsigned long long>(r.gi_idle), static_cast<unsigned long long>(r.gi_frames));
    md << buf;
    double sum = 0.0, truth_sum = 0.0;
    for (std::size_t i = 0; i < r.errors.size(); ++i) {
      std::snprintf(buf, sizeof buf, " %.3f (%.3f) |", r.errors[i], r.truth_errors[i]);
      md << buf;
      sum += r.errors[i];
      truth_sum += r.truth_errors[i];
    }
    const double n = static_cast<double>(std::max<std::size_t>(r.errors.size(), 1));
    std::snprintf(buf, sizeof buf, " %.3f (%.3f) |\n", sum / n, truth_sum / n);
    md << buf;
  }
  md << "\nThe reference's own noise (relative RMSE of its sampling variance, estimated from two independent halves "
        "of its samples):";
  for (const auto& [f, noise] : reference_noise) {
    char buf[64];
    std::snprintf(buf, sizeof buf, " f%llu %.3f;", static_cast<unsigned long long>(f), noise);
    md << buf;
  }
  md << " at " << spp << " samples per pixel.\n";
  return md.str();
}

void add_options(CLI::App& app, Options& o) {
  app.add_option("--session", o.session_path, "Recorded session (.girec)")->required()->check(CLI::ExistingFile);
  app.add_option("--bundle", o.bundles,
                 "NAME=DIR of a bake bundle, or 'none' for the stand-in (repeatable); NAME=DIR,area-shadows=centre "
                 "shadows area lights from their centre only (default soft); "
                 "NAME=DIR,light-reach=off[,area-shadows=...][,area-shadow-res=full|half] "
                 "shades every light on every pixel (default on)")
      ->required();
  app.add_option("--frames", o.frames_text, "Comma-separated frames compared with the path tracer");
  app.add_option("--width", o.width)->check(CLI::Range(16, 4096));
  app.add_option("--height", o.height)->check(CLI::Range(16, 4096));
  app.add_option("--spp", o.spp, "Path-tracer samples per pixel of the reference frames")->check(CLI::PositiveNumber);
  app.add_option("--out", o.out_path, "Markdown table to write (also printed)");
  app.add_option("--images", o.images_dir, "Directory for the compared frames as EXR (reference and each row)");
}

// Replays the session once, rendering the reference of every picked frame; returns the
// process's exit code on failure, 0 when done.
int render_references(const game_demo::Session& session, const Options& o, const std::vector<std::uint64_t>& picked,
                      std::map<std::uint64_t, gi::RgbField>& reference) {
  auto sim = game_demo::simulation_for_session(session, o.session_path);
  if (!sim) {
    std::cerr << "gi-replay-quality: " << sim.error().to_string() << '\n';
    return 1;
  }
  for (std::uint64_t f = 0; f <= picked.back(); ++f) {
    sim->step(session.frames[f].input);
    if (!std::binary_search(picked.begin(), picked.end(), f)) continue;
    if (const int rc = render_reference_frame(*sim, o, f, reference); rc != 0) return rc;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  CLI::App app{
      "Replays a session with GI bakes of different quality: frame time vs image error against the path tracer"};
  add_options(app, o);
  // The tools' host contract (tools/common/tool_main.h): --version, exit 0 done, 1 failed,
  // 2 bad usage, 130 Ctrl-C (stops at the next frame or reference sample pass; --out unwritten).
  if (const std::optional<int> rc = tools::parse(app, kTool, argc, argv)) return *rc;
  tools::install_interrupt_handler();

  const std::optional<std::vector<std::uint64_t>> frames = parse_frames(o.frames_text);
  if (!frames)
    return tools::fail(kTool, "--frames wants comma-separated frame numbers, not '" + o.frames_text + "'",
                       tools::kExitUsage);
  const std::vector<std::uint64_t>& picked = *frames;
  if (picked.empty()) return tools::fail(kTool, "--frames names no frame", tools::kExitUsage);
  auto session = game_demo::load_session(o.session_path);
  if (!session) {
    std::cerr << "gi-replay-quality: " << session.error().to_string() << '\n';
    return 1;
  }
  const std::uint64_t last = picked.back();
  if (last >= session->frames.size()) {
    std::cerr << "gi-replay-quality: frame " << last << " is past the session's " << session->frames.size()
              << " frames\n";
    return 2;
  }

  // Reference: the path tracer at each picked frame of the replayed state.
  std::map<std::uint64_t, gi::RgbField> reference;
  if (const int rc = render_references(*session, o, picked, reference); rc != 0) return rc;

  auto gpu = engine::GpuContext::create_headless();
  if (!gpu) {
    std::cerr << "gi-replay-quality: " << gpu.error().to_string() << '\n';
    return 1;
  }
  std::vector<Row> rows;
  std::map<std::uint64_t, double> reference_noise;  // relative RMSE of the reference's own noise, per frame
  for (const std::string& bundle : o.bundles) {
    RowSpec spec;
    if (const int rc = parse_row_spec(bundle, spec); rc != 0) return rc;
    if (const int rc = replay_row(*session, o, last, reference, spec, reference_noise); rc != 0) return rc;
    rows.push_back(spec.row);
    std::printf("%s: %.2f ms mean per frame\n", spec.row.name.c_str(), spec.row.mean_ms);
  }

  const std::string md = markdown_table(rows, picked, reference_noise, o.spp);
  std::cout << md;
  if (!o.out_path.empty()) {
    std::ofstream out(o.out_path);
    out << md;
    if (!out) {
      std::cerr << "gi-replay-quality: cannot write " << o.out_path << '\n';
      return 1;
    }
  }
  return 0;
}
