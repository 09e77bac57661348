#pragma once
// The linear-HDR forward renderer: direct light from point, spot, directional and
// rectangular area lights with shadow maps (cube maps for point lights), Lambert + GGX,
// indirect light through engine::IndirectLightProvider, exposure and tonemapping last.
//   auto ctx = engine::GpuContext::create_headless();              // engine/gpu/context.h
//   auto r = engine::Renderer::create(scene.assets, {.width = 640, .height = 360});
//   r.value()->render(scene.registry, engine::find_camera(scene.registry));
//   engine::save_png("frame.png", r.value()->read_ldr());

#include <memory>
#include <string>
#include <vector>

#include <engine/entity.h>
#include <engine/image.h>
#include <engine/indirect_light.h>
#include <engine/registry.h>
#include <engine/result.h>
#include <engine/scene_asset.h>

namespace engine {

/// G toggles the split screen: left half direct light only, right half direct + indirect.
enum class SplitView : std::uint8_t { Off, DirectLeftFullRight };

struct RenderSettings {
  int width = 960;
  int height = 540;
  /// Linear scale applied before tonemapping (exposure = 1 / (1.2 * 2^EV100) style factor).
  float exposure = 1.0f;
  int shadow_map_size = 1024;
  /// Radiance of the constant ambient stand-in used when no IndirectLightProvider is set,
  /// W/(m^2 sr) per channel; it is labelled "constant ambient (stand-in)" in timings.
  float stand_in_ambient = 0.02f;
  SplitView split = SplitView::Off;
};

/// Wall time of one render pass (GPU work measured with glFinish + a steady clock on
/// llvmpipe; see DESIGN.md section 4).
struct PassTiming {
  std::string name;
  double ms = 0.0;
};

class Renderer {
 public:
  /// Uploads meshes, materials and textures of `assets`. Needs a current GL 4.5 context.
  static Result<std::unique_ptr<Renderer>> create(const SceneAsset& assets, const RenderSettings& settings);
  virtual ~Renderer() = default;

  /// Draws the registry's MeshRenderer entities lit by its Light entities, seen from
  /// `camera` (an entity with Camera and WorldTransform), into the offscreen HDR target;
  /// then tonemaps into the LDR target (and, in a window, the default framebuffer).
  virtual void render(const Registry& registry, Entity camera) = 0;

  /// The tonemapped frame (sRGB, rows top to bottom).
  virtual ImageRgba8 read_ldr() const = 0;
  /// The linear HDR frame before exposure and tonemapping.
  virtual ImageRgbaF read_hdr() const = 0;

  /// Blits the LDR result into the currently bound default framebuffer (windowed demo).
  virtual void present(int window_width, int window_height) const = 0;

  virtual void set_indirect_light(IndirectLightProvider* provider) = 0;
  virtual RenderSettings& settings() = 0;
  /// Timings of the passes of the last render(), in execution order.
  virtual const std::vector<PassTiming>& last_timings() const = 0;
};

}  // namespace engine
