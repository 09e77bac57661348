#pragma once
// Depth textures of the shadow-casting lights and the pass that fills them: a 2-D array
// (spot, area lights), a 2-D array of its own size for directional lights (each covers the
// whole level) and a cube-map array (point lights), all compared in the shader
// (sampler*Shadow) against linear depth.

#include <vector>

#include <engine/gpu/gl_objects.h>
#include <engine/gpu/shader_program.h>

#include "render/program_uniforms.h"

#include "render/frame_data.h"
#include "render/gpu_scene.h"

namespace engine::render {

class ShadowMaps {
 public:
  /// Makes room for `layers_2d` maps of map_size^2, `sun_layers` maps of sun_size^2 and
  /// `cubes` cube maps of cube_size^2 per face (at least one of each so the samplers are
  /// always complete).
  void reserve(int map_size, int layers_2d, int sun_size, int sun_layers, int cube_size, int cubes);
  /// Renders into each view's layer the casters that can reach it (for perspective views,
  /// those whose bounds come within the view's far distance of its eye; every caster for
  /// orthographic ones). A layer whose view and reaching casters (mesh and transform) are
  /// what they were when it was last rendered is kept: static lights over static casters
  /// render once. A layer of a light that did not move whose dynamic casters did keeps its
  /// static casters' depth in a second texture: it is copied back and only the dynamic
  /// casters are drawn (the same texels as drawing every caster). Returns the number of
  /// views rendered.
  /// A view that would be drawn but whose volume the camera (`camera_view_proj`) cannot see
  /// into is not drawn and is drawn when it can (last_unseen_views()).
  /// Opaque primitives are drawn with `program`; MASK ones (at their cutoff) and BLEND ones
  /// (a cut-out at 0.5) with `cut_out_program`, shadow.frag.glsl with ALPHA_TEST (needed only
  /// when the scene has such materials, GpuScene::has_cut_out()).
  int render(const std::vector<ShadowView>& views, const std::vector<DrawItem>& items, const GpuScene& scene,
             const LocatedProgram<DepthUniforms>& program, const LocatedProgram<DepthUniforms>* cut_out_program,
             const glm::mat4& camera_view_proj);

  std::uint32_t maps_2d() const { return maps_[kMaps2d].texture.id(); }
  std::uint32_t sun_maps() const { return maps_[kSunMaps].texture.id(); }
  std::uint32_t cube_maps() const { return maps_[kCubeMaps].texture.id(); }
  /// Of the last render()'s views, those drawn over their cached static depth.
  int last_cached_views() const { return cached_views_; }
  /// Of the last render()'s views that changed, those left undrawn: the camera cannot see into them.
  int last_unseen_views() const { return unseen_views_; }

 private:
  /// A caster as drawn: mesh, transform and material override (its alpha cuts the shadow).
  struct Caster {
    const GpuMesh* mesh = nullptr;
    glm::mat4 model{1.0f};
    std::int32_t material_override = -1;
    bool operator==(const Caster& o) const {
      return mesh == o.mesh && model == o.model && material_override == o.material_override;
    }
  };
  /// What a layer holds: the view and its casters as last rendered.
  struct LayerContent {
    ShadowView view;
    std::vector<Caster> casters;
    bool operator==(const LayerContent& o) const;
  };
  /// One texture array and what its layers hold.
  struct MapArray {
    GlTexture texture;
    GlTexture static_cache;                    ///< The static depth cache: same size, made on first use.
    std::vector<LayerContent> content;         ///< Per layer (a cube array: cube * 6 + face).
    std::vector<LayerContent> static_content;  ///< Per layer: the view and static casters the cache holds.
    int size = 0;
    int layers = 0;  ///< Layers of a 2-D array; cubes of a cube array.
  };
  enum Kind : int { kMaps2d = 0, kSunMaps = 1, kCubeMaps = 2 };
  static Kind kind_of(const ShadowView& v) { return v.cube ? kCubeMaps : v.sun ? kSunMaps : kMaps2d; }
  void reserve_array(Kind kind, int size, int layers);
  void ensure_static_cache(Kind kind);
  /// Per view: every caster that can reach it, its static ones, its dynamic ones.
  struct ViewContents {
    std::vector<LayerContent> wanted;
    std::vector<LayerContent> wanted_static;
    std::vector<std::vector<Caster>> dynamic;
  };
  static ViewContents contents_of(const std::vector<ShadowView>& views, const std::vector<DrawItem>& items);
  /// The views whose layer holds other content than `wanted` and that the camera can see into
  /// (counts the others in unseen_views_).
  std::vector<std::size_t> stale_views(const std::vector<ShadowView>& views, const std::vector<LayerContent>& wanted,
                                       const glm::mat4& camera_view_proj);
  /// The programs a layer is drawn with and the materials they read.
  struct Programs {
    const GpuScene* scene = nullptr;
    const LocatedProgram<DepthUniforms>* opaque = nullptr;
    const LocatedProgram<DepthUniforms>* cut_out = nullptr;  ///< MASK and BLEND; null: none in the scene.
  };
  /// `casters` into the bound layer from `view`: opaque primitives first, then the cut-out ones.
  static void draw_casters(const std::vector<Caster>& casters, const ShadowView& view, const Programs& programs);
  /// View `k` (`v`) into its layer, over its static depth cache when only dynamic casters changed.
  void render_layer(const ShadowView& v, std::size_t k, ViewContents& contents, const Programs& programs);

  MapArray maps_[3];
  int cached_views_ = 0;
  int unseen_views_ = 0;
  GlFramebuffer framebuffer_;
};

}  // namespace engine::render
