#include "raytrace/reference_render.h"

#include <engine/components.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <functional>
#include <string>

#include "core/random.h"
#include "core/thread_pool.h"
#include "raytrace/embree_ray_caster.h"
#include "raytrace/path_tracer.h"
#include "raytrace/scene_adapter.h"

namespace gi {
namespace {

engine::Error settings_error(const std::string& message) {
  return engine::Error{"<reference settings>", "", message, engine::ErrorKind::Invalid};
}

engine::Status check_settings(const ReferenceSettings& s) {
  if (s.samples_per_pixel < 1 || s.samples_per_pixel > (1 << 20))
    return settings_error("samples_per_pixel must be in [1, 2^20], got " + std::to_string(s.samples_per_pixel));
  if (s.max_bounces < -1) return settings_error("max_bounces must be -1 (unlimited) or >= 0");
  if (s.russian_roulette_start < 1) return settings_error("russian_roulette_start must be >= 1");
  return {};
}

glm::vec3 finite_or_zero(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z) ? v : glm::vec3(0.0f);
}

struct Prepared {
  ReferenceSceneIndex index;
  std::unique_ptr<RayCaster> caster;
};

engine::Result<Prepared> prepare(const ReferenceScene& scene) {
  auto index = index_reference_scene(scene);
  if (!index) return index.error();
  auto caster = make_embree_ray_caster(scene.geometry);
  if (!caster) return caster.error();
  return Prepared{std::move(index.value()), std::move(caster.value())};
}

PathTracerSettings tracer_settings(const ReferenceSettings& s) {
  PathTracerSettings t;
  t.max_bounces = s.max_bounces;
  t.russian_roulette_start = s.russian_roulette_start;
  return t;
}

engine::Status check_camera(const PinholeCamera& camera) {
  if (camera.width < 1 || camera.height < 1 || camera.width > 16384 || camera.height > 16384)
    return settings_error("image size must be in [1, 16384]^2, got " + std::to_string(camera.width) + "x" +
                          std::to_string(camera.height));
  if (!(camera.yfov_rad > 0.0f && camera.yfov_rad < 3.1f)) return settings_error("camera yfov must be in (0, 3.1) rad");
  return {};
}

// The camera rays of a pinhole image: one place, so the first-hit image and the radiance
// image trace the very same rays through the pixel centres.
struct PixelRays {
  explicit PixelRays(const PinholeCamera& camera)
      : eye(camera.camera_to_world[3]),
        rot(camera.camera_to_world),
        tan_half(std::tan(0.5f * camera.yfov_rad)),
        aspect(camera.aspect > 0.0f ? camera.aspect
                                    : static_cast<float>(camera.width) / static_cast<float>(camera.height)),
        width(camera.width),
        height(camera.height) {}

  /// Unit direction through (x + jx, y + jy) in pixels, rows top to bottom.
  glm::vec3 direction(int x, int y, float jx, float jy) const {
    const float ndc_x = 2.0f * (static_cast<float>(x) + jx) / static_cast<float>(width) - 1.0f;
    const float ndc_y = 1.0f - 2.0f * (static_cast<float>(y) + jy) / static_cast<float>(height);
    return glm::normalize(rot * glm::vec3(ndc_x * tan_half * aspect, ndc_y * tan_half, -1.0f));
  }

  glm::vec3 eye;
  glm::mat3 rot;
  float tan_half;
  float aspect;
  int width;
  int height;
};

}  // namespace

