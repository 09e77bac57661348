#pragma once
// Baking basis radiance fields for a scene's dynamic meshes: the settings presets and the
// per-mesh bake (PCA basis, then the field around it), timed.
//   gi::BrfSettings s = gi::brf_preset("preview").value();
//   gi::BrfMeshBake b = gi::bake_brf_mesh(source, s).value();   // source: dynamic_brf_meshes()
//
// Presets (measured on the 24-vertex crate of assets/demo_level.gltf, 2 threads; see
// docs/brf.md "Bake"):
//   preview 128 lights, N = 16,  8 spheres x 6x8x8 points,   3 bands, 128 directions
//   medium  256 lights, N = 16, 12 spheres x 6x12x12 points, 3 bands, 128 directions
//   high    256 lights, N = 16, 16 spheres x 6x16x16 points, 3 bands, 256 directions (the paper's)
// Glossy meshes (BrfSource::glossy) get 4 glossy terms (preview, medium; the issue's
// default) or 8 (high) from a 16 x 16 hemisphere table (docs/sweeps/brf_glossy).

#include <engine/result.h>
#include <gi/progress.h>

#include <optional>
#include <string>
#include <string_view>

#include "brf/brf_mesh.h"
#include "brf/brf_model.h"
#include "brf/pca_basis.h"
#include "brf/radiance_field.h"

namespace gi {

/// Everything a BRF bake of one mesh depends on besides the mesh.
struct BrfSettings {
  PcaBasisSettings basis;
  RadianceFieldSettings field;
  BrdfSeparationSettings glossy;  ///< For glossy meshes only.
};

/// "preview", "medium" or "high" (above); error naming the valid names otherwise.
engine::Result<BrfSettings> brf_preset(std::string_view name);

/// What a bake of one dynamic mesh gives (and a brf_<name>.bin file holds, but the mesh).
struct BrfMeshBake {
  BrfModel model;              ///< name: BrfSource::name; mesh: the source's (empty as read_brf_mesh reads it).
  std::string mesh_hash;       ///< BrfSource::mesh_hash of the mesh baked.
  double basis_seconds = 0.0;  ///< Wall time of compute_pca_basis.
  double field_seconds = 0.0;  ///< Wall time of compute_basis_radiance_field.
};

/// Bakes `source.mesh`: for a glossy source separate_glossy_brdf with settings.glossy, then
/// compute_pca_basis with settings.basis, then compute_basis_radiance_field with
/// settings.field. `progress` gets the fraction done (the basis counts as the first 10%, the
/// field as the rest) and cancels by returning false. Errors: those of the steps, prefixed
/// with the source's name; cancellation (ErrorKind::Cancelled).
engine::Result<BrfMeshBake> bake_brf_mesh(const BrfSource& source, const BrfSettings& settings,
                                          const ProgressCallback& progress = {});

}  // namespace gi
