#include "sweep/reference_sweep.h"

#include <engine/scene.h>
#include <gi/reference.h>

#include <chrono>
#include <string>

#include "core/stopwatch.h"
#include "raytrace/atlas_reference.h"
#include "uv/atlas_input.h"
#include "uv/atlas_layout.h"
#include "uv/atlas_rasterizer.h"

namespace gi {
namespace {

// References draw from other random streams than the runs they judge: a run at N spp with
// the same seed would repeat the reference's first N samples and look better than it is.
constexpr std::uint64_t kReferenceSeed = 0x7265666572656e63ULL;

engine::Error request_error(const ReferenceRequest& r, const std::string& message) {
  return engine::Error{"<sweep>", r.key(), message};
}

int int_param(const ReferenceRequest& r, const char* name) { return std::stoi(r.param(name)); }

// The entity made from the scene's camera number `index` (SceneAsset::cameras order).
engine::Entity camera_entity(const engine::Scene& scene, int index) {
  for (std::size_t n = 0; n < scene.assets.nodes.size(); ++n)
    if (scene.assets.nodes[n].camera == index) return scene.node_entities[n];
  return engine::Entity{};
}

RgbField field_from(int w, int h, const std::vector<float>& rgba) {
  RgbField f;
  f.width = w;
  f.height = h;
  f.rgb.resize(3 * f.count());
  for (std::size_t i = 0; i < f.count(); ++i)
    for (std::size_t c = 0; c < 3; ++c) f.rgb[3 * i + c] = rgba[4 * i + c];
  return f;
}

engine::Result<RgbField> render_camera(const SweepScene& s, const ReferenceRequest& r, ReferenceSettings settings) {
  const engine::Scene scene = engine::instantiate(s.asset);
  const engine::Entity camera = camera_entity(scene, int_param(r, "camera"));
  if (camera.is_null()) return request_error(r, "the scene has no such camera");
  const int w = int_param(r, "width"), h = int_param(r, "height");
  auto image = render_reference_image(scene, camera, w, h, settings);
  if (!image) return image.error();
  return field_from(w, h, image->pixels);
}

engine::Result<RgbField> atlas_indirect(const SweepScene& s, const ReferenceRequest& r, ReferenceSettings settings) {
  const TexelPlacement placement =
      r.param("texels") == "visible_surface" ? TexelPlacement::VisibleSurface : TexelPlacement::Raster;
  // The light atlas's truth is what it bakes: the static world under the static lights.
  // Moving lights are the PRM's and dynamic objects BRF's (a reference with them measured the
  // demo level's swinging lamp and crates as 25% atlas error whatever the atlas spent).
  auto truth = reference_atlas(static_world(bake_input_from(engine::instantiate(s.asset))),
                               std::stof(r.param("texels_per_m")), settings, placement);
  if (!truth) return truth.error();
  return RgbField::from_texels(truth->width, truth->height, truth->indirect, truth->valid, truth->indirect_variance);
}

// Converged-reference settings: the request's spp, the reference seed, unlimited bounces.
ReferenceSettings reference_settings(const ReferenceJob& job) {
  ReferenceSettings settings;
  settings.samples_per_pixel = int_param(job.request, "spp");
  settings.seed = kReferenceSeed;
  settings.threads = job.threads;
  settings.progress = job.progress;
  return settings;
}

}  // namespace

BakeInput static_world(BakeInput input) {
  std::erase_if(input.lights, [](const BakeLight& l) { return l.light.moves; });
  std::erase_if(input.instances, [](const BakeInstance& i) { return i.mobility != BakeMobility::Static; });
  return input;
}

void register_reference_sweep(SweepRegistry& registry) {
  registry.add_reference_provider({.kind = "camera_image", .version = "pt-1", .compute = [](const ReferenceJob& job) {
                                     return render_camera(job.scene, job.request, reference_settings(job));
                                   }});
  // pt-3: a texel's rays below its triangle's face are dropped (the shading normal may lean off
  // it; pt-2 counted the front of the texel's own surface as indirect light).
  // pt-4: and so is the sun's and the lights' light from below the face, and the rays leave
  // along the face (the light atlas's direct_at; pt-3 lit a leaning texel by a sun behind it).
  registry.add_reference_provider(
      {.kind = "atlas_indirect_irradiance", .version = "pt-4", .compute = [](const ReferenceJob& job) {
         return atlas_indirect(job.scene, job.request, reference_settings(job));
       }});

  SweepMethod pt;
  pt.name = "pathtracer";
  pt.description = "the reference path tracer itself: samples per pixel and bounce limit vs a converged render";
  pt.knobs = {
      {.name = "spp",
       .description = "samples per pixel",
       .kind = KnobKind::Integer,
       .default_grid = {"1", "4", "16", "64", "256", "1024"},
       .min_value = 1,
       .max_value = 1 << 20},
      {.name = "bounces",
       .description = "indirect bounces (-1: unlimited, Russian roulette)",
       .kind = KnobKind::Integer,
       .default_grid = {"-1"},
       .min_value = -1,
       .max_value = 1000},
      {.name = "size",
       .description = "image width and height, pixels",
       .kind = KnobKind::Integer,
       .default_grid = {"128"},
       .min_value = 8,
       .max_value = 4096},
  };
  pt.reference_for = [](const SweepScene&, const KnobSetting& k) {
    const int size = static_cast<int>(k.integer("size"));
    return ReferenceRequest::camera_image(0, size, size, kConvergedReferenceSpp);
  };
  pt.run = [](const RunContext& ctx) -> engine::Result<MethodOutput> {
    ReferenceSettings settings;
    settings.samples_per_pixel = static_cast<int>(ctx.knobs.integer("spp"));
    settings.max_bounces = static_cast<int>(ctx.knobs.integer("bounces"));
    settings.seed = ctx.seed;
    settings.threads = ctx.threads;
    settings.progress = ctx.progress;
    const auto start = std::chrono::steady_clock::now();
    auto field = render_camera(ctx.scene, ctx.request, settings);
    if (!field) return field.error();
    MethodOutput out;
    out.field = std::move(field.value());
    out.costs.bake_seconds = seconds_since(start);
    out.costs.bytes = out.field.rgb.size() * sizeof(float);
    return out;
  };
  registry.add_method(std::move(pt));
}

}  // namespace gi
