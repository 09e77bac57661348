#include "frame_truth_output.h"

#include <engine/display_transform.h>
#include <engine/image.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace frame_truth_tool {
namespace {

double luminance(const float* p) { return 0.2126 * double{p[0]} + 0.7152 * double{p[1]} + 0.0722 * double{p[2]}; }

engine::ImageRgba8 display(const engine::ImageRgbaF& image, float exposure) {
  engine::ImageRgba8 out{.width = image.width, .height = image.height, .pixels = {}};
  out.pixels.resize(image.pixels.size());
  for (std::size_t i = 0; i < image.pixels.size(); ++i) {
    const double v = image.pixels[i];
    out.pixels[i] = i % 4 == 3 ? 255
                               : static_cast<std::uint8_t>(std::lround(
                                     255.0 * (std::isfinite(v) ? engine::display_tonemap(v, exposure) : 0.0)));
  }
  return out;
}

engine::ImageRgba8 region_map(const gi::FrameTruth& truth) {
  // Distinct colours for the first regions; "other" grey, the background black.
  static const std::uint8_t kColours[][3] = {{230, 159, 0}, {86, 180, 233}, {0, 158, 115},  {240, 228, 66},
                                             {0, 114, 178}, {213, 94, 0},   {204, 121, 167}};
  const std::size_t other = truth.regions.size();
  engine::ImageRgba8 out{.width = truth.image.width, .height = truth.image.height, .pixels = {}};
  out.pixels.assign(truth.region_of_pixel.size() * 4, 255);
  for (std::size_t i = 0; i < truth.region_of_pixel.size(); ++i) {
    const std::uint8_t r = truth.region_of_pixel[i];
    std::uint8_t* o = &out.pixels[4 * i];
    if (r == gi::kBackgroundPixel) {
      o[0] = o[1] = o[2] = 0;
    } else if (r == other) {
      o[0] = o[1] = o[2] = 128;
    } else {
      const auto* c = kColours[r % (sizeof kColours / sizeof kColours[0])];
      o[0] = c[0], o[1] = c[1], o[2] = c[2];
    }
  }
  return out;
}

// The table's number forms; "n/a" for NaN (a region without pixels or light).
enum class Form { Significant3, Fixed3, SignedPercent, Percent };
std::string number(Form form, double v) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  switch (form) {
    case Form::Significant3:
      std::snprintf(buf, sizeof buf, "%.3g", v);
      break;
    case Form::Fixed3:
      std::snprintf(buf, sizeof buf, "%.3f", v);
      break;
    case Form::SignedPercent:
      std::snprintf(buf, sizeof buf, "%+.1f%%", 100.0 * v);
      break;
    case Form::Percent:
      std::snprintf(buf, sizeof buf, "%.1f%%", 100.0 * v);
      break;
  }
  return buf;
}

std::vector<const gi::RegionAccuracy*> rows_of(const gi::FrameTruthReport& report) {
  std::vector<const gi::RegionAccuracy*> rows;
  for (const gi::RegionAccuracy& r : report.regions) rows.push_back(&r);
  rows.push_back(&report.overall);
  return rows;
}

}  // namespace

float exposure_for(const gi::FrameTruth& truth) {
  double sum_log = 0.0, sum = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < truth.region_of_pixel.size(); ++i)
    if (truth.region_of_pixel[i] != gi::kBackgroundPixel) sum += luminance(&truth.image.pixels[4 * i]), ++n;
  const double floor = 1e-6 * std::max(sum / static_cast<double>(std::max<std::size_t>(n, 1)), 1e-12);
  for (std::size_t i = 0; i < truth.region_of_pixel.size(); ++i) {
    if (truth.region_of_pixel[i] == gi::kBackgroundPixel) continue;
    const double l = luminance(&truth.image.pixels[4 * i]);
    sum_log += std::log(std::isfinite(l) ? std::max(l, floor) : floor);
  }
  return n == 0 ? 1.0f : static_cast<float>(0.18 / std::exp(sum_log / static_cast<double>(n)));
}

engine::Status write_truth_images(const std::filesystem::path& dir, const std::string& stem,
                                  const gi::FrameTruth& truth, float exposure) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return engine::Error{dir.string(), "", "cannot create the folder: " + ec.message()};
  const float e = exposure > 0.0f ? exposure : exposure_for(truth);
  const std::string base = (dir / stem).string();
  for (const engine::Status& s : {engine::save_exr(base + "_truth.exr", truth.image),
                                  engine::save_png(base + "_truth.png", display(truth.image, e)),
                                  engine::save_png(base + "_regions.png", region_map(truth))})
    if (!s) return s;
  return {};
}

engine::Status write_frame_images(const std::filesystem::path& dir, const std::string& stem,
                                  const gi::FrameTruthReport& report, const gi::FrameTruth& truth, float exposure) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return engine::Error{dir.string(), "", "cannot create the folder: " + ec.message()};
  const float e = exposure > 0.0f ? exposure : exposure_for(truth);
  const std::string base = (dir / stem).string();
  for (const engine::Status& s : {engine::save_exr(base + "_frame.exr", report.frame),
                                  engine::save_png(base + "_frame.png", display(report.frame, e)),
                                  engine::save_png(base + "_ratio.png", gi::ratio_image(report, 2.0f))})
    if (!s) return s;
  return {};
}

std::string markdown_header() {
  return "| run | GI | camera | region | pixels | frame L | truth L | bias (± truth noise) | rel RMSE | truth rel RMSE "
         "| "
         "reference noise |\n"
         "|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|\n";
}

std::string markdown_rows(const RunInfo& run, const gi::FrameTruthReport& report) {
  std::string out;
  for (const gi::RegionAccuracy* r : rows_of(report)) {
    const bool frame = r == &report.overall;
    const std::string region = frame ? "**frame**" : r->name;
    out += "| " + run.label + " | " + run.gi + " | " + report.camera + " | " + region + " | " +
           std::to_string(r->pixels) + " | " + number(Form::Significant3, r->frame_luminance) + " | " +
           number(Form::Significant3, r->truth_luminance) + " | " + number(Form::SignedPercent, r->bias) + " (± " +
           number(Form::Percent, r->bias_noise) + ") | " + number(Form::Fixed3, r->rel_rmse) + " | " +
           number(Form::Fixed3, r->truth_rel_rmse) + " | " + number(Form::Fixed3, r->reference_noise) + " |\n";
  }
  return out;
}

std::string csv_header() {
  return "run,gi,camera,region,width,height,spp,pixels,frame_luminance,truth_luminance,bias,bias_noise,rel_rmse,"
         "truth_rel_rmse,reference_noise,frame_ms,first_frame_ms,truth_seconds\n";
}

std::string csv_rows(const RunInfo& run, const gi::FrameTruthReport& report) {
  std::string out;
  for (const gi::RegionAccuracy* r : rows_of(report)) {
    char buf[512];
    std::snprintf(buf, sizeof buf, "%s,%s,%s,%s,%d,%d,%d,%zu,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.3f,%.3f,%.2f\n",
                  run.label.c_str(), run.gi.c_str(), report.camera.c_str(), r->name.c_str(), run.width, run.height,
                  run.samples_per_pixel, r->pixels, r->frame_luminance, r->truth_luminance, r->bias, r->bias_noise,
                  r->rel_rmse, r->truth_rel_rmse, r->reference_noise, report.cost.frame_ms, report.cost.first_frame_ms,
                  report.truth_seconds);
    out += buf;
  }
  return out;
}

}  // namespace frame_truth_tool
