#include "brf/brf_bake.h"

#include <chrono>
#include <utility>

#include "core/stopwatch.h"

namespace gi {

engine::Result<BrfSettings> brf_preset(std::string_view name) {
  BrfSettings s;
  if (name == "preview") {
    s.basis.lights = 128, s.basis.basis = 16;
    s.field.spheres = 8, s.field.face_resolution = 8, s.field.directions = 128;
  } else if (name == "medium") {
    s.basis.lights = 256, s.basis.basis = 16;
    s.field.spheres = 12, s.field.face_resolution = 12, s.field.directions = 128;
  } else if (name == "high") {
    s.basis.lights = 256, s.basis.basis = 16;
    s.field.spheres = 16, s.field.face_resolution = 16, s.field.directions = 256;
  } else {
    return engine::invalid_request("unknown BRF preset '" + std::string(name) + "' (preview, medium, high)");
  }
  s.field.sh_bands = 3;
  // docs/sweeps/brf_glossy: 4 terms are the cheapest on the front, 8 the most accurate.
  s.glossy.terms = name == "high" ? 8 : 4;
  s.glossy.resolution = 16;
  return s;
}

engine::Result<BrfMeshBake> bake_brf_mesh(const BrfSource& source, const BrfSettings& settings,
                                          const ProgressCallback& progress) {
  const auto prefixed = [&](engine::Error e) {
    e.message = "mesh \"" + source.name + "\": " + e.message;
    return e;
  };
  BrfMeshBake out;
  BrfModel& model = out.model;
  model.name = source.name;
  out.mesh_hash = source.mesh_hash;
  constexpr double kBasisShare = 0.1;
  if (progress && !progress(0.0)) return prefixed(engine::cancelled_error("basis radiance field bake"));
  auto start = std::chrono::steady_clock::now();
  if (source.glossy) {
    auto sep = separate_glossy_brdf(*source.glossy, settings.glossy);
    if (!sep) return prefixed(sep.error());
    model.glossy = std::move(sep).value();
  }
  const BrdfSeparation* glossy = model.glossy_lobe();
  auto basis = compute_pca_basis(source.mesh, settings.basis, glossy);
  if (!basis) return prefixed(basis.error());
  out.basis_seconds = seconds_since(start);
  if (progress && !progress(kBasisShare)) return prefixed(engine::cancelled_error("basis radiance field bake"));
  start = std::chrono::steady_clock::now();
  RadianceFieldSettings field_settings = settings.field;
  if (progress) field_settings.progress = [&](double f) { return progress(kBasisShare + (1.0 - kBasisShare) * f); };
  auto field = compute_basis_radiance_field(source.mesh, *basis, field_settings, glossy);
  if (!field) return prefixed(field.error());
  out.field_seconds = seconds_since(start);
  model.mesh = source.mesh;
  model.basis = std::move(basis).value();
  model.field = std::move(field).value();
  return out;
}

}  // namespace gi
