// Directional light maps at run time: the glossy static surfaces' bins, uploaded once, drawn
// at the uv1 of the static world's atlas; the renderer integrates the specular lobe against
// them for the view, per pixel.

#include "dlm/dlm_io.h"
#include "system/dlm_lighting.h"
#include "system/method_table.h"

namespace gi {

namespace {

class DlmMethod final : public MethodRuntime {
 public:
  explicit DlmMethod(std::unique_ptr<DlmLighting> lighting) : lighting_(std::move(lighting)) {}
  void frame(FrameState& state) override { lighting_->fill(state.frame); }
  std::string label() const override { return "DLM"; }

 private:
  std::unique_ptr<DlmLighting> lighting_;
};

}  // namespace

engine::Result<std::unique_ptr<MethodRuntime>> load_dlm_method(MethodLoad& load) {
  auto d = load_dlm(load.bundle_dir, load.input);
  if (!d) return d.error();
  if (load.atlas_width == 0)
    return engine::Error{(load.bundle_dir / kDlmFile).string(), "",
                         "directional light maps need the light atlas's (or PRM's) uv1 layout, and the bundle has "
                         "neither (bake atlas too)"};
  const int directions = static_cast<int>(d->directions.size());
  const std::size_t glossy = d->stats.glossy_texels;
  auto l = DlmLighting::from_bake(std::move(d).value(), load.atlas_width, load.atlas_height);
  if (!l) {
    engine::Error e = l.error();
    e.file = (load.bundle_dir / kDlmFile).string();
    return e;
  }
  std::unique_ptr<DlmLighting> dlm = std::move(l).value();
  load.stats.dlm_texels = dlm->texels();
  load.stats.dlm_gpu_bytes = dlm->gpu_bytes();
  load.text << "DLM: " << directions << " directions x " << dlm->texels() << " texels (" << glossy
            << " on glossy static surfaces, " << static_cast<double>(dlm->gpu_bytes()) / 1e6
            << " MB on the GPU); specular lobe vs the view, per pixel\n";
  return std::unique_ptr<MethodRuntime>(new DlmMethod(std::move(dlm)));
}

}  // namespace gi
