#pragma once
// The runtime of an antiradiance region (docs/antiradiance.md) inside GISystem: watches
// the deforming instances' entities, and on a frame where one moved relinks only its
// elements, recomputes the direct light at the elements, runs the iteration on the GPU
// (antiradiance_gpu_pass.h; from the previous pose's solution after the first solve) and adds the change against the
// baked pose into the irradiance atlas (antiradiance_composite.comp.glsl). A frame where nothing moved does nothing;
// composite() re-adds the last change when the base atlas changed. With the bake's
// near_visibility, the leaves near each deforming instance take their change from a
// NearDoorVisibility (ray-traced visibility, on the CPU after the GPU solve's read-back).
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
#include <utility>
#include <vector>

#include "antiradiance/antiradiance_gpu_pass.h"
#include "antiradiance/antiradiance_region.h"
#include "antiradiance/antiradiance_texel_blend.h"
#include "antiradiance/near_door_visibility.h"
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
    /// Near-door visibility (issue 37; the bake's settings.near_visibility): the leaves near a
    /// deforming instance gather with ray-traced visibility (NearDoorVisibility), the others
    /// keep the GPU solve. On when the bake asked for it and every near set was made at load.
    bool near_visibility = false;
    /// The bake asked for it but a near set could not be made (logged as a warning, the
    /// reason in near_fell_back_reason()): antiradiance alone.
    bool near_fell_back = false;
    std::size_t near_receivers = 0;    ///< Leaves that gather with visibility (all near sets).
    std::size_t near_table_bytes = 0;  ///< Their couplings and kept visibility on the CPU (bytes).
    double near_load_ms = 0.0;         ///< The baked pose's couplings and solve, at load.
    double near_ms = 0.0;              ///< Last update: the near sets' couplings' update + solve (part of last_ms).
    std::size_t near_rays = 0;         ///< Last update: rays the near sets cast.
    std::size_t near_pairs = 0;        ///< Last update: leaf pairs they recomputed.
    int near_iterations = 0;           ///< Last update: Jacobi iterations of the near solve (the most of any set).
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
  /// out = base with the region's change at the texels it covers (composite_change: light added
  /// is added, light lost is lost as a share), base elsewhere. Both textures RGBA32F of the
  /// atlas's size.
  void composite(std::uint32_t base_texture, std::uint32_t out_texture);

  const Stats& stats() const { return stats_; }
  const std::string& disabled() const { return disabled_; }
  /// Why near-door visibility fell back (empty: it did not).
  const std::string& near_fell_back_reason() const { return near_reason_; }
  /// The change per leaf the last update uploaded (W/m^2; what composite() blends into the
  /// atlas): the near sets' receivers' move result minus their baseline, the GPU solve's
  /// change elsewhere. Empty before the first update.
  const std::vector<glm::vec3>& leaf_change() const { return leaf_change_; }
  /// The change's zero per leaf (W/m^2): the near sets' baseline at their receivers, the
  /// region's elsewhere; w: the composite's share (composite_change), 1 at the receivers (a
  /// loss taken as a share of their light), 0 elsewhere (added).
  std::vector<glm::vec4> leaf_baseline() const;
  /// The last update's GPU solve per leaf (read back, energy guard applied): what the near
  /// sets held the other leaves at. Empty before the first solve.
  const std::vector<glm::vec3>& solved_irradiance() const { return solved_; }

 private:
  AntiradianceLighting() = default;
  /// GL objects on first use (a context is current in frame()). False: disabled.
  bool ensure_gpu();
  /// The last update's solve (and the relink's counters) into stats_; warns when unconverged.
  void record(const AntiradianceSolveReport& report);
  /// Makes a NearDoorVisibility per deforming instance with receivers (region at its baked
  /// pose); on failure none, logged, stats_.near_fell_back.
  void create_near_sets(const BakeInput& input);
  /// leaf_change_ = E(now) - baseline per leaf, the near sets' receivers replaced by theirs
  /// (after moving them as `moved` says); then uploaded.
  void upload_change(const std::vector<std::pair<std::uint32_t, glm::mat4>>& moved);
  /// The near sets' part of upload_change: moves them, puts their receivers' change in leaf_change_.
  void near_change(const std::vector<std::pair<std::uint32_t, glm::mat4>>& moved);
  void clear_near_stats();
  /// One near set: its instance and the class (which holds its receivers, near_door_receivers).
  struct NearSet {
    std::uint32_t instance = 0;
    std::unique_ptr<NearDoorVisibility> visibility;
  };
  std::vector<NearSet> near_;
  /// Per leaf, the index in near_ of the set that holds it (the first whose receivers include
  /// it; its change and baseline are that set's), -1 for none. Made with near_.
  std::vector<std::int32_t> near_owner_;
  std::string near_reason_;
  std::vector<glm::vec3> solved_, leaf_change_;
  std::vector<TexelBlendHost> blends_host_;
  std::unique_ptr<AntiradianceRegion> region_;
  const engine::Registry* registry_ = nullptr;
  std::vector<std::pair<std::uint32_t, engine::Entity>> deforming_;  ///< BakeInput instance, entity.
  std::optional<AntiradianceGpuPass> gpu_;
  engine::ShaderProgram program_;
  engine::GlBuffer blends_, delta_, baseline_;
  std::uint32_t blend_count_ = 0;
  bool gpu_warm_startable_ = false;  ///< The GPU tables hold a converged solve.
  int width_ = 0, height_ = 0;
  Stats stats_;
  std::string disabled_;
  LogCallback log_;
};

}  // namespace gi
