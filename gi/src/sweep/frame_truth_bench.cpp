// gi/frame_truth.h: the renderer's frame against the path tracer's truth, per region.
#include <engine/components.h>
#include <engine/scene.h>
#include <gi/bake_input.h>
#include <gi/frame_truth.h>
#include <gi/gi_system.h>
#include <gi/reference.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>
#include <utility>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "core/stopwatch.h"
#include "sweep/region_accuracy.h"

namespace gi {
namespace {

constexpr const char* kCameraNodeName = "frame_truth_camera";
constexpr std::size_t kMaxRegions = 250;

engine::Error invalid(const std::string& message) {
  return engine::Error{"<frame truth>", "", message, engine::ErrorKind::Invalid};
}

engine::Status check_settings(const FrameTruthSettings& s) {
  if (s.width < 1 || s.height < 1 || s.width > 8192 || s.height > 8192)
    return invalid("width and height must lie in [1, 8192], got " + std::to_string(s.width) + "x" +
                   std::to_string(s.height));
  if (s.samples_per_pixel < 2) return invalid("samples_per_pixel must be >= 2 (two halves)");
  if (s.warmup_frames < 0 || s.warmup_frames > 100) return invalid("warmup_frames must lie in [0, 100]");
  if (s.timed_frames < 1 || s.timed_frames > 100) return invalid("timed_frames must lie in [1, 100]");
  if (s.regions.size() > kMaxRegions) return invalid("at most 250 regions");
  if (!(s.region_probe_m >= 0.0f && s.region_probe_m < 1.0f)) return invalid("region_probe_m must lie in [0, 1) m");
  for (const WorldRegion& r : s.regions) {
    const bool finite = std::isfinite(r.min_m.x + r.min_m.y + r.min_m.z + r.max_m.x + r.max_m.y + r.max_m.z);
    if (r.name.empty() || r.name == "other" || r.name == "frame")
      return invalid("a region needs a name other than 'other' and 'frame'");
    if (!finite || glm::any(glm::greaterThan(r.min_m, r.max_m)))
      return invalid("region " + r.name + ": its box must be finite with min <= max");
  }
  return {};
}

double total_ms(const std::vector<engine::PassTiming>& passes) {
  double ms = 0.0;
  for (const engine::PassTiming& p : passes) ms += p.ms;
  return ms;
}

// Draws the still view `warmup` + `timed` times; the cost of the first frame and of the
// median timed one (by the sum of its passes).
FrameCost draw_and_time(engine::Renderer& renderer, engine::Registry& reg, engine::Entity camera, int warmup,
                        int timed) {
  FrameCost cost;
  std::vector<std::vector<engine::PassTiming>> frames;
  for (int f = 0; f < warmup + timed; ++f) {
    if (f > 0) reg.begin_frame();  // a still scene: nothing changes after the camera moved
    renderer.render(reg, camera);
    if (f == 0) cost.first_frame = renderer.last_timings();
    if (f >= warmup) frames.push_back(renderer.last_timings());
  }
  std::sort(frames.begin(), frames.end(), [](const auto& a, const auto& b) { return total_ms(a) < total_ms(b); });
  cost.frame = frames[frames.size() / 2];
  cost.first_frame_ms = total_ms(cost.first_frame);
  cost.frame_ms = total_ms(cost.frame);
  cost.frame_ms_min = total_ms(frames.front());
  cost.frame_ms_max = total_ms(frames.back());
  return cost;
}

std::uint8_t region_of(const std::vector<WorldRegion>& regions, const glm::vec3& p) {
  for (std::size_t r = 0; r < regions.size(); ++r)
    if (glm::all(glm::greaterThanEqual(p, regions[r].min_m)) && glm::all(glm::lessThanEqual(p, regions[r].max_m)))
      return static_cast<std::uint8_t>(r);
  return static_cast<std::uint8_t>(regions.size());  // "other"
}

// The camera's rotation (local -Z to the target, +Y up as far as it can be).
glm::quat look_rotation(const glm::vec3& eye, const glm::vec3& target) {
  const glm::vec3 forward = glm::normalize(target - eye);
  const glm::vec3 up = std::fabs(forward.y) > 0.999f ? glm::vec3(0.0f, 0.0f, 1.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
  const glm::mat4 camera_to_world = glm::inverse(glm::lookAt(eye, target, up));
  return glm::normalize(glm::quat_cast(glm::mat3(camera_to_world)));
}

}  // namespace

struct FrameTruthBench::State {
  FrameTruthSettings settings;
  engine::Scene scene;
  engine::Entity camera;
  BakeInput truth_input;  // what the path tracer sees: the scene as instantiated
  std::unique_ptr<GISystem> gi;
  std::unique_ptr<engine::Renderer> renderer;  // declared last: destroyed before the GI system
};

FrameTruthBench::FrameTruthBench(std::unique_ptr<State> state) : state_(std::move(state)) {}
FrameTruthBench::~FrameTruthBench() = default;

engine::Result<std::unique_ptr<FrameTruthBench>> FrameTruthBench::create(engine::SceneAsset asset,
                                                                         const std::filesystem::path& bundle,
                                                                         FrameTruthSettings settings) {
  if (auto ok = check_settings(settings); !ok) return ok.error();
  // A camera node of the bench's own (the renderer draws from an entity), placed per view.
  asset.cameras.push_back({kCameraNodeName, engine::Camera{.yfov_rad = 1.0f, .znear_m = 0.05f, .zfar_m = 1000.0f}});
  engine::Node node;
  node.name = kCameraNodeName;
  node.camera = static_cast<int>(asset.cameras.size()) - 1;
  asset.nodes.push_back(node);

  auto state = std::make_unique<State>();
  state->settings = std::move(settings);
  state->scene = engine::instantiate(std::move(asset));
  state->camera = state->scene.node_entities.back();
  if (!bundle.empty()) {
    auto gi = GISystem::load(bundle, state->scene);  // gives the static meshes their TEXCOORD_1
    if (!gi) return gi.error();
    state->gi = std::move(gi).value();
  }
  state->truth_input = bake_input_from(state->scene);
  auto renderer = engine::Renderer::create(
      state->scene.assets,
      {.width = state->settings.width, .height = state->settings.height, .exposure = state->settings.exposure});
  if (!renderer) return renderer.error();
  state->renderer = std::move(renderer).value();
  state->renderer->set_indirect_light(state->gi.get());
  return std::unique_ptr<FrameTruthBench>(new FrameTruthBench(std::move(state)));
}

std::string FrameTruthBench::gi_label() const {
  return state_->gi ? std::string(state_->gi->label()) : std::string("constant ambient (stand-in)");
}

engine::Status FrameTruthBench::place_camera(const FrameCamera& camera) {
  const glm::vec3 d = camera.target_m - camera.position_m;
  if (!std::isfinite(d.x + d.y + d.z + camera.position_m.x + camera.position_m.y + camera.position_m.z) ||
      !(glm::length(d) > 1e-4f))
    return invalid("camera " + camera.name + ": position and target must be finite and apart");
  if (!(camera.yfov_rad > 0.01f && camera.yfov_rad < 3.0f))
    return invalid("camera " + camera.name + ": the field of view must lie in (0.01, 3) rad");
  State& s = *state_;
  engine::Registry& reg = s.scene.registry;
  reg.begin_frame();
  engine::Transform& t = reg.write<engine::Transform>(s.camera);
  t.position = camera.position_m;
  t.rotation = look_rotation(camera.position_m, camera.target_m);
  reg.write<engine::Camera>(s.camera).yfov_rad = camera.yfov_rad;
  engine::update_world_transforms(reg);
  return {};
}

engine::Result<FrameTruth> FrameTruthBench::render_truth(const FrameCamera& camera,
                                                         const StageProgressCallback& progress) {
  // The path tracer's camera is the renderer's: the world matrix the registry computes.
  if (auto ok = place_camera(camera); !ok) return ok.error();
  State& s = *state_;
  const ReferenceCamera rc{.camera_to_world = s.scene.registry.get<engine::WorldTransform>(s.camera).matrix,
                           .yfov_rad = camera.yfov_rad,
                           .aspect = 0.0f};
  const int w = s.settings.width, h = s.settings.height;
  const auto t0 = std::chrono::steady_clock::now();
  if (progress && !progress("first hits", 0.0)) return engine::cancelled_error("frame truth");
  auto hits = reference_first_hits(s.truth_input, rc, w, h, s.settings.threads);
  if (!hits) return hits.error();
  engine::ImageRgbaF half[2];
  for (int k = 0; k < 2; ++k) {
    const std::string stage = "truth " + std::to_string(k + 1) + "/2";
    ReferenceSettings rs;
    rs.samples_per_pixel = s.settings.samples_per_pixel / 2;
    rs.seed = s.settings.seed + static_cast<std::uint64_t>(k);
    rs.threads = s.settings.threads;
    rs.jitter_pixels = false;  // through the pixel centres, as the rasterizer samples
    if (progress) rs.progress = [&](double done) { return progress(stage, done); };
    auto image = render_reference_image(s.truth_input, rc, w, h, rs);
    if (!image) return image.error();
    half[k] = std::move(image).value();
  }

  // The halves' mean, and per channel (a - b)^2 / 4, the variance of that mean.
  FrameTruth truth;
  truth.camera = camera;
  truth.samples_per_pixel = 2 * (s.settings.samples_per_pixel / 2);
  truth.regions = s.settings.regions;
  const std::size_t n = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  truth.image = half[0];
  truth.variance.assign(3 * n, 0.0f);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t c = 0; c < 3; ++c) {
      const float a = half[0].pixels[4 * i + c], b = half[1].pixels[4 * i + c];
      truth.image.pixels[4 * i + c] = 0.5f * (a + b);
      truth.variance[3 * i + c] = 0.25f * (a - b) * (a - b);
    }
  truth.region_of_pixel.assign(n, kBackgroundPixel);
  for (std::size_t i = 0; i < n; ++i)
    if (hits->hit[i])
      truth.region_of_pixel[i] =
          region_of(truth.regions, hits->position_m[i] + s.settings.region_probe_m * hits->normal[i]);
  truth.seconds = seconds_since(t0);
  return truth;
}

engine::Result<FrameTruthReport> FrameTruthBench::compare(const FrameTruth& truth) {
  State& s = *state_;
  const std::size_t n = static_cast<std::size_t>(s.settings.width) * static_cast<std::size_t>(s.settings.height);
  if (truth.image.width != s.settings.width || truth.image.height != s.settings.height ||
      truth.variance.size() != 3 * n || truth.region_of_pixel.size() != n)
    return invalid("a truth of " + std::to_string(truth.image.width) + "x" + std::to_string(truth.image.height) +
                   " pixels for a bench of " + std::to_string(s.settings.width) + "x" +
                   std::to_string(s.settings.height));
  if (auto ok = place_camera(truth.camera); !ok) return ok.error();
  FrameTruthReport report;
  report.camera = truth.camera.name;
  report.truth = truth.image;
  report.region_of_pixel = truth.region_of_pixel;
  report.truth_seconds = truth.seconds;
  report.cost =
      draw_and_time(*s.renderer, s.scene.registry, s.camera, s.settings.warmup_frames, s.settings.timed_frames);
  report.frame = s.renderer->read_hdr();

  std::vector<std::uint8_t> compared(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (truth.region_of_pixel[i] == kBackgroundPixel) {
      ++report.background_pixels;
      continue;
    }
    bool finite = true;
    for (std::size_t c = 0; c < 3; ++c)
      finite = finite && std::isfinite(report.frame.pixels[4 * i + c]) &&
               std::isfinite(truth.image.pixels[4 * i + c]) && std::isfinite(truth.variance[3 * i + c]);
    compared[i] = finite ? 1 : 0;
    report.nonfinite_pixels += finite ? 0 : 1;
  }
  report.overall = measure_region("frame", report.frame, truth.image, truth.variance, compared);
  std::vector<std::uint8_t> mask(n);
  for (std::size_t r = 0; r <= truth.regions.size(); ++r) {
    for (std::size_t i = 0; i < n; ++i) mask[i] = compared[i] && truth.region_of_pixel[i] == r;
    const std::string name = r < truth.regions.size() ? truth.regions[r].name : std::string("other");
    report.regions.push_back(measure_region(name, report.frame, truth.image, truth.variance, mask));
  }
  return report;
}

engine::Result<FrameTruthReport> FrameTruthBench::compare(const FrameCamera& camera,
                                                          const StageProgressCallback& progress) {
  auto truth = render_truth(camera, progress);
  if (!truth) return truth.error();
  return compare(*truth);
}

engine::SceneAsset without_textures(engine::SceneAsset asset) {
  for (engine::Material& m : asset.materials) {
    m.base_color_texture = {};
    m.metallic_roughness_texture = {};
    m.emissive_texture = {};
    m.normal_texture = {};
    m.alpha_mode = engine::AlphaMode::Opaque;  // as gi::without_textures(BakeInput)
  }
  return asset;
}

}  // namespace gi
