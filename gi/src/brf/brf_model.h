#pragma once
// A rigid object's basis radiance field model, as the bake produces it and the runtime uses it.

#include <optional>
#include <string>

#include "brf/brdf_separation.h"
#include "brf/pca_basis.h"
#include "brf/radiance_field.h"

namespace gi {

/// One rigid object's baked data: the mesh (object space), its PCA basis and the basis
/// radiance field around it, and a glossy mesh's separated lobe (the basis and field were
/// baked with it; none: diffuse). The bake produces it (BrfMeshBake::model), the bundle
/// stores all of it but the mesh (the scene's, checked by hash and filled in at load), and
/// the CPU twin (brf_runtime.h), the GPU pass (brf_gpu_pass.h) and BrfLighting all take it.
///   gi::BrfModel crate{"crate", mesh, basis, field};
///   auto pass = gi::BrfGpuPass::create(std::span(&crate, 1)).value();
struct BrfModel {
  std::string name;  ///< BrfSource::name; for messages.
  BrfMesh mesh;
  BrfBasis basis;
  BasisRadianceField field;
  std::optional<BrdfSeparation> glossy;
  /// The glossy lobe or nullptr (diffuse).
  const BrdfSeparation* glossy_lobe() const { return glossy ? &*glossy : nullptr; }
};

}  // namespace gi
