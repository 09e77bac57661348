// The basis radiance fields' baker (bake/method_bakers.h): one field per dynamic mesh, save.
#include <chrono>
#include <string>

#include "bake/bake_options.h"
#include "bake/bake_stage.h"
#include "bake/method_bakers.h"
#include "brf/brf_bake.h"
#include "brf/brf_io.h"
#include "brf/brf_mesh.h"

namespace gi {

engine::Status bake_brf_method(const MethodBake& job) {
  const BakeInput& input = job.input;
  const BakeOptions& o = job.options;
  const BakeHost& host = job.host;
  Timings& timings = job.timings;
  auto settings = brf_settings(o);
  if (!settings) return settings.error();
  auto sources = dynamic_brf_meshes(input);
  if (!sources) return sources.error();
  const BakeStage header{host, "BRF"};
  const PcaBasisSettings& b = settings->basis;
  const RadianceFieldSettings& f = settings->field;
  header.log(
      format_line("basis radiance fields of %s, preset %s: %zu dynamic meshes; %d lights, N = %d, %d spheres x 6x%dx%d "
                  "points, %d SH bands, %d directions",
                  scene_file_name(input).c_str(), o.preset.c_str(), sources->size(), b.lights, b.basis, f.spheres,
                  f.face_resolution, f.face_resolution, f.sh_bands, f.directions));
  if (sources->empty()) {
    header.log("  no dynamic mesh: nothing to bake");
    return {};
  }
  BrfBake bake{.settings = *settings, .meshes = {}};
  for (const BrfSource& s : *sources) {
    const BakeStage stage{host, "BRF " + s.name};
    auto mesh = bake_brf_mesh(s, *settings, stage.progress());
    if (!mesh) return mesh.error();
    stage.log(
        format_line("  %-16s %6zu vertices, %zu instances, basis %d of %d kept, condition %.3g, field %.2f MB, %.2f s",
                    s.name.c_str(), s.mesh.positions.size(), s.instances.size(), mesh->model.basis.basis_count, b.basis,
                    mesh->model.basis.condition, static_cast<double>(mesh->model.field.bytes()) / 1e6,
                    mesh->basis_seconds + mesh->field_seconds));
    if (mesh->model.glossy)
      stage.log(format_line("  %-16s glossy (GGX alpha %.3f, f0 %.2f): %d BRDF terms, weighted BRDF error %.2f", "",
                            static_cast<double>(mesh->model.glossy->lobe.alpha),
                            static_cast<double>(mesh->model.glossy->lobe.f0), mesh->model.glossy->terms,
                            static_cast<double>(mesh->model.glossy->relative_error)));
    timings[s.name] = {{"basis_seconds", mesh->basis_seconds}, {"field_seconds", mesh->field_seconds}};
    bake.meshes.push_back(std::move(mesh).value());
  }
  return save_brf(job.dir, bake, input);
}

}  // namespace gi
