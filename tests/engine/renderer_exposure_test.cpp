// Exposure (engine/exposure.h, docs/exposure.md): automatic exposure's GPU metering against
// the same statistic computed on the CPU from read_hdr(), its independence of the light's
// scale, its adaptation rate, its clamp, and the fixed modes' output.
#include <engine/exposure.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "engine/renderer_test_scene.h"

namespace {

using namespace renderer_test;

constexpr float kAlbedo = 0.5f;
constexpr double kDt = 1.0 / 60.0;

// A plane lit by a point light: luminance falls off smoothly over many bins of the
// histogram; the sky beyond the plane's edge is black (not metered). No ambient term, so
// the frame's radiance is exactly proportional to the light's intensity.
struct LitPlane {
  engine::SceneAsset assets;
  engine::Registry reg;
  engine::Entity light;
  TestCamera cam{{0.0f, 2.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.9f, 64};
  engine::Entity camera;

  explicit LitPlane(float intensity_w_sr) {
    assets.materials.push_back(diffuse_material(kAlbedo));
    assets.meshes.push_back(plane_mesh(2.5f, 0));
    add_mesh(reg, 0, glm::mat4(1.0f));
    light = add_light(reg, engine::Light{.type = engine::LightType::Point, .intensity = intensity_w_sr},
                      {0.4f, 0.8f, 0.3f}, {0.4f, 0.0f, 0.3f});
    camera = cam.add_to(reg);
  }
  void set_intensity(float w_sr) { reg.write<engine::Light>(light).intensity = w_sr; }
};

std::unique_ptr<engine::Renderer> automatic_renderer(const LitPlane& s, const engine::AutoExposure& a = {}) {
  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  if (r) {
    r->settings().exposure_mode = engine::ExposureMode::Automatic;
    r->settings().auto_exposure = a;
  }
  return r;
}

// The statistic of engine/exposure.h computed exactly: the log2 luminance of every metered
// pixel (every second pixel of every second row from the bottom-left corner, at or above
// the metering floor), sorted, the mean over the ranks between the two percentiles (the
// pixels at the edges counted by the share of them inside).
struct CpuMetering {
  double mean_log2 = 0.0;
  std::size_t metered = 0;
};
CpuMetering cpu_metering(const engine::ImageRgbaF& hdr, const engine::AutoExposure& a) {
  std::vector<double> logs;
  for (int row = 0; row < hdr.height; ++row)  // read_hdr()'s rows run top to bottom
    for (int x = 0; x < hdr.width; ++x) {
      if (x % engine::kMeteredPixelStride != 0 || (hdr.height - 1 - row) % engine::kMeteredPixelStride != 0) continue;
      const std::size_t i =
          (static_cast<std::size_t>(row) * static_cast<std::size_t>(hdr.width) + static_cast<std::size_t>(x)) * 4;
      const double r = hdr.pixels[i], g = hdr.pixels[i + 1], b = hdr.pixels[i + 2];
      const double l = 683.0 * (0.2126 * r + 0.7152 * g + 0.0722 * b);
      if (l >= std::exp2(double{engine::kMeteredLog2LuminanceMin}))
        logs.push_back(std::min(std::log2(l), double{engine::kMeteredLog2LuminanceMax}));
    }
  std::sort(logs.begin(), logs.end());
  const double lo = double{a.low_percentile} * static_cast<double>(logs.size());
  const double hi = double{a.high_percentile} * static_cast<double>(logs.size());
  double kept = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < logs.size(); ++i) {
    const double w = std::min(hi, static_cast<double>(i + 1)) - std::max(lo, static_cast<double>(i));
    if (w > 0.0) kept += w, sum += w * logs[i];
  }
  return {kept > 0.0 ? sum / kept : 0.0, logs.size()};
}

double mean_ldr(const engine::ImageRgba8& img) {
  double sum = 0.0;
  for (std::size_t i = 0; i < img.pixels.size(); i += 4) sum += img.pixels[i] + img.pixels[i + 1] + img.pixels[i + 2];
  return sum / (3.0 * 255.0 * static_cast<double>(img.pixels.size() / 4));
}

// The GPU bins luminance at 1/8 EV and places each pixel within its bin in 1/16 steps, so
// its mean is within 1/256 EV of the exact one per pixel; the bins cut by a percentile
// count their share at the bin's mean. 0.02 EV (1.4% in luminance) bounds both here.
constexpr double kMeteringTolEv = 0.02;

TEST(RendererExposure, MeteredLuminanceIsTheCpuStatisticOfTheHdrFrame) {
  engine::GpuContext ctx = headless_context();
  LitPlane s(10.0f);
  for (const engine::AutoExposure a :
       {engine::AutoExposure{}, engine::AutoExposure{.low_percentile = 0.5f, .high_percentile = 0.6f}}) {
    auto r = automatic_renderer(s, a);
    ASSERT_NE(r, nullptr);
    r->render(s.reg, s.camera, kDt);
    const engine::ExposureReading got = r->read_exposure();
    const CpuMetering want = cpu_metering(r->read_hdr(), a);
    ASSERT_TRUE(got.metered);
    const std::size_t grid = static_cast<std::size_t>(s.cam.size / 2 * s.cam.size / 2);  // 64 x 64: 32 x 32 metered
    EXPECT_GT(want.metered, grid / 2) << "most of the frame shows the lit plane";
    EXPECT_LT(want.metered, grid) << "the black sky is not metered";
    EXPECT_EQ(got.metered_pixels, want.metered);
    EXPECT_NEAR(got.mean_log2_luminance, want.mean_log2, kMeteringTolEv)
        << a.low_percentile << ".." << a.high_percentile;
    // The first frame snaps to the target: the meter's EV100, log2(8 L_avg), in the clamp.
    EXPECT_NEAR(got.target_ev100, want.mean_log2 + 3.0, kMeteringTolEv);
    EXPECT_FLOAT_EQ(got.ev100, got.target_ev100);
    EXPECT_NEAR(got.exposure, engine::exposure_of_ev100(got.ev100), 1e-5f * got.exposure);
  }
}

TEST(RendererExposure, AHundredTimesTheLightGivesTheSameFrame) {
  engine::GpuContext ctx = headless_context();
  LitPlane dim(1.0f), bright(100.0f);
  auto rd = automatic_renderer(dim), rb = automatic_renderer(bright);
  ASSERT_NE(rd, nullptr);
  ASSERT_NE(rb, nullptr);
  rd->render(dim.reg, dim.camera, kDt);
  rb->render(bright.reg, bright.camera, kDt);
  const double ev_step = rb->read_exposure().ev100 - rd->read_exposure().ev100;
  EXPECT_NEAR(ev_step, std::log2(100.0), kMeteringTolEv);
  const double a = mean_ldr(rd->read_ldr()), b = mean_ldr(rb->read_ldr());
  EXPECT_GT(a, 0.1) << "the frame is not black";
  EXPECT_NEAR(b, a, 0.02 * a);
  // Under a fixed exposure the same two frames differ wholly (the contrast that makes the
  // test able to fail).
  rd->settings().exposure_mode = rb->settings().exposure_mode = engine::ExposureMode::FixedLinear;
  rd->settings().exposure = rb->settings().exposure = rd->read_exposure().exposure;
  rd->render(dim.reg, dim.camera, kDt);
  rb->render(bright.reg, bright.camera, kDt);
  EXPECT_GT(mean_ldr(rb->read_ldr()), 1.5 * mean_ldr(rd->read_ldr()));
}

// After a step of the light, the EV100 approaches the new target as
// target + (ev0 - target) exp(-rate t), t = frames x dt: rate 3/s when the scene got
// brighter, 1/s when it got darker (AutoExposure's defaults).
TEST(RendererExposure, AdaptationAfterAStepFollowsTheDocumentedRate) {
  engine::GpuContext ctx = headless_context();
  LitPlane s(1.0f);
  auto r = automatic_renderer(s);
  ASSERT_NE(r, nullptr);
  r->render(s.reg, s.camera, kDt);
  const float ev_dim = r->read_exposure().ev100;
  struct Step {
    float intensity;
    double rate;
  };
  for (const Step step : {Step{16.0f, 3.0}, Step{1.0f, 1.0}}) {
    s.set_intensity(step.intensity);
    const float ev0 = r->read_exposure().ev100;
    float previous = ev0, target = 0.0f;
    for (int n = 1; n <= 90; ++n) {
      r->render(s.reg, s.camera, kDt);
      const engine::ExposureReading e = r->read_exposure();
      if (n == 1) target = e.target_ev100;
      ASSERT_FLOAT_EQ(e.target_ev100, target) << "the metering does not depend on the exposure";
      const double t = n * kDt;
      EXPECT_NEAR(e.ev100, double{target} + double{ev0 - target} * std::exp(-step.rate * t), 1e-3) << "frame " << n;
      EXPECT_NEAR(e.ev100, engine::adapt_ev100(previous, target, kDt, {}), 1e-4) << "frame " << n;
      previous = e.ev100;
    }
    if (step.intensity == 16.0f) {
      EXPECT_NEAR(target - ev_dim, 4.0, kMeteringTolEv) << "16x the light: 4 EV";
    }
  }
  EXPECT_FLOAT_EQ(r->read_exposure().target_ev100, ev_dim) << "back to the first light";
  // reset_exposure(): the next frame snaps to the target again.
  s.set_intensity(16.0f);
  r->reset_exposure();
  r->render(s.reg, s.camera, kDt);
  EXPECT_FLOAT_EQ(r->read_exposure().ev100, r->read_exposure().target_ev100);
}

TEST(RendererExposure, TheMeteredEv100IsClampedThenCompensated) {
  engine::GpuContext ctx = headless_context();
  const engine::AutoExposure clamp{.min_ev100 = 2.0f, .max_ev100 = 14.0f};
  struct Case {
    float intensity;
    float compensation;
    float want_ev100;
  };
  // 1e-3 W/sr meters below EV100 2, 1e5 W/sr beyond the meter's top (2^22 cd/m^2: EV100 25).
  for (const Case c :
       {Case{1e-3f, 0.0f, 2.0f}, Case{1e5f, 0.0f, 14.0f}, Case{1e5f, 1.5f, 12.5f}, Case{1e-3f, -1.0f, 3.0f}}) {
    LitPlane s(c.intensity);
    engine::AutoExposure a = clamp;
    a.compensation_ev = c.compensation;
    auto r = automatic_renderer(s, a);
    ASSERT_NE(r, nullptr);
    for (int n = 0; n < 3; ++n) r->render(s.reg, s.camera, kDt);
    const engine::ExposureReading e = r->read_exposure();
    const double metered = double{e.mean_log2_luminance} + 3.0;
    EXPECT_TRUE(metered < 2.0 || metered > 14.0) << "the case must meter outside the clamp: " << metered;
    EXPECT_FLOAT_EQ(e.ev100, c.want_ev100) << c.intensity << " W/sr, compensation " << c.compensation;
    EXPECT_NEAR(e.exposure, engine::exposure_of_ev100(c.want_ev100), 1e-5f * e.exposure);
  }
  // Nothing metered (no light at all): the clamp's darkest end.
  LitPlane black(0.0f);
  auto r = automatic_renderer(black, clamp);
  ASSERT_NE(r, nullptr);
  r->render(black.reg, black.camera, kDt);
  EXPECT_EQ(r->read_exposure().metered_pixels, 0u);
  EXPECT_FLOAT_EQ(r->read_exposure().ev100, 2.0f);
}

// The fixed modes are today's tonemap of the HDR frame: FixedLinear scales by `exposure`,
// FixedEv100 by the camera model's 683 / (1.2 x 2^EV100), the same bits as FixedLinear at
// that scale; a frame after automatic ones is the same as a fresh renderer's.
TEST(RendererExposure, FixedModesAreTodaysTonemapAndUntouchedByAutomaticFrames) {
  engine::GpuContext ctx = headless_context();
  LitPlane s(10.0f);
  auto fresh = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(fresh, nullptr);
  EXPECT_EQ(fresh->settings().exposure_mode, engine::ExposureMode::FixedLinear) << "the default";
  fresh->settings().exposure = 0.3f;
  fresh->render(s.reg, s.camera, kDt);
  const engine::ImageRgba8 linear = fresh->read_ldr();
  const engine::ImageRgbaF hdr = fresh->read_hdr();
  EXPECT_FALSE(fresh->read_exposure().metered);
  EXPECT_FLOAT_EQ(fresh->read_exposure().exposure, 0.3f);
  for (const engine::PassTiming& t : fresh->last_timings())
    EXPECT_EQ(t.name.find("exposure ("), std::string::npos) << "no metering pass in a fixed mode: " << t.name;
  std::size_t off_by_more = 0;
  for (std::size_t i = 0; i < linear.pixels.size(); i += 4) {
    const float x = std::max(hdr.pixels[i], 0.0f) * 0.3f;
    const float t = std::clamp(x * (2.51f * x + 0.03f) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
    const float srgb = t <= 0.0031308f ? 12.92f * t : 1.055f * std::pow(t, 1.0f / 2.4f) - 0.055f;
    off_by_more += std::abs(static_cast<float>(linear.pixels[i]) - srgb * 255.0f) > 1.0f ? 1 : 0;
  }
  EXPECT_EQ(off_by_more, 0u);

  auto r = make_renderer(s.assets, s.cam.size, 0.0f);
  ASSERT_NE(r, nullptr);
  r->settings().exposure_mode = engine::ExposureMode::Automatic;
  for (int n = 0; n < 3; ++n) r->render(s.reg, s.camera, kDt);
  r->settings().exposure_mode = engine::ExposureMode::FixedLinear;
  r->settings().exposure = 0.3f;
  r->render(s.reg, s.camera, kDt);
  EXPECT_EQ(r->read_ldr().pixels, linear.pixels);

  r->settings().exposure_mode = engine::ExposureMode::FixedEv100;
  r->settings().ev100 = 12.0f;
  r->render(s.reg, s.camera, kDt);
  const engine::ImageRgba8 by_ev = r->read_ldr();
  EXPECT_NEAR(r->read_exposure().ev100, 12.0f, 1e-4f);
  fresh->settings().exposure = engine::exposure_of_ev100(12.0f);
  fresh->render(s.reg, s.camera, kDt);
  EXPECT_EQ(by_ev.pixels, fresh->read_ldr().pixels);
  EXPECT_NE(by_ev.pixels, linear.pixels);
}

TEST(ExposureModel, Ev100AndExposureFollowTheCameraModel) {
  // Sunny 16: EV100 15 scales radiance by 683 / (1.2 x 32768).
  EXPECT_NEAR(engine::exposure_of_ev100(15.0f), 683.0 / (1.2 * 32768.0), 1e-8);
  EXPECT_NEAR(engine::ev100_of_exposure(engine::exposure_of_ev100(7.25f)), 7.25f, 1e-5f);
  // gi_demo's old default 0.3 is EV100 log2(683 / 0.36) = 10.89.
  EXPECT_NEAR(engine::ev100_of_exposure(0.3f), 10.889f, 1e-3f);
  // A meter reading 1000 cd/m^2 sets EV100 log2(8000) = 12.97; that luminance then lands at
  // 1 / 9.6 of the camera's saturation.
  EXPECT_NEAR(engine::ev100_of_luminance(1000.0f), std::log2(8000.0f), 1e-5f);
  const float radiance = 1000.0f / 683.0f;  // W/(m^2 sr) of a grey of 1000 cd/m^2
  EXPECT_NEAR(radiance * engine::exposure_of_ev100(engine::ev100_of_luminance(1000.0f)), 1.0f / 9.6f, 1e-6f);
  EXPECT_NEAR(engine::photometric_luminance(glm::vec3(1.0f)), 683.0f, 1e-3f);
}

}  // namespace
