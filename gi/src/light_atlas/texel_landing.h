#pragma once
// The landing reads of the texel gather (texel_gather.h): where one of its rays ends and what
// it reads there. The rules that keep a read to the light of the landing point: the gap rule
// (a surface facing the texel across a covered gap of under 0.05 texel is dark), the corners
// of the bilinear read whose samples do not see the point (samples moved off their surface),
// reads across a shadow edge, which take the lights' direct light at the point itself, and
// landings nearer than a texel, which take all their light at the point (a regather).
//   const gi::LandingTable lt = gi::landing_table(bake_scene, layout, table).value();
//   const gi::Landing l = gi::land_ray(bake_scene, lt, table, ray, table.face[i]);
//   if (l.texel < gi::kBack) radiosity = gi::read_landing(bake_scene, table, source, l, rng, rays);

#include <engine/result.h>

#include <cstdint>
#include <span>
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

/// What a landing reads of the scene and the atlas, packed so that one landing misses the
/// cache a few times instead of once per array (issue 35: on Dabrovic Sponza the landing code
/// was a third of the gather, stalled on atlas-sized arrays). The values are copies of the bake
/// scene's and the TexelTable's: reading them here computes the same landings.
struct LandingTable {
  static constexpr std::uint32_t kTexelMask = 0x3fffffffu, kMoved = 1u << 30, kSharp = 1u << 31;
  /// Per triangle of the caster: its unit face normal, whether its material is double-sided,
  /// its index.triangles entry and its atlas UV (uv1) at the corners; one cache line.
  struct alignas(64) Triangle {
    glm::vec3 face_normal{0.0f};
    std::uint32_t double_sided = 0;
    std::uint32_t triangle = 0;
    glm::vec2 uv[3]{};
  };
  /// Per atlas pixel: the valid texel it is read as (TexelTable::redirect) with that texel's
  /// `moved` flag and the pixel's shadow-edge flag (GatherSource::sharp) in its top bits, and
  /// that texel's albedo; 16 bytes.
  struct Pixel {
    std::uint32_t bits = kTexelMask;
    glm::vec3 albedo{0.0f};
  };

  std::vector<std::uint32_t> first;  // per caster instance: its first entry of `triangles`
  std::vector<Triangle> triangles;
  std::vector<Pixel> pixels;

  const Triangle& triangle_of(const Hit& h) const { return triangles[first[h.instance] + h.primitive]; }
  static std::uint32_t texel_of(const Pixel& p) {
    const std::uint32_t r = p.bits & kTexelMask;
    return r == kTexelMask ? kDark : r;
  }
};

/// The landing table of `t` (its `sharp` flags all 0: mark_sharp sets them). Errors: an atlas
/// of 2^30 texels or more (the texel ids share their word with the flags).
engine::Result<LandingTable> landing_table(const StaticBakeScene& b, const AtlasLayout& layout, const TexelTable& t);

/// Sets the table's shadow-edge flags from `sharp` (per atlas pixel, sharp_pixels).
void mark_sharp(LandingTable& lt, const std::vector<std::uint8_t>& sharp);

/// The shading normal at a landing on `tri` (barycentric u, v) seen from `side` (its face
/// normal turned towards the ray's origin), as the path tracer shades a hit (shading_brdf):
/// the interpolated vertex normal, turned over on the back of a double-sided surface, and
/// `side` itself where that normal still points below the surface (vertex normals opposite
/// their face: Dabrovic Sponza's column bases).
glm::vec3 landing_shading_normal(const ShadingTriangle& tri, glm::vec2 barycentric, const glm::vec3& side);

/// Casts `ray` from a texel whose face is `from` and says where it lands (Landing).
Landing land_ray(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const Ray& ray,
                 const glm::vec3& from);

/// land_ray of every ray of `rays` (all from a texel whose face is `from`) into `out`, the same
/// landings, but cast a few at a time before any lands, so that their reads' cache misses
/// overlap (out.size() == rays.size()).
void land_rays(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, std::span<const Ray> rays,
               const glm::vec3& from, std::span<Landing> out);

/// landing()'s texel of every ray of `rays`, as land_rays lands them.
void landings(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, std::span<const Ray> rays,
              const glm::vec3& from, std::span<std::uint32_t> out);

/// land_ray's texel alone (kSky, kBack, kDark or a texel), and its atlas UV in `uv` (if given)
/// when it lands on a surface; without the visibility rays of Landing::unseen_corners.
std::uint32_t landing(const StaticBakeScene& b, const LandingTable& lt, const TexelTable& t, const Ray& ray,
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
  const LandingTable* table = nullptr;  // the flags of `sharp` set (mark_sharp)
  int near_rays = 0;
  float near_m = 0.0f;
  /// A regather's own near landings regather again, down to this many levels (1: they read
  /// the texels); below the first level with `near_deep_rays` rays each (0: `near_rays`).
  int near_depth = 1;
  int near_deep_rays = 0;
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
/// the sky and the indirect light at the point, the last two from `near_rays` cosine rays read
/// where they land as a fresh ray's landing is (down to `src.near_depth` levels of regathers),
/// and the sky where they escape.
/// Rays it casts (the direct light's shadow rays) are added to `rays`.
glm::dvec3 read_landing(const StaticBakeScene& b, const TexelTable& t, const GatherSource& src, const Landing& l,
                        Pcg32& rng, std::uint64_t& rays);

/// Marks the pixels whose 3 x 3 neighbourhood of `lit` (rho E_d, dilated) holds a sharp change.
std::vector<std::uint8_t> sharp_pixels(const std::vector<glm::vec3>& lit, int w, int h);

}  // namespace gi
