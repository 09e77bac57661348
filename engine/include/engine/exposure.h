#pragma once
// Exposure: the scale the renderer applies to the linear HDR frame (radiance, W/(m^2 sr) per
// channel) before the tonemap, and how it is chosen (RenderSettings::exposure_mode). The
// camera model, every constant and its cost are in docs/exposure.md.
//
// The standard camera model (ISO 2720 / ISO 12232, as in Lagarde and de Rousiers 2014,
// "Moving Frostbite to physically based rendering", section 5.1) works on photometric
// luminance L_v (cd/m^2) = 683 lm/W x (0.2126 R + 0.7152 G + 0.0722 B) of the radiance:
//   - a camera set to EV100 saturates at L_max = 78 / (q S) x 2^EV100 = 1.2 x 2^EV100 cd/m^2
//     (S = 100, lens and vignetting factor q = 0.65), so its exposure is H = 1 / L_max;
//     applied to radiance instead of luminance: exposure = 683 / (1.2 x 2^EV100);
//   - a reflected-light meter reading the average luminance L_avg sets
//     EV100 = log2(L_avg x S / K) = log2(8 L_avg) (calibration constant K = 12.5).
// A scene metered at L_avg is then shown at L_avg x H = 1 / 9.6 of saturation before the
// tonemap, i.e. about 0.40 once ACES-fitted and sRGB-encoded.
//   engine::RenderSettings s;
//   s.exposure_mode = engine::ExposureMode::Automatic;   // or FixedEv100 with s.ev100 = 15 (sunny 16)

#include <engine/units.h>

#include <cstdint>
#include <glm/glm.hpp>

namespace engine {

/// How the renderer chooses the exposure of each frame.
enum class ExposureMode : std::uint8_t {
  FixedLinear,  ///< RenderSettings::exposure as given (the default: tests and goldens keep it).
  FixedEv100,   ///< RenderSettings::ev100 through the camera model: exposure_of_ev100(ev100).
  Automatic,    ///< Metered on the GPU from each frame, adapted over time, clamped (AutoExposure).
};

/// Automatic exposure's metering, clamp, compensation and adaptation
/// (RenderSettings::auto_exposure). Metering: the frame's pixels on every
/// kMeteredPixelStride-th column and row from the bottom-left corner (a quarter of them)
/// whose photometric luminance is at least 2^kMeteredLog2LuminanceMin cd/m^2 (darker ones, such as a background without
/// a sky, are not metered; brighter than 2^kMeteredLog2LuminanceMax count as that) are ranked
/// by luminance; the mean log2 luminance of those ranked between low_percentile and
/// high_percentile (fractions of the metered pixels) is log2 of the frame's log-average
/// luminance L_avg. The target is clamp(log2(8 L_avg), min_ev100, max_ev100) -
/// compensation_ev (no metered pixel: min_ev100 - compensation_ev). The EV100 approaches it
/// exponentially over the frames' time steps.
struct AutoExposure {
  /// Brightness added after metering, in EV: +1 shows the frame twice as bright.
  float compensation_ev = 0.0f;
  /// The metered EV100 is clamped to [min_ev100, max_ev100] (before the compensation):
  /// -4 is about a landscape under a full moon, so a room with its lights off stays dark instead
  /// of being pulled up to a noisy grey; 21 is one EV above the engine's 700 W/m^2 sun on a
  /// white surface (20.1), so the sun's own disc or a specular glint cannot push it further.
  float min_ev100 = -4.0f;
  float max_ev100 = 21.0f;
  /// The darkest 10% of the metered pixels are left out (deep shadows, black corners)...
  float low_percentile = 0.10f;
  /// ... and the brightest 5% (lamps, the sky through a window, specular highlights), so the
  /// exposure follows the lit surfaces that fill most of the frame.
  float high_percentile = 0.95f;
  /// Rates of the exponential approach, per second: after a step of the scene's brightness,
  /// EV100(t) = target + (EV100(0) - target) x exp(-rate t). The eye adapts to light faster
  /// than to darkness: 3/s when the scene got brighter (95% of the way in 1 s), 1/s when it
  /// got darker (95% in 3 s).
  float brighter_rate_per_s = 3.0f;
  float darker_rate_per_s = 1.0f;
};

/// The exposure a frame was shown with (Renderer::read_exposure()).
struct ExposureReading {
  float exposure = 1.0f;  ///< Linear scale applied to the radiance before the tonemap.
  float ev100 = 0.0f;     ///< The EV100 of that exposure (ev100_of_exposure).
  /// Automatic: the frame's target EV100 (metered, clamped, compensated) and its metering;
  /// fixed modes: ev100 and no metering.
  float target_ev100 = 0.0f;
  float mean_log2_luminance = 0.0f;  ///< log2 of the trimmed log-average luminance, log2(cd/m^2).
  std::uint32_t metered_pixels = 0;  ///< Pixels at or above 2^kMeteredLog2LuminanceMin.
  bool metered = false;              ///< True when the values come from an automatic frame.
};

/// Saturation-based speed of the camera model: L_max = kSaturationScale x 2^EV100 cd/m^2
/// (78 / (0.65 x 100)).
inline constexpr float kSaturationScale = 1.2f;
/// Reflected-light meter: EV100 = log2(L_avg x 100 / 12.5) = log2(L_avg) + kMeterEvOffset.
inline constexpr float kMeterEvOffset = 3.0f;
/// Metering looks at every second pixel of every second row (GL's pixel (0, 0) first): a
/// quarter of the frame, which keeps the pass at about a third of the tonemap's cost on
/// llvmpipe (docs/exposure.md) and changes the log-average of any frame by little.
inline constexpr int kMeteredPixelStride = 2;
/// Metered luminance range, cd/m^2: 2^-10 (below starlight) to 2^22 (well above the engine's sun).
inline constexpr float kMeteredLog2LuminanceMin = -10.0f;
inline constexpr float kMeteredLog2LuminanceMax = 22.0f;

/// Photometric luminance of linear radiance (W/(m^2 sr) per channel), cd/m^2.
inline float photometric_luminance(const glm::vec3& radiance) {
  return units::kLumensPerWatt * (0.2126f * radiance.x + 0.7152f * radiance.y + 0.0722f * radiance.z);
}

/// The linear scale the camera model applies to radiance at `ev100`: 683 / (1.2 x 2^EV100).
float exposure_of_ev100(float ev100);
/// The EV100 whose exposure_of_ev100 is `exposure` (> 0).
float ev100_of_exposure(float exposure);
/// The reflected-light meter's EV100 for an average luminance (cd/m^2, > 0): log2(8 L_avg).
float ev100_of_luminance(float average_luminance_cd_m2);
/// One step of automatic exposure's adaptation: `current` moved toward `target` over `dt_s`
/// seconds at AutoExposure's rate for the direction of the change (brighter scene: target >
/// current). The same formula the GPU pass uses.
float adapt_ev100(float current, float target, double dt_s, const AutoExposure& settings);

}  // namespace engine
