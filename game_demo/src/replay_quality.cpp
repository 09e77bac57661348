// gi-replay-quality: one recorded session replayed with GI bakes of different quality, each
// frame timed and selected frames compared with the reference path tracer rendering the same
// state (docs/replay_quality.md).
//   gi-replay-quality --session tests/sessions/walk_flashlight.girec --bundle none
//       --bundle preview=out/dl_preview.gibake --bundle medium=out/dl_medium.gibake
//       --frames 150,300,450 --spp 256 --out docs/replay_quality.md [--images out/rq]
// --images DIR also writes each compared frame as linear half-float EXR (ref_f<N>.exr and
// <name>_f<N>.exr), to see where a row's error lies.
// "none" is the renderer's constant-ambient stand-in. The error is the relative RMSE of linear
// radiance over the frame (the renderer's HDR target against the path tracer's image), so it
// includes the rasterizer's own approximations (shadow maps, light falloff), which the
// stand-in row shows on its own.
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>
#include <engine/gpu/context.h>
#include <engine/renderer.h>
#include <game_demo/replay.h>
#include <game_demo/session_file.h>
#include <game_demo/simulation.h>
#include <gi/error_metrics.h>
#include <gi/gi_system.h>
#include <gi/reference.h>
#include <gi/rgb_field.h>
#include <engine/image.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <numeric>
#include <sstream>

namespace {

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
  std::vector<double> errors;
  std::uint64_t gi_idle = 0, gi_frames = 0;
};

