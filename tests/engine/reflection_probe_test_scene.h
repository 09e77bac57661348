#pragma once
// The scene the reflection probes' GPU tests share (tests/engine/renderer_reflection_probes_test.cpp,
// gi/tests/system/reflection_probes_lobe_test.cpp): a 4 x 4 m glossy floor in a 4 x 3 x 4 m room
// (the probe's box) whose +X side may open into a hall, one probe at its centre handed to the
// renderer as the runtime hands it (cube-map array of all levels, optional R32F distances, the
// box in an SSBO), and an irradiance atlas of one texel. Engine only: the gi test passes its
// gi::ProbeCube's levels as plain vectors.
//   probe_test::GlossyFloor s(0.02f, probe_test::kOverTheFloor);
//   probe_test::ProbeProvider probe(64, levels, nullptr, {.atlas_irradiance = 2.0f});
#define GL_GLEXT_PROTOTYPES 1
#include <GL/glcorearb.h>

#include <engine/gltf_brdf.h>
#include <engine/gpu/gl_objects.h>
#include <engine/indirect_light.h>

#include <cmath>
#include <vector>

#include "renderer_test_scene.h"

namespace probe_test {

inline const glm::vec3 kRoomMin(-2.0f, 0.0f, -2.0f);
inline const glm::vec3 kRoomMax(2.0f, 3.0f, 2.0f);
inline const glm::vec3 kProbe(0.0f, 1.5f, 0.0f);
/// The hall's far wall: 3 m beyond the box's +X side.
inline constexpr float kHallEnd = 5.0f;

/// Where the ray from `from` (kProbe) along d leaves the room [kRoomMin, kRoomMax] stretched to x = far_x.
struct SideHit {
  float distance = 0.0f;
  int axis = 0;  ///< The side's axis; its sign is d[axis]'s.
  glm::vec3 point{0.0f};
};
inline SideHit side_hit(glm::vec3 d, float far_x, glm::vec3 from = kProbe) {
  const glm::vec3 hi(far_x, kRoomMax.y, kRoomMax.z);
  SideHit h{1e30f, 0, glm::vec3(0.0f)};
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) continue;
    const float ta = ((d[a] > 0.0f ? hi[a] : kRoomMin[a]) - from[a]) / d[a];
    if (ta < h.distance) h.distance = ta, h.axis = a;
  }
  h.point = from + h.distance * d;
  return h;
}

/// GL's cube-map face directions (OpenGL 4.6 table 8.19) for face coordinates u, v in [-1, 1].
inline glm::vec3 face_direction(int face, float u, float v) {
  switch (face) {
    case 0:
      return {1.0f, -v, -u};
    case 1:
      return {-1.0f, -v, u};
    case 2:
      return {u, 1.0f, v};
    case 3:
      return {u, -1.0f, -v};
    case 4:
      return {u, -v, 1.0f};
    default:
      return {-u, -v, -1.0f};
  }
}

/// One face-major, row-major level of face size s filled with f(unit direction of each texel centre).
template <typename T, typename F>
std::vector<T> cube_level(int s, const F& f) {
  std::vector<T> texels;
  texels.reserve(static_cast<std::size_t>(6 * s * s));
  for (int face = 0; face < 6; ++face)
    for (int y = 0; y < s; ++y)
      for (int x = 0; x < s; ++x) {
        const float u = (2.0f * static_cast<float>(x) + 1.0f) / static_cast<float>(s) - 1.0f;
        const float v = (2.0f * static_cast<float>(y) + 1.0f) / static_cast<float>(s) - 1.0f;
        texels.push_back(f(glm::normalize(face_direction(face, u, v))));
      }
  return texels;
}

struct ProbeFrameSettings {
  float atlas_irradiance = 0.0f;  ///< The atlas's one texel (W/m^2, grey).
  float max_roughness = 0.3f;
  int lobe_samples = 0;      ///< 0: the split sum's single read.
  int lobe_samples_max = 0;  ///< The most a grazing view takes; lobe_samples or less: a fixed count.
};

/// One probe of a ProbeProvider: where it was captured, its levels (face size size >> m each) and
/// its distances (a cube of any face size, 6 x n^2 values; null: none). Every probe's box is the room [kRoomMin,
/// kRoomMax].
struct ProbeLayer {
  glm::vec3 centre = kProbe;
  const std::vector<std::vector<glm::vec3>>* levels = nullptr;
  const std::vector<float>* distances = nullptr;
};

