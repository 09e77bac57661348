#include "system/method_table.h"

#include <GL/glcorearb.h>

#include <algorithm>
#include <array>

#include "bundle/manifest.h"
#include "transport/static_scene.h"

namespace gi {

std::span<const MethodRuntimeEntry> method_runtimes() {
  static constexpr std::array<MethodRuntimeEntry, 6> kTable{{
      {EffectMethod::LightAtlas, &load_light_atlas_method, std::nullopt, true},
      {EffectMethod::Prm, &load_prm_method, EffectMethod::LightAtlas, true},
      {EffectMethod::BasisRadianceFields, &load_brf_method, std::nullopt, true},
      {EffectMethod::DirectionalLightMaps, &load_dlm_method, std::nullopt, true},
      {EffectMethod::Antiradiance, &load_antiradiance_method, std::nullopt, false},
      {EffectMethod::ReflectionProbes, &load_reflection_probes_method, std::nullopt, false},
  }};
  return kTable;
}

bool in_manifest(const Manifest& manifest, EffectMethod m) {
  return manifest.methods.contains(std::string(method_descriptor(m).key));
}

bool MethodLoad::is_superseded(EffectMethod m) const {
  return std::find(superseded.begin(), superseded.end(), m) != superseded.end();
}

engine::Result<std::shared_ptr<const RayCaster>> MethodLoad::static_world() {
  if (!caster) {
    auto c = make_static_caster(input);
    if (!c) return c.error();
    caster = std::shared_ptr<const RayCaster>(std::move(c).value());
  }
  return caster;
}

std::uint32_t atlas_target_like(std::uint32_t source, engine::GlTexture& target) {
  if (target.empty()) {
    GLint w = 0, h = 0;
    glGetTextureLevelParameteriv(source, 0, GL_TEXTURE_WIDTH, &w);
    glGetTextureLevelParameteriv(source, 0, GL_TEXTURE_HEIGHT, &h);
    target = engine::GlTexture::create_2d(GL_RGBA32F, w, h);
    glTextureParameteri(target.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(target.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(target.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(target.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  return target.id();
}

}  // namespace gi
