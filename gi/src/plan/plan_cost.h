#pragma once
// The planner's cost model: the work each baker does, counted from scene quantities and
// settings (texels, VPLs, path nodes, shadow rays, field samples), turned into bake seconds
// and runtime bytes with constants measured on this project's scenes (the calibration table
// in plan_cost.cpp says where each number comes from).
//   gi::AtlasWork w = gi::light_atlas_work(census, gi::light_atlas_preset("preview").value(), lights);
//   double s = w.bake_seconds;

#include <cstdint>
#include <vector>

#include "antiradiance/antiradiance_settings.h"
#include "brf/pca_basis.h"
#include "brf/radiance_field.h"
#include "dlm/dlm.h"
#include "light_atlas/light_atlas.h"
#include "plan/static_surface_census.h"
#include "prm/prm.h"
#include "reflection_probes/reflection_probes.h"

namespace gi {

/// The light sources a static bake shoots from.
struct LightPointCount {
  int punctual = 0;  ///< Point and spot lights (one point each, plus a flux check).
  int sampled = 0;   ///< Area lights and emissive triangles (area_light_samples points each).
  int directional = 0;
};

/// The light-atlas layout the census implies at a density (shared by the atlas and PRM).
struct AtlasTexelEstimate {
  double lit_texels = 0.0;   ///< Texels a triangle covers (the atlas's "texels lit").
  double pane_texels = 0.0;  ///< Lit texels plus the dilated gutter rings (PRM pane elements).
  /// Texels inside the charts' footprints: coarse PRM panes keep only these (docs/prm.md).
  double footprint_texels = 0.0;
  int width = 0;  ///< Packed atlas size (power of two, as gi's packer chooses).
  int height = 0;
};
AtlasTexelEstimate atlas_texels(const StaticSurfaceCensus& census, float texels_per_metre);

struct BakeWork {
  double rays = 0.0;          ///< Shadow rays the bake casts.
  double units = 0.0;         ///< The model's main quantity (texels x VPLs, path nodes, samples).
  double cpu_seconds = 0.0;   ///< CPU time (load-independent; what the constants were fitted to).
  double bake_seconds = 0.0;  ///< Wall time on 2 threads of a quiet machine.
  std::uint64_t runtime_bytes = 0;
};

BakeWork light_atlas_work(const StaticSurfaceCensus& census, const LightAtlasSettings& settings,
                          const LightPointCount& lights);

/// `path_nodes` out: the virtual lights the random walks leave (E x N_s x a / (1 - a)).
BakeWork prm_work(const StaticSurfaceCensus& census, const PrmSettings& settings, double* path_nodes = nullptr);

/// One distinct dynamic mesh (a basis and a field each, shared by all its instances);
/// `terms`: 1 for a diffuse mesh, 1 + glossy terms for a glossy one.
BakeWork brf_work(std::size_t vertex_count, std::size_t triangle_count, const PcaBasisSettings& basis,
                  const RadianceFieldSettings& field, int terms = 1);

/// Directional light maps over the glossy surfaces (`glossy`: the census of the glossy static
/// instances alone; `albedo`: the scene's mean albedo, which sets the photons' path length).
/// runtime_bytes: N directions x 8 B per stored texel (RGB halves padded to 8 bytes) plus the
/// atlas-sized texel index map (4 B per atlas texel of the scene's layout, `atlas`).
/// `bytes_per_texel` out: N x 8.
BakeWork dlm_work(const StaticSurfaceCensus& glossy, double albedo, const AtlasTexelEstimate& atlas,
                  const DlmSettings& settings, double* stored_texels = nullptr, double* bytes_per_texel = nullptr);

/// Antiradiance over a deforming region of `elements` hierarchy nodes, `leaves` of them
/// leaves (build_element_hierarchy's counts): links ~ 4.2 x bins per element; the bake links
/// them and solves the baseline. runtime_bytes: the GPU tables (exitant and incident per
/// node and bin, I_L and I_A per leaf and bin: 12 B each) and the 8-byte link records with
/// their (receiver, bin) runs. `links` out: the link estimate; `file_bytes` out: antiradiance.bin.
/// Near-door visibility (issue 37; settings.near_visibility, AntiradianceLighting): the
/// couplings of `receivers` leaves with all `leaves` at the baked pose, computed at load, not
/// baked (cpu_seconds: that load work, bake_seconds 0; units: the leaf pairs), and the memory the
/// runtime keeps on the CPU (runtime_bytes: the receivers' rows, a float coupling and 2 bytes of
/// kept visibility per 16 point pairs, per receiver and leaf). `move_seconds` out: a door move's near update.
BakeWork near_visibility_work(std::size_t leaves, std::size_t receivers, const AntiradianceSettings& settings,
                              double* move_seconds = nullptr);

BakeWork antiradiance_work(std::size_t elements, std::size_t leaves, const AntiradianceSettings& settings,
                           double* links = nullptr, double* file_bytes = nullptr);

/// Reflection probes: `probes` cube maps of settings.resolution^2 x 6 texels, supersample^2
/// rays per texel plus a shadow ray per static light point at each hit, then the prefilter.
/// runtime_bytes: RGBA16F cube maps with their mips (x 4/3) and 48 B per probe's box.
BakeWork reflection_probes_work(std::size_t probes, const ReflectionProbeSettings& settings, int light_points);

}  // namespace gi
