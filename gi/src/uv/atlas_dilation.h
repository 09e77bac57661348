#pragma once
// Dilation of an atlas image: fills texels outside the charts from their valid neighbours,
// one ring per iteration, so bilinear lookups near chart borders never read empty texels.
//   std::vector<std::uint8_t> filled = gi::dilate<glm::vec4>(irradiance, w, h, texels.valid, 2);
//   upload(irradiance);  // no black seams
//
// Each iteration sets every invalid texel that has at least one valid texel among its 8
// neighbours to the mean of those neighbours, then marks it valid (values written in an
// iteration are not read in the same iteration, so the result does not depend on the scan
// order). With the layout's padding >= 2, one iteration makes every bilinear read at a point
// inside a triangle use only texels of that triangle's chart; more iterations fill more of
// the gutter (useful for mipmaps).

#include <cstdint>
#include <span>
#include <vector>
#include <glm/glm.hpp>

namespace gi {

/// Dilates `values` (width x height, texel (x, y) at y * width + x) in place where `valid`
/// is 0, `iterations` rings deep. Returns the grown validity mask. Instantiated for float,
/// glm::vec3 and glm::vec4. Preconditions: both spans hold width x height texels, iterations >= 0.
template <class Texel>
std::vector<std::uint8_t> dilate(std::span<Texel> values, int width, int height, std::span<const std::uint8_t> valid,
                                 int iterations);

/// For each texel, the texel of the valid mask whose value dilate() carries into it over the
/// same rings: itself where `valid`; where a ring fills it, the source of its first filled
/// neighbour in scan order (the 8 neighbours, row by row); -1 where no ring reaches it. Lets
/// data that is not an average (an index, a blend of leaves) follow the dilated image.
std::vector<std::int32_t> dilation_sources(int width, int height, std::span<const std::uint8_t> valid, int iterations);

/// The rings an irradiance atlas is dilated by: its gutter (the layout's padding), at least 4
/// so the mip chain's bilinear reads stay on filled texels. The light atlas, the PRM's atlas
/// read and antiradiance's texel blends grow the same rings.
inline int atlas_gutter_rings(int padding_texels) { return padding_texels > 4 ? padding_texels : 4; }

extern template std::vector<std::uint8_t> dilate<float>(std::span<float>, int, int, std::span<const std::uint8_t>, int);
extern template std::vector<std::uint8_t> dilate<glm::vec3>(std::span<glm::vec3>, int, int,
                                                            std::span<const std::uint8_t>, int);
extern template std::vector<std::uint8_t> dilate<glm::vec4>(std::span<glm::vec4>, int, int,
                                                            std::span<const std::uint8_t>, int);

}  // namespace gi
