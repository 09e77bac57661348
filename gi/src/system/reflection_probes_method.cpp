// Reflection probes at run time: the baked cube maps uploaded once as one cube map array,
// their boxes as a buffer, handed to the renderer through the frame (engine/indirect_light.h,
// reflection_probe_*); the forward pass blends them per pixel (docs/reflection_probes.md).

#include <GL/glcorearb.h>

#include <vector>

#include "reflection_probes/reflection_probes_io.h"
#include "system/method_table.h"

namespace gi {

namespace {

class ReflectionProbesMethod final : public MethodRuntime {
 public:
  explicit ReflectionProbesMethod(ReflectionProbeSet set) : set_(std::move(set)) {}

  void frame(FrameState& state) override {
    if (cubes_.empty()) upload();
    engine::IndirectLightFrame& f = state.frame;
    f.reflection_probe_cubes = engine::TextureHandle{cubes_.id()};
    f.reflection_probe_buffer = engine::SsboHandle<engine::ReflectionProbeBox>{boxes_.id()};
    f.reflection_probe_distances = engine::TextureHandle{distances_.id()};
    f.reflection_probe_count = static_cast<int>(set_.probes.size());
    f.reflection_probe_levels = levels_;
    f.reflection_probe_max_roughness = set_.settings.max_roughness;
    f.reflection_probe_lobe_samples = kProbeLobeSamples;
    f.reflection_probe_lobe_samples_max = kProbeGrazingLobeSamples;
  }
  std::string label() const override { return "reflection probes"; }

 private:
  // One cube per probe, every level; then the cube maps' CPU copy is released.
  void upload() {
    const int size = set_.settings.resolution;
    levels_ = full_mip_count(size);
    const int count = static_cast<int>(set_.probes.size());
    cubes_ = engine::GlTexture::create_cube_array(GL_RGBA16F, size, count, levels_);
    for (int i = 0; i < count; ++i)
      for (int m = 0; m < levels_; ++m) {
        const int s = cube_level_size(size, m);
        const std::vector<glm::vec3>& level =
            set_.cubes[static_cast<std::size_t>(i)].levels[static_cast<std::size_t>(m)];
        glTextureSubImage3D(cubes_.id(), m, 0, 0, 6 * i, s, s, 6, GL_RGB, GL_FLOAT, level.data());
      }
    glTextureParameteri(cubes_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(cubes_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    // Each probe's distances (one level, kProbeDistanceScale x level 0's size; the file's check
    // holds every probe's to the first's), read bilinearly by the parallax search.
    const int ds = count > 0 ? cube_distance_size(set_.cubes.front()) : size;
    distances_ = engine::GlTexture::create_cube_array(GL_R32F, ds, count, 1);
    for (int i = 0; i < count; ++i)
      glTextureSubImage3D(distances_.id(), 0, 0, 0, 6 * i, ds, ds, 6, GL_RED, GL_FLOAT,
                          set_.cubes[static_cast<std::size_t>(i)].distance.data());
    glTextureParameteri(distances_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(distances_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    std::vector<engine::ReflectionProbeBox> boxes;
    for (const ProbeVolume& v : set_.probes)
      boxes.push_back({glm::vec4(v.centre, 0.0f), glm::vec4(v.box_min, 0.0f), glm::vec4(v.box_max, 0.0f)});
    boxes_ = engine::GlBuffer::create(boxes.size() * sizeof(engine::ReflectionProbeBox), boxes.data());
    set_.cubes.clear();
    set_.cubes.shrink_to_fit();
  }

  ReflectionProbeSet set_;
  int levels_ = 0;
  engine::GlTexture cubes_, distances_;
  engine::GlBuffer boxes_;
};

}  // namespace

engine::Result<std::unique_ptr<MethodRuntime>> load_reflection_probes_method(MethodLoad& load) {
  auto set = load_reflection_probes(load.bundle_dir, load.input);
  if (!set) return set.error();
  std::uint64_t bytes = 0;
  for (const ProbeCube& c : set->cubes) {
    bytes += c.distance.size() * 4;
    for (const auto& level : c.levels) bytes += level.size() * 8;
  }
  load.text << "reflection probes: " << set->probes.size() << " probes of " << set->settings.resolution << "^2 x 6 ("
            << static_cast<double>(bytes) / 1e6 << " MB on the GPU); roughness < " << set->settings.max_roughness
            << " and dynamic objects, parallax from the captured distances, per pixel\n";
  if (set->probes.empty()) return std::unique_ptr<MethodRuntime>();
  return std::unique_ptr<MethodRuntime>(new ReflectionProbesMethod(std::move(set).value()));
}

}  // namespace gi
