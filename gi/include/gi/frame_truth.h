#pragma once
// A frame against the truth (target gi::sweep, the measuring harness): the renderer's frame
// of a scene lit with a bake bundle's GI, seen from a camera, against the reference path
// tracer's image of the same state, per world region the pixels show and over the frame.
//   auto gpu = engine::GpuContext::create_headless();   // a current GL context, first
//   auto bench = gi::FrameTruthBench::create(asset, "out/level.gibake", {.width = 240, .height = 135,
//       .samples_per_pixel = 256, .regions = {{"courtyard", {-5, 0, -3}, {5, 1, 3}}}});
//   auto r = bench.value()->compare({.name = "floor", .position_m = {-10, 1.7f, 0}, .target_m = {0, 2, 0}});
//   std::printf("bias %+.1f%%\n", 100.0 * r->overall.bias);
//
// The two sides see the same rays: the renderer rasterizes pixel centres and the path tracer
// traces one ray through each centre (ReferenceSettings::jitter_pixels false), so an edge is
// no error and a pixel's difference is light. The frame is the renderer's linear HDR target
// (before exposure and tonemapping). The truth is the mean of two path-traced halves with
// independent seeds (samples_per_pixel / 2 each): for two independent estimates a, b of a
// pixel's value, (a - b)^2 / 4 estimates the variance of their mean without bias, so every
// comparison also says its error against the noise-free truth (gi/error_metrics.h,
// truth_rel_rmse) and how much of a bias could be the truth's noise.
// Each pixel is classified by the world position of the path tracer's first hit through its
// centre (reference_first_hits), moved a little off the surface towards the camera (into the
// air the surface faces: the two faces of a thin wall then fall into the rooms they face):
// the first region box that holds that point, else "other"; pixels whose ray escapes (the
// sky) are background and compared nowhere.
// Textures: the bakers and the path tracer read them (docs/materials-in-bakes.md); a bundle
// baked --untextured is compared on the scene without_textures() gives, so both sides see
// the same materials.

#include <engine/image.h>
#include <engine/renderer.h>
#include <engine/result.h>
#include <engine/scene_asset.h>
#include <gi/progress.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// A named axis-aligned box of the world, metres: a pixel belongs to it when the point its
/// centre ray first hits, moved FrameTruthSettings::region_probe_m along the surface's normal
/// towards the camera, lies inside (bounds included).
struct WorldRegion {
  std::string name;
  glm::vec3 min_m{0.0f};
  glm::vec3 max_m{0.0f};
};

/// A pinhole camera at `position_m` looking at `target_m`, +Y up (+Z up when it looks
/// straight up or down), with a vertical field of view in radians; aspect = width / height.
struct FrameCamera {
  std::string name;
  glm::vec3 position_m{0.0f};
  glm::vec3 target_m{0.0f, 0.0f, -1.0f};
  float yfov_rad = 1.0f;
};

struct FrameTruthSettings {
  int width = 240;  ///< Pixels of both images.
  int height = 135;
  /// The truth's samples per pixel in total: two halves of samples_per_pixel / 2 (>= 2).
  int samples_per_pixel = 256;
  std::uint64_t seed = 1;  ///< The halves use seed and seed + 1.
  unsigned threads = 0;    ///< The path tracer's; 0: all hardware threads. Results do not depend on it.
  /// The renderer's fixed exposure (RenderSettings::exposure): only its LDR frame depends on
  /// it, the compared HDR frame does not.
  float exposure = 1.0f;
  /// Frames drawn before the timed ones (the first uploads the GI data and draws the
  /// shadow maps; a still scene's later frames are its steady cost).
  int warmup_frames = 2;
  /// Frames timed after the warm-up (>= 1): the cost is the median one's, so that a busy
  /// machine's odd frame does not make it. The compared frame is the last (all are the same).
  int timed_frames = 5;
  /// Checked in order, the first that holds the hit wins; at most 250.
  std::vector<WorldRegion> regions;
  /// How far off the surface (along its normal, towards the camera) a pixel's hit is
  /// classified, metres: thinner than any room, thicker than any wall's two coincident faces.
  float region_probe_m = 0.05f;
};

/// The accuracy of the frame over one set of pixels. Luminance is Rec. 709's
/// (0.2126 R + 0.7152 G + 0.0722 B) of linear radiance, W/(m^2 sr).
struct RegionAccuracy {
  std::string name;              ///< A region's, "other", or "frame" (every surface pixel).
  std::size_t pixels = 0;        ///< Compared pixels: a surface hit, finite on both sides.
  double frame_luminance = 0.0;  ///< Mean luminance of the frame over them.
  double truth_luminance = 0.0;  ///< Mean luminance of the truth over them.
  /// sum frame luminance / sum truth luminance - 1: + too bright, - too dark. NaN without
  /// pixels or light.
  double bias = 0.0;
  /// One standard deviation of `bias` due to the truth's own noise (its estimated variance
  /// summed over the pixels): a bias within ~3 of these could be noise.
  double bias_noise = 0.0;
  double rel_rmse = 0.0;         ///< compare_rgb's relative RMSE against the truth's estimate.
  double truth_rel_rmse = 0.0;   ///< ... against the noise-free truth (its variance removed).
  double reference_noise = 0.0;  ///< The truth's own relative RMSE from its variance.
  std::string problem;           ///< Why the metrics are NaN (no pixels, a black truth); else empty.
};