// Writes DIR/<name>_f<frame>.exr when --images is given; false (after saying why) on failure.
bool save_frame(const std::string& dir, const std::string& name, std::uint64_t frame, const engine::ImageRgbaF& image) {
  if (dir.empty()) return true;
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  const std::filesystem::path path = std::filesystem::path(dir) / (name + "_f" + std::to_string(frame) + ".exr");
  if (const engine::Status st = engine::save_exr(path, image); !st) {
    std::cerr << "gi-replay-quality: " << st.error().to_string() << '\n';
    return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  std::string session_path, out_path, images_dir, frames_text = "150,300,450";
  std::vector<std::string> bundles;
  int width = 320, height = 180, spp = 256;
  CLI::App app{
      "Replays a session with GI bakes of different quality: frame time vs image error against the path tracer"};
  app.add_option("--session", session_path, "Recorded session (.girec)")->required()->check(CLI::ExistingFile);
  app.add_option("--bundle", bundles,
                 "NAME=DIR of a bake bundle, or 'none' for the stand-in (repeatable); NAME=DIR,area-shadows=centre "
                 "shadows area lights from their centre only (default soft)")
      ->required();
  app.add_option("--frames", frames_text, "Comma-separated frames compared with the path tracer");
  app.add_option("--width", width)->check(CLI::Range(16, 4096));
  app.add_option("--height", height)->check(CLI::Range(16, 4096));
  app.add_option("--spp", spp, "Path-tracer samples per pixel of the reference frames")->check(CLI::PositiveNumber);
  app.add_option("--out", out_path, "Markdown table to write (also printed)");
  app.add_option("--images", images_dir, "Directory for the compared frames as EXR (reference and each row)");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::uint64_t> picked;
  std::stringstream ss(frames_text);
  for (std::string f; std::getline(ss, f, ',');) picked.push_back(std::stoull(f));
  std::sort(picked.begin(), picked.end());
  auto session = game_demo::load_session(session_path);
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
  {
    auto sim = game_demo::simulation_for_session(*session, session_path);
    if (!sim) {
      std::cerr << "gi-replay-quality: " << sim.error().to_string() << '\n';
      return 1;
    }
    for (std::uint64_t f = 0; f <= last; ++f) {
      sim->step(session->frames[f].input);
      if (!std::binary_search(picked.begin(), picked.end(), f)) continue;
      const auto t0 = std::chrono::steady_clock::now();
      gi::ReferenceSettings rs;
      rs.samples_per_pixel = spp;
      auto image = gi::render_reference_image(sim->scene(), sim->context().camera, width, height, rs);
      if (!image) {
        std::cerr << "gi-replay-quality: " << image.error().to_string() << '\n';
        return 1;
      }
      if (!save_frame(images_dir, "ref", f, *image)) return 1;
      std::size_t bad = 0;
      reference.emplace(f, field_of(*image, &bad));
      std::printf("reference frame %llu: %.1f s, %zu non-finite pixels masked\n", static_cast<unsigned long long>(f),
                  std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), bad);
      std::fflush(stdout);
    }
  }

  auto gpu = engine::GpuContext::create_headless();
  if (!gpu) {
    std::cerr << "gi-replay-quality: " << gpu.error().to_string() << '\n';
    return 1;
  }
  std::vector<Row> rows;
  for (const std::string& spec : bundles) {
    Row row;
    const std::size_t eq = spec.find('=');
    row.name = eq == std::string::npos ? spec : spec.substr(0, eq);
    row.bundle = eq == std::string::npos ? "" : spec.substr(eq + 1);
    // Renderer choices after the bundle: ",area-shadows=centre" (RenderSettings::area_soft_shadows off).
    bool area_soft_shadows = true;
    if (const std::size_t opt = row.bundle.find(",area-shadows="); opt != std::string::npos) {
      const std::string value = row.bundle.substr(opt + 14);
      if (value != "soft" && value != "centre") {
        std::cerr << "gi-replay-quality: area-shadows must be soft or centre, not '" << value << "'\n";
        return 2;
      }
      area_soft_shadows = value == "soft";
      row.bundle = row.bundle.substr(0, opt);
    }
    if (row.bundle == "none") row.bundle.clear();
    auto sim = game_demo::simulation_for_session(*session, session_path);
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
    auto renderer = engine::Renderer::create(
        sim->scene().assets,
        engine::RenderSettings{.width = width, .height = height, .exposure = game_demo::kDemoExposure,
                               .area_soft_shadows = area_soft_shadows});
    if (!renderer) {
      std::cerr << "gi-replay-quality: " << renderer.error().to_string() << '\n';
      return 1;
    }
    (*renderer)->set_indirect_light(gi.get());
    std::vector<double> ms;
    for (std::uint64_t f = 0; f <= last; ++f) {
      sim->step(session->frames[f].input);
      const auto t0 = std::chrono::steady_clock::now();
      (*renderer)->render(sim->registry(), sim->context().camera);
      glFinish();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      if (const auto it = reference.find(f); it != reference.end()) {
        const engine::ImageRgbaF hdr = (*renderer)->read_hdr();
        if (!save_frame(images_dir, row.name, f, hdr)) return 1;
        std::size_t bad = 0;
        gi::RgbField mine = masked(field_of(hdr, &bad), it->second);
        gi::RgbField ref = it->second;
        for (std::size_t i = 0; i < ref.valid.size(); ++i)
          if (!mine.is_valid(i)) ref.valid[i] = 0;
        if (bad > 0)
          std::printf("%s frame %llu: %zu non-finite pixels masked\n", row.name.c_str(),
                      static_cast<unsigned long long>(f), bad);
        row.errors.push_back(gi::relative_rmse(mine, ref));
      }
    }
    row.mean_ms = std::accumulate(ms.begin(), ms.end(), 0.0) / static_cast<double>(ms.size());
    std::sort(ms.begin(), ms.end());
    row.p95_ms = ms[static_cast<std::size_t>(0.95 * static_cast<double>(ms.size() - 1))];
    if (gi) row.gi_idle = gi->stats().idle_frames, row.gi_frames = gi->stats().frames;
    rows.push_back(row);
    std::printf("%s: %.2f ms mean per frame\n", row.name.c_str(), row.mean_ms);
  }

  std::ostringstream md;
  md << "| GI | frame ms (mean / p95) | GI idle frames |";
  for (std::uint64_t f : picked) md << " rel RMSE f" << f << " |";
  md << " mean rel RMSE |\n|---|---|---|";
  for (std::size_t i = 0; i < picked.size(); ++i) md << "---|";
  md << "---|\n";
  for (const Row& r : rows) {
    char buf[128];
    std::snprintf(buf, sizeof buf, "| %s | %.1f / %.1f | %llu of %llu |", r.name.c_str(), r.mean_ms, r.p95_ms,
                  static_cast<unsigned long long>(r.gi_idle), static_cast<unsigned long long>(r.gi_frames));
    md << buf;
    double sum = 0.0;
    for (double e : r.errors) {
      std::snprintf(buf, sizeof buf, " %.3f |", e);
      md << buf;
      sum += e;
    }
    std::snprintf(buf, sizeof buf, " %.3f |\n", sum / static_cast<double>(std::max<std::size_t>(r.errors.size(), 1)));
    md << buf;
  }
  std::cout << md.str();
  if (!out_path.empty()) {
    std::ofstream out(out_path);
    out << md.str();
    if (!out) {
      std::cerr << "gi-replay-quality: cannot write " << out_path << '\n';
      return 1;
    }
  }
  return 0;
}