/// The probes handed to the renderer as the runtime hands them: their levels as one RGBA16F
/// cube-map array, their distances (when the first has them, all must) as one R32F array, the
/// boxes in an SSBO. The one-probe form: the probe at kProbe with box [kRoomMin, kRoomMax].
class ProbeProvider : public engine::IndirectLightProvider {
 public:
  ProbeProvider(int size, const std::vector<std::vector<glm::vec3>>& levels, const std::vector<float>* distances,
                const ProbeFrameSettings& s)
      : ProbeProvider(size, {ProbeLayer{kProbe, &levels, distances}}, s) {}
  ProbeProvider(int size, const std::vector<ProbeLayer>& probes, const ProbeFrameSettings& s) {
    const int count = static_cast<int>(probes.front().levels->size());
    const int layers = static_cast<int>(probes.size());
    atlas_ = engine::GlTexture::create_2d(GL_RGBA32F, 1, 1);
    const float texel[4] = {s.atlas_irradiance, s.atlas_irradiance, s.atlas_irradiance, 1.0f};
    glTextureSubImage2D(atlas_.id(), 0, 0, 0, 1, 1, GL_RGBA, GL_FLOAT, texel);
    cubes_ = engine::GlTexture::create_cube_array(GL_RGBA16F, size, layers, count);
    for (int i = 0; i < layers; ++i)
      for (int m = 0; m < count; ++m) {
        const int w = size >> m > 0 ? size >> m : 1;
        glTextureSubImage3D(cubes_.id(), m, 0, 0, 6 * i, w, w, 6, GL_RGB, GL_FLOAT,
                            (*probes[static_cast<std::size_t>(i)].levels)[static_cast<std::size_t>(m)].data());
      }
    glTextureParameteri(cubes_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTextureParameteri(cubes_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    if (probes.front().distances) {
      // Their face size from their count (the bake stores them finer than level 0).
      const int ds =
          static_cast<int>(std::lround(std::sqrt(static_cast<double>(probes.front().distances->size()) / 6.0)));
      distances_ = engine::GlTexture::create_cube_array(GL_R32F, ds, layers, 1);
      for (int i = 0; i < layers; ++i)
        glTextureSubImage3D(distances_.id(), 0, 0, 0, 6 * i, ds, ds, 6, GL_RED, GL_FLOAT,
                            probes[static_cast<std::size_t>(i)].distances->data());
      glTextureParameteri(distances_.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTextureParameteri(distances_.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      frame_.reflection_probe_distances = {distances_.id()};
    }
    std::vector<engine::ReflectionProbeBox> boxes;
    for (const ProbeLayer& p : probes)
      boxes.push_back({glm::vec4(p.centre, 0.0f), glm::vec4(kRoomMin, 0.0f), glm::vec4(kRoomMax, 0.0f)});
    boxes_ = engine::GlBuffer::create(boxes.size() * sizeof boxes[0], boxes.data());
    frame_.irradiance_atlas_texture = {atlas_.id()};
    frame_.reflection_probe_cubes = {cubes_.id()};
    frame_.reflection_probe_buffer = engine::SsboHandle<engine::ReflectionProbeBox>{boxes_.id()};
    frame_.reflection_probe_count = layers;
    frame_.reflection_probe_levels = count;
    frame_.reflection_probe_max_roughness = s.max_roughness;
    frame_.reflection_probe_lobe_samples = s.lobe_samples;
    frame_.reflection_probe_lobe_samples_max = s.lobe_samples_max;
  }
  const engine::IndirectLightFrame& frame() override { return frame_; }
  const char* label() const override { return "test room probe"; }

 private:
  engine::IndirectLightFrame frame_;
  engine::GlTexture atlas_, cubes_, distances_;
  engine::GlBuffer boxes_;
};

/// A static 4 x 4 m floor (grey 0.5, dielectric, `roughness`) at y = 0 and the camera `cam`.
struct GlossyFloor {
  engine::SceneAsset assets;
  engine::Registry reg;
  renderer_test::TestCamera cam;
  engine::Entity camera;
  float roughness;

  GlossyFloor(float r, const renderer_test::TestCamera& c) : cam(c), roughness(r) {
    assets.materials.push_back(renderer_test::diffuse_material(0.5f, r));
    assets.meshes.push_back(renderer_test::plane_mesh(2.0f, 0));
    renderer_test::add_mesh(reg, 0, glm::mat4(1.0f), /*is_static=*/true);
    camera = cam.add_to(reg);
  }
  [[nodiscard]] engine::GltfBrdf brdf() const { return engine::gltf_brdf(glm::vec3(0.5f), 0.0f, roughness); }
  /// The floor's directional albedo per lobe at floor point p seen from the camera.
  [[nodiscard]] engine::GltfBrdfValue albedo_at(glm::vec3 p) const {
    return engine::gltf_directional_albedo(brdf(), glm::normalize(cam.eye - p).y);
  }
};

}  // namespace probe_test