/// What one measured frame cost the renderer (engine::Renderer::last_timings).
struct FrameCost {
  /// The first frame drawn from the view (on a bench's first view it also compiles the
  /// shaders, uploads the GI data and draws the shadow maps).
  std::vector<engine::PassTiming> first_frame;
  std::vector<engine::PassTiming> frame;  ///< The median of the timed frames (by their sum).
  double first_frame_ms = 0.0;            ///< Sums of the passes.
  double frame_ms = 0.0;
  double frame_ms_min = 0.0;  ///< The fastest and slowest timed frames' sums.
  double frame_ms_max = 0.0;
};

/// Region index of a background pixel in FrameTruth::region_of_pixel.
inline constexpr std::uint8_t kBackgroundPixel = 255;

/// The path tracer's image of a view and what its pixels show: rendered once, compared with
/// the frames of any number of bakes of the same scene and lights.
struct FrameTruth {
  FrameCamera camera;
  int samples_per_pixel = 0;  ///< Of both halves together.
  engine::ImageRgbaF image;   ///< Linear radiance, W/(m^2 sr): the mean of the two halves.
  /// Per pixel 3 values (R, G, B): the variance of `image` as an estimate of its expectation,
  /// (a - b)^2 / 4 of the halves a, b.
  std::vector<float> variance;
  std::vector<WorldRegion> regions;  ///< The bench's regions, in order; "other" follows them.
  /// Per pixel (rows top to bottom): index into `regions` (regions.size(): "other"), or
  /// kBackgroundPixel where the centre ray escapes to the sky.
  std::vector<std::uint8_t> region_of_pixel;
  double seconds = 0.0;  ///< Wall time of the first hits and the two halves.
};

struct FrameTruthReport {
  std::string camera;                         ///< FrameCamera::name.
  engine::ImageRgbaF frame;                   ///< The renderer's linear HDR frame, W/(m^2 sr).
  engine::ImageRgbaF truth;                   ///< FrameTruth::image.
  std::vector<std::uint8_t> region_of_pixel;  ///< FrameTruth::region_of_pixel.
  std::vector<RegionAccuracy> regions;        ///< The truth's regions in order, then "other".
  RegionAccuracy overall;                     ///< Every compared pixel ("frame").
  std::size_t background_pixels = 0;          ///< The sky: compared nowhere.
  std::size_t nonfinite_pixels = 0;           ///< Surface pixels left out: NaN/Inf in the frame or the truth.
  FrameCost cost;
  double truth_seconds = 0.0;  ///< FrameTruth::seconds.
};

/// The measuring instrument: a scene with its GI runtime and renderer, ready to compare
/// frames from any camera with the path tracer's truth.
///   auto bench = gi::FrameTruthBench::create(asset, bundle, settings).value();
///   auto truth = bench->render_truth(camera).value();          // once per view
///   auto report = bench->compare(truth).value();               // and per bake (another bench)
class FrameTruthBench {
 public:
  /// Instantiates `asset` (plus a camera node of its own), loads `bundle` (a bake of this
  /// asset; empty path: no GI, the renderer's constant-ambient stand-in) and creates the
  /// renderer. Needs a current GL 4.5 context that outlives the bench (engine::GpuContext).
  /// Errors: bad settings (Invalid), a bundle that does not load, a renderer that cannot be
  /// created.
  static engine::Result<std::unique_ptr<FrameTruthBench>> create(engine::SceneAsset asset,
                                                                 const std::filesystem::path& bundle,
                                                                 FrameTruthSettings settings);
  ~FrameTruthBench();
  FrameTruthBench(const FrameTruthBench&) = delete;
  FrameTruthBench& operator=(const FrameTruthBench&) = delete;

  /// The path tracer's truth of the view from `camera` at the settings' size and samples,
  /// its pixels classified into the settings' regions. Progress per stage ("first hits",
  /// "truth 1/2", "truth 2/2"; false cancels). Errors: a degenerate camera (Invalid), the
  /// path tracer's errors, cancellation. It depends on the scene and its lights, not on the
  /// bundle: a truth of one bench serves every bench of the same scene.
  engine::Result<FrameTruth> render_truth(const FrameCamera& camera, const StageProgressCallback& progress = {});

  /// Renders the frame from the truth's camera (the warm-up frames, then the measured one)
  /// and compares it with the truth per region and over the frame. Errors: a truth of
  /// another size (Invalid) or a degenerate camera.
  engine::Result<FrameTruthReport> compare(const FrameTruth& truth);

  /// render_truth, then compare.
  engine::Result<FrameTruthReport> compare(const FrameCamera& camera, const StageProgressCallback& progress = {});

  /// The label of the GI the frames are drawn with ("light atlas", or "constant ambient
  /// (stand-in)" without a bundle).
  std::string gi_label() const;

 private:
  struct State;
  explicit FrameTruthBench(std::unique_ptr<State> state);
  /// Moves the bench's camera entity to `camera` (a new registry frame). Errors: degenerate.
  engine::Status place_camera(const FrameCamera& camera);
  std::unique_ptr<State> state_;
};

/// `asset` with every material's base-colour, metallic-roughness, emissive and normal
/// textures and its alpha mode dropped (the factors stay, Opaque): the scene a bake of
/// gi::without_textures(BakeInput) (gi-bake --untextured) saw, so the renderer, the bakers
/// and the path tracer see the same materials. The images stay (unused).
engine::SceneAsset without_textures(engine::SceneAsset asset);

/// The frame's luminance against the truth's per pixel, in false colour: log2 of the ratio
/// from -stops (blue: 2^stops times too dark) through white (equal) to +stops (red: too
/// bright), clamped; background pixels mid grey. stops > 0.
engine::ImageRgba8 ratio_image(const FrameTruthReport& report, float stops = 2.0f);

}  // namespace gi
