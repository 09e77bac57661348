#pragma once
// The runtime of an antiradiance region (docs/antiradiance.md) inside GISystem: watches
// the deforming instances' entities, and on a frame where one moved relinks only its
// elements, recomputes the direct light at the elements, runs the iteration on the GPU
// (antiradiance_gpu_pass.h; from the previous pose's solution after the first solve) and adds the change against the
// baked pose into the irradiance atlas (antiradiance_composite.comp.glsl). A frame where nothing moved does nothing;
// composite() re-adds the last change when the base atlas changed.
//   auto a = gi::AntiradianceLighting::create(std::move(bake), input, layout, scene.registry).value();
//   if (a->update()) { /* moved */ }  a->composite(base_texture, out_texture);

#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>
#include <engine/registry.h>
#include <engine/result.h>
#include <gi/bake_input.h>
#include <gi/log.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_texel_blend.h"
#include "uv/atlas_layout.h"

namespace gi {

class AntiradianceLighting {
 public:
  /// One covered atlas texel: its leaves and blend weights (antiradiance_texel_blend.h).
  using TexelBlendHost = AntiradianceTexelBlend;
  struct Stats {
    std::uint64_t updates = 0;          ///< Frames on which a deforming instance moved.
    std::size_t relinked_elements = 0;  ///< Last update: elements whose links were rebuilt.
    std::size_t links = 0;              ///< Links after it.
    std::size_t elements = 0;           ///< Elements of the region.
    std::size_t covered_texels = 0;     ///< Atlas texels the region's change reaches.
    double last_ms = 0.0;               ///< Last update: relink + direct light + GPU iteration (glFinish-timed).
    bool fell_back = false;             ///< Last update: the symmetric iteration grew.
    int iterations = 0;                 ///< Last update: iterations of the solve.
    double residual = 0.0;              ///< Last update: its final relative residual (sum |Delta I_ex| / sum |I_ex|).
    /// Last update: the iteration budget ran out before the residual tolerance (logged as a
    /// warning); the change shown is the last iterate's.
    bool unconverged = false;
    std::uint64_t unconverged_updates = 0;  ///< Updates that ended so.
    /// Last update: the solve started from the previous pose's solution (warm start), not
    /// from the direct light. An update back at the baked pose solves nothing (iterations 0).
    bool warm = false;
  };

  /// Errors: the bake does not fit `input` (AntiradianceRegion::create). `log` hears a
  /// warning for every solve that ends without converging.
  static engine::Result<std::unique_ptr<AntiradianceLighting>> create(AntiradianceBake bake, const BakeInput& input,
                                                                      const AtlasLayout& layout,
                                                                      const engine::Registry& registry,
                                                                      LogCallback log = {});

  /// Reads the deforming entities' world transforms; when one changed, solves (GL context
  /// current). True when it did. Errors of the GPU pass disable the method (stats().disabled).
  bool update();
  /// out = base + the region's change at the texels it covers, base elsewhere. Both
  /// textures RGBA32F of the atlas's size.
  void composite(std::uint32_t base_texture, std::uint32_t out_texture);

  const Stats& stats() const { return stats_; }
  const std::string& disabled() const { return disabled_; }

 private:
  AntiradianceLighting() = default;
  /// GL objects on first use (a context is current in frame()). False: disabled.
  bool ensure_gpu();
  /// The last update's solve (and the relink's counters) into stats_; warns when unconverged.
  void record(const AntiradianceSolveReport& report);
  /// Uploads delta = E(now) - baseline per leaf.
  void upload_delta(const std::vector<glm::vec3>& irradiance, float scale);
  std::vector<TexelBlendHost> blends_host_;
  std::unique_ptr<AntiradianceRegion> region_;
  const engine::Registry* registry_ = nullptr;
  std::vector<std::pair<std::uint32_t, engine::Entity>> deforming_;  ///< BakeInput instance, entity.
  std::optional<AntiradianceGpuPass> gpu_;
  engine::ShaderProgram program_;
  engine::GlBuffer blends_, delta_;
  std::uint32_t blend_count_ = 0;
  bool gpu_warm_startable_ = false;  ///< The GPU tables hold a converged solve.
  int width_ = 0, height_ = 0;
  Stats stats_;
  std::string disabled_;
  LogCallback log_;
};

}  // namespace gi
