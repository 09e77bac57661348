#pragma once
// The landing reads of the texel gather (texel_gather.h): where one of its rays ends and what
// it reads there. The rules that keep a read to the light of the landing point: the gap rule
// (a surface facing the texel across a covered gap of under 0.05 texel is dark), the corners
// of the bilinear read whose samples do not see the point (samples moved off their surface),
// reads across a shadow edge, which take the lights' direct light at the point itself, and
// landings nearer than a texel, which take all their light at the point (a regather).
//   const gi::Landing l = gi::land_ray(bake_scene, layout, table, ray, table.face[i]);
//   if (l.texel < gi::kBack) radiosity = gi::read_landing(bake_scene, table, source, l, rng, rays);

#include <cstdint>
#include <vector>
#include <glm/glm.hpp>

#include "core/random.h"
#include "light_atlas/texel_table.h"
#include "raytrace/ray.h"
#include "transport/static_scene.h"
#include "uv/atlas_layout.h"

namespace gi {

/// Where a ray from a texel whose face is `from` ends: kSky, kBack (the back of a one-sided
/// surface, or a surface facing `from` across a covered gap of under 0.05 texel: the gap rule)
/// or the atlas texel it reads (a valid texel, redirected from an empty one); on a surface also
/// the atlas UV of the hit, the atlas texel under it as it is (`pixel`, maybe empty), the
/// distance and |cos| at the surface, and the hit itself (its triangle, barycentrics, the side
/// the ray came from).
struct Landing {
  std::uint32_t texel = kSky;
  glm::vec2 uv{0.0f};
  std::uint32_t pixel = kDark;
  float distance = 0.0f, cos_surface = 0.0f;
  std::uint32_t triangle = 0;
  glm::vec2 barycentric{0.0f};
  glm::vec3 side{0.0f};  // the hit triangle's unit face normal turned towards the ray's origin
  // Bit k: the sample of the bilinear read's corner k does not see the landing point (its
  // light is not the point's).
  std::uint8_t unseen_corners = 0;
};

/// The shading normal at a landing on `tri` (barycentric u, v) seen from `side` (its face
/// normal turned towards the ray's origin), as the path tracer shades a hit (shading_brdf):
/// the interpolated vertex normal, turned over on the back of a double-sided surface, and
/// `side` itself where that normal still points below the surface (vertex normals opposite
/// their face: Dabrovic Sponza's column bases).
glm::vec3 landing_shading_normal(const ShadingTriangle& tri, glm::vec2 barycentric, const glm::vec3& side);

/// Casts `ray` from a texel whose face is `from` and says where it lands (Landing).
Landing land_ray(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t, const Ray& ray,
                 const glm::vec3& from);

/// land_ray's texel alone (kSky, kBack, kDark or a texel), and its atlas UV in `uv` (if given)
/// when it lands on a surface; without the visibility rays of Landing::unseen_corners.
std::uint32_t landing(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t, const Ray& ray,
                      const glm::vec3& from, glm::vec2* uv);

/// What step 3's rays read, per atlas pixel (dilated): rho (E_d + E) of every texel, the same
/// without the lights' direct light, rho (sky + E), and where the lights' direct light changes
/// sharply (`sharp`: in the pixel's 3 x 3 neighbourhood the dimmest is under half the
/// brightest, a shadow edge crossing it).
struct GatherSource {
  std::vector<glm::vec3> reflected, without_lights;
  std::vector<std::uint8_t> sharp;
  /// With `punctual_everywhere`: rho (E_d + E) without the punctual lights' direct light
  /// (DirectLights::Punctual), which landings off the `sharp` pixels take at their point.
  std::vector<glm::vec3> without_punctual;
  bool punctual_everywhere = false;
  /// Landings nearer than `near_m` take the sky and the indirect light at the point itself
  /// from `near_rays` cosine rays (a second gather one level down, reading `reflected`)
  /// instead of reading them from the texels (0 rays: never).
  const AtlasLayout* layout = nullptr;
  int near_rays = 0;
  float near_m = 0.0f;
};

/// A texel holds the light at its one sample point. Where a shadow edge crosses it, the light
/// of another point of the texel can be anything between its neighbours': in a 5 cm slot
/// under a slab of Dabrovic Sponza, the floor's texel straddles the slot's mouth, its sample
/// lies in the sun, and rays from the slab's underside that land in the dark slot read that
/// sun (issue 35, "Noise against floor"). There the read takes the lights' direct light at the
/// landing point itself (one sample of each light, unbiased) and only the rest bilinearly;
/// with `src.punctual_everywhere`, elsewhere too for the punctual lights (point, spot,
/// directional, the sun), whose one ray at the point is sharp where an area light's one
/// sample is noise.
/// Bilinear corners whose samples do not see the point (Landing::unseen_corners) are left out;
/// where none does, that direct light is all the read takes. A landing nearer than
/// `src.near_m` (with `src.near_rays` > 0) reads no texel of its own: the lights' direct light,
/// the sky and the indirect light at the point, the last two from `near_rays` cosine rays
/// reading `reflected` where they land (with the same corner rule) and the sky where they escape.
/// Rays it casts (the direct light's shadow rays) are added to `rays`.
glm::dvec3 read_landing(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l,
                        Pcg32& rng, std::uint64_t& rays);

/// Marks the pixels whose 3 x 3 neighbourhood of `lit` (rho E_d, dilated) holds a sharp change.
std::vector<std::uint8_t> sharp_pixels(const std::vector<glm::vec3>& lit, int w, int h);

}  // namespace gi
