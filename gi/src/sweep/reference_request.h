#pragma once
// What reference a sweep run is compared against, as a kind (which provider computes it)
// and parameters, with a stable string key that names it in the cache.
//   gi::ReferenceRequest r = gi::ReferenceRequest::camera_image(0, 256, 256, 4096);
//   r.key();  // "camera_image(camera=0,height=256,spp=4096,width=256)"

#include <gi/reference.h>

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace gi {

struct ReferenceRequest {
  std::string kind;  ///< The ReferenceProvider::kind that computes it ([a-z0-9_]+).
  /// Everything the result depends on besides the scene; names and values must not
  /// contain , = ( ) or whitespace. Order does not matter: key() sorts them.
  std::vector<std::pair<std::string, std::string>> params;

  /// "kind(name=value,...)" with parameters sorted by name: equal requests, equal keys.
  /// Precondition: kind and params use no reserved characters.
  std::string key() const;
  /// The value of parameter `name`, or empty.
  std::string param(std::string_view name) const;

  /// Linear radiance seen from camera `camera_index` of the scene (its order in
  /// SceneAsset::cameras) at width x height pixels, `spp` samples per pixel.
  static ReferenceRequest camera_image(int camera_index, int width, int height, int spp);
  /// Indirect irradiance at the light-atlas texels of the scene's uv1 layout at
  /// `texels_per_m` atlas density, `spp` samples per texel.
  /// `placement` enters the key only when it is VisibleSurface.
  static ReferenceRequest atlas_indirect_irradiance(double texels_per_m, int spp,
                                                    TexelPlacement placement = TexelPlacement::Raster);
  /// The light atlas's split truth (atlas_split_truth.h: indirect and total irradiance
  /// stacked) at the same texels: the mean of two path-traced estimates of `spp` samples per
  /// texel each, with different seeds, and its noise from them.
  static ReferenceRequest atlas_split_truth(double texels_per_m, int spp, TexelPlacement placement);
};

}  // namespace gi
