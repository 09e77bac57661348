#pragma once
// The light of docs/real_level.md for the diagnosis programs of a real level: the scene loaded
// untextured, under the gradient sky (zenith 10, 16, 30; horizon 28, 30, 34; ground 6, 6, 6
// W/(m^2 sr)) and a sun of 700, 650, 600 W/m^2 from (0.25, -1, 0.15), 0.27 degrees wide:
// the sweeps' `--untextured --sky ... --sun ...` on Dabrovic Sponza.
//   auto asset = gi_bench::load_untextured_under_sun_and_sky(path);

#include <engine/gltf.h>
#include <engine/result.h>
#include <engine/sun.h>
#include <gi/bake_input.h>

#include <string>
#include <utility>

namespace gi_bench {

inline engine::Result<engine::SceneAsset> load_untextured_under_sun_and_sky(const std::string& path) {
  auto loaded = engine::load_gltf(path);
  if (!loaded) return loaded.error();
  engine::SceneAsset asset = gi::without_textures(std::move(loaded).value());
  asset.environment.sky_radiance = glm::vec3(0.0f);
  asset.environment.sky_gradient = {.zenith = {10, 16, 30}, .horizon = {28, 30, 34}, .ground = {6, 6, 6}};
  engine::set_sun(asset, {.direction = {0.25f, -1.0f, 0.15f},
                          .irradiance = {700.0f, 650.0f, 600.0f},
                          .angular_radius_rad = 0.27f * 3.14159265f / 180.0f});
  return asset;
}

}  // namespace gi_bench