engine::Result<engine::ImageRgbaF> render_reference(const ReferenceScene& scene, const PinholeCamera& camera,
                                                    const ReferenceSettings& settings, const WorkShard& shard) {
  if (auto ok = check_settings(settings); !ok) return ok.error();
  if (auto ok = check_camera(camera); !ok) return ok.error();
  auto prepared = prepare(scene);
  if (!prepared) return prepared.error();
  const PathTracer tracer(scene, prepared->index, *prepared->caster, tracer_settings(settings));
  const PixelRays rays(camera);

  engine::ImageRgbaF image;
  image.width = camera.width;
  image.height = camera.height;
  image.pixels.assign(static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height) * 4, 1.0f);
  // A whole image needs no item list (16384^2 pixels would be 2 GB of indices).
  const std::vector<std::size_t> items =
      shard.whole() ? std::vector<std::size_t>{} : shard.items(image.pixels.size() / 4);
  const std::size_t count = shard.whole() ? image.pixels.size() / 4 : items.size();
  if (!shard.whole())
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
      if (i % 4 != 3) image.pixels[i] = 0.0f;
  ThreadPool pool(settings.threads);
  const bool completed = pool.parallel_for_with_progress(count, settings.progress, [&](std::size_t k) {
    const std::size_t i = shard.whole() ? k : items[k];
    const int x = static_cast<int>(i % static_cast<std::size_t>(camera.width));
    const int y = static_cast<int>(i / static_cast<std::size_t>(camera.width));
    Pcg32 rng = Pcg32::for_item(settings.seed, i);
    glm::dvec3 sum(0.0);
    for (int s = 0; s < settings.samples_per_pixel; ++s) {
      const float jx = settings.jitter_pixels ? rng.next_float() : 0.5f;
      const float jy = settings.jitter_pixels ? rng.next_float() : 0.5f;
      sum += glm::dvec3(finite_or_zero(tracer.radiance(Ray{rays.eye, 0.0f, rays.direction(x, y, jx, jy)}, rng)));
    }
    const glm::dvec3 mean = sum / static_cast<double>(settings.samples_per_pixel);
    for (int c = 0; c < 3; ++c) image.pixels[4 * i + static_cast<std::size_t>(c)] = static_cast<float>(mean[c]);
  });
  if (!completed) return engine::cancelled_error("reference render");
  return image;
}

engine::Result<FirstHitImage> first_hits(const ReferenceScene& scene, const PinholeCamera& camera, unsigned threads) {
  if (auto ok = check_camera(camera); !ok) return ok.error();
  auto prepared = prepare(scene);
  if (!prepared) return prepared.error();
  const PixelRays rays(camera);
  FirstHitImage out;
  out.width = camera.width;
  out.height = camera.height;
  const std::size_t count = static_cast<std::size_t>(camera.width) * static_cast<std::size_t>(camera.height);
  out.position_m.assign(count, glm::vec3(0.0f));
  out.normal.assign(count, glm::vec3(0.0f));
  out.hit.assign(count, 0);
  ThreadPool pool(threads);
  pool.parallel_for(
      count,
      [&](std::size_t i) {
        const int x = static_cast<int>(i % static_cast<std::size_t>(camera.width));
        const int y = static_cast<int>(i / static_cast<std::size_t>(camera.width));
        const glm::vec3 dir = rays.direction(x, y, 0.5f, 0.5f);
        const Hit hit = prepared->caster->intersect(Ray{rays.eye, 0.0f, dir});
        if (!hit.valid()) return;
        const ShadingTriangle& tri =
            prepared->index.triangles[prepared->index.instance_first[hit.instance] + hit.primitive];
        out.position_m[i] = tri.p0 + hit.barycentric.x * tri.e1 + hit.barycentric.y * tri.e2;
        out.normal[i] = glm::dot(tri.face_normal, dir) > 0.0f ? -tri.face_normal : tri.face_normal;
        out.hit[i] = 1;
      },
      256);
  return out;
}

