#pragma once
// Indirect irradiance at points (atlas texels) gathered from a solved antiradiance hierarchy
// (Dachsbacher et al. 2007, §3.1 eq. 16 with a point receiver): each point is a receiver
// with its normal, linked to hierarchy nodes by the same solid-angle oracle as the solve
// (a node whose bounding sphere subtends at most oracle_scale x 4 pi / bins (link_mesh.cpp's threshold) is read as
// a whole, a larger one is opened; a leaf too near to pass is read through 16 disc points
// standing for it, each with its own distance and bin). A node contributes its exitant
// intensity I_ex = I_L - I_A in the bin of the direction towards the point, times the
// cosine at the point over the squared distance; the antiradiance leaving a door's back face
// takes away the light the door blocks, so the result has the structure of the texel's own
// position and normal (decimetres), not the leaves' (docs/antiradiance.md, "Output").
//   std::vector<glm::vec3> e = gi::gather_at_points(h, bins, settings, exitant, points);

#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "antiradiance/antiradiance_settings.h"
#include "antiradiance/directional_bins.h"
#include "antiradiance/element_hierarchy.h"

namespace gi {

/// A receiver point: world position (m) and unit normal.
struct GatherPoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
};

/// Indirect irradiance (W/m^2) at each point from `exitant` (nodes x bins RGB, row-major
/// [node][bin], W/sr: a solve's I_ex after its pull). Deterministic; runs the points in
/// parallel.
std::vector<glm::vec3> gather_at_points(const ElementHierarchy& h, const DirectionalBins& bins,
                                        const AntiradianceSettings& settings, std::span<const glm::vec3> exitant,
                                        std::span<const GatherPoint> points);

}  // namespace gi
