#pragma once
// What gi-frame-truth writes: the images of each compared view (to look at where the error
// lies) and its rows of the measurement table, as Markdown and CSV.
//   write_truth_images(dir, "sponza_high_floor", truth, 0.0f);   // 0: exposure from the truth
//   std::string md = markdown_header() + markdown_rows(run, report);

#include <engine/result.h>
#include <gi/frame_truth.h>

#include <filesystem>
#include <string>

namespace frame_truth_tool {

/// What a table row says besides the report's numbers.
struct RunInfo {
  std::string label;  ///< The run's name (the tool's --label).
  std::string gi;     ///< The bake: "preview", "medium", "high", or the bundle's path.
  int width = 0;
  int height = 0;
  int samples_per_pixel = 0;  ///< The truth's, both halves.
};

/// 0.18 / the geometric mean of the truth's luminance over the surface pixels: a middle
/// grey for the view's typical surface (an exposure for PNGs of any scene).
float exposure_for(const gi::FrameTruth& truth);

/// Writes <dir>/<stem>_truth.exr and .png (exposure; <= 0: exposure_for) and _regions.png
/// (each region one colour, "other" grey, background black).
engine::Status write_truth_images(const std::filesystem::path& dir, const std::string& stem,
                                  const gi::FrameTruth& truth, float exposure);

/// Writes <dir>/<stem>_frame.exr and .png (the truth's exposure, as above) and _ratio.png
/// (gi::ratio_image, +-2 stops).
engine::Status write_frame_images(const std::filesystem::path& dir, const std::string& stem,
                                  const gi::FrameTruthReport& report, const gi::FrameTruth& truth, float exposure);

/// The Markdown table's header lines and one row per region (then "other", then the frame).
std::string markdown_header();
std::string markdown_rows(const RunInfo& run, const gi::FrameTruthReport& report);

/// The CSV's header line and one line per region, then "other", then the frame.
std::string csv_header();
std::string csv_rows(const RunInfo& run, const gi::FrameTruthReport& report);

}  // namespace frame_truth_tool