engine::Result<IrradianceEstimate> estimate_irradiance(const ReferenceScene& scene,
                                                       std::span<const SurfacePoint> points,
                                                       const ReferenceSettings& settings, const WorkShard& shard) {
  if (auto ok = check_settings(settings); !ok) return ok.error();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const glm::vec3 p = points[i].position_m;
    const float nl = glm::length(points[i].normal);
    if (!std::isfinite(p.x + p.y + p.z) || !(std::fabs(nl - 1.0f) < 1e-3f))
      return settings_error("surface point " + std::to_string(i) + ": non-finite position or normal not unit length");
  }
  auto prepared = prepare(scene);
  if (!prepared) return prepared.error();
  const PathTracer tracer(scene, prepared->index, *prepared->caster, tracer_settings(settings));

  IrradianceEstimate out;
  out.direct.assign(points.size(), glm::vec3(0.0f));
  out.indirect.assign(points.size(), glm::vec3(0.0f));
  out.indirect_variance.assign(points.size(), glm::vec3(0.0f));
  const std::vector<std::size_t> items = shard.whole() ? std::vector<std::size_t>{} : shard.items(points.size());
  const std::size_t count = shard.whole() ? points.size() : items.size();
  ThreadPool pool(settings.threads);
  const bool completed = pool.parallel_for_with_progress(count, settings.progress, [&](std::size_t k) {
    const std::size_t i = shard.whole() ? k : items[k];
    Pcg32 rng = Pcg32::for_item(settings.seed, i);
    glm::dvec3 direct(0.0), indirect(0.0), indirect2(0.0);
    for (int s = 0; s < settings.samples_per_pixel; ++s) {
      const PathTracer::Irradiance e =
          tracer.irradiance(points[i].position_m, points[i].normal, rng, points[i].face_normal);
      direct += glm::dvec3(finite_or_zero(e.direct));
      const glm::dvec3 ind(finite_or_zero(e.indirect));
      indirect += ind;
      indirect2 += ind * ind;
    }
    const double n = static_cast<double>(settings.samples_per_pixel);
    out.direct[i] = glm::vec3(direct / n);
    out.indirect[i] = glm::vec3(indirect / n);
    if (n > 1.0) {
      const glm::dvec3 mean = indirect / n;
      out.indirect_variance[i] = glm::vec3(glm::max((indirect2 / n - mean * mean) * (n / (n - 1.0)), 0.0) / n);
    }
  });
  if (!completed) return engine::cancelled_error("irradiance estimate");
  return out;
}

engine::Result<engine::ImageRgbaF> render_reference_image(const engine::Scene& scene, engine::Entity camera, int width,
                                                          int height, const ReferenceSettings& settings) {
  const engine::Registry& reg = scene.registry;
  if (!reg.valid(camera) || !reg.has<engine::Camera>(camera) || !reg.has<engine::WorldTransform>(camera))
    return engine::Error{scene.assets.source, "camera", "no camera entity with Camera and WorldTransform"};
  const engine::Camera& cam = reg.get<engine::Camera>(camera);
  PinholeCamera pc;
  return render_reference_image(bake_input_from(scene),
                                {.camera_to_world = reg.get<engine::WorldTransform>(camera).matrix,
                                 .yfov_rad = cam.yfov_rad,
                                 .aspect = cam.aspect},
                                width, height, settings);
}

engine::Result<engine::ImageRgbaF> render_reference_image(const BakeInput& input, const ReferenceCamera& camera,
                                                          int width, int height, const ReferenceSettings& settings) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  PinholeCamera pc;
  pc.camera_to_world = camera.camera_to_world;
  pc.yfov_rad = camera.yfov_rad;
  pc.aspect = camera.aspect;
  pc.width = width;
  pc.height = height;
  return render_reference(reference_scene_from(input), pc, settings);
}

engine::Result<FirstHitImage> reference_first_hits(const BakeInput& input, const ReferenceCamera& camera, int width,
                                                   int height, unsigned threads) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  PinholeCamera pc;
  pc.camera_to_world = camera.camera_to_world;
  pc.yfov_rad = camera.yfov_rad;
  pc.aspect = camera.aspect;
  pc.width = width;
  pc.height = height;
  return first_hits(reference_scene_from(input), pc, threads);
}

engine::Result<IrradianceEstimate> reference_irradiance(const BakeInput& input, std::span<const SurfacePoint> points,
                                                        const ReferenceSettings& settings) {
  if (auto ok = validate_bake_input(input); !ok) return ok.error();
  return estimate_irradiance(reference_scene_from(input), points, settings);
}

engine::Result<IrradianceEstimate> reference_irradiance(const engine::Scene& scene,
                                                        std::span<const SurfacePoint> points,
                                                        const ReferenceSettings& settings) {
  return reference_irradiance(bake_input_from(scene), points, settings);
}

}  // namespace gi
