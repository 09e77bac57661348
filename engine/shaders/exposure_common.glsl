// Automatic exposure's metering histogram (engine/exposure.h, docs/exposure.md), shared by
// exposure_histogram.comp.glsl and exposure_adapt.comp.glsl. Defined by the C++ side
// (render/exposure_meter.cpp): METER_BINS bins of 1/BINS_PER_EV EV each from
// METER_MIN_LOG2 (log2 cd/m^2); each bin also sums where in the bin its pixels fall, in
// SUB_BIN_STEPS steps, so the mean of a bin is its pixels' mean within 1/(2 SUB_BIN_STEPS) of
// a bin instead of the bin's centre.
#ifndef EXPOSURE_STATE_BINDING
#define EXPOSURE_STATE_BINDING 4  // render/exposure_meter.h's kExposureStateBinding defines it
#endif
#ifndef EXPOSURE_HISTOGRAM_BINDING
#define EXPOSURE_HISTOGRAM_BINDING 5  // ... and kExposureHistogramBinding
#endif
layout(std430, binding = EXPOSURE_HISTOGRAM_BINDING) buffer ExposureHistogram {
  uint hist_count[METER_BINS];
  uint hist_sub_bin_sum[METER_BINS];
};

// The adapted exposure: what the tonemap reads (render/exposure_meter.h's GpuExposureState).
layout(std430, binding = EXPOSURE_STATE_BINDING) buffer ExposureState {
  float state_exposure;       // linear scale applied to radiance before the tonemap
  float state_ev100;          // the adapted EV100
  float state_target_ev100;   // this frame's target (metered, clamped, compensated)
  float state_mean_log2;      // the trimmed mean of log2 luminance (log2 cd/m^2)
  uint state_metered_pixels;  // pixels at or above 2^METER_MIN_LOG2 cd/m^2
  uint state_pad0;
  uint state_pad1;
  uint state_pad2;
};

// Photometric luminance (cd/m^2) of radiance in W/(m^2 sr): 683 lm/W x Rec. 709 Y.
float photometric_luminance(vec3 radiance) { return LUMENS_PER_WATT * dot(radiance, vec3(0.2126, 0.7152, 0.0722)); }

// The mean log2 luminance of bin i's pixels, from its count and sum of sub-bin steps.
float bin_mean_log2(uint i, uint count, uint sub_bin_sum) {
  const float within = (float(sub_bin_sum) / float(count) + 0.5) / float(SUB_BIN_STEPS);
  return METER_MIN_LOG2 + (float(i) + within) / float(BINS_PER_EV);
}
