#pragma once
// What the planner's cost model needs to know about the static world, read cheaply from a
// scene (no ray traced, no layout built): world-space area, mean albedo, and an estimate of
// the light-atlas charts (near-coplanar connected pieces of each static instance, with the
// extent of each in its plane).
//   gi::StaticSurfaceCensus c = gi::census_static_surfaces(input);
//   double texels = c.area_m2 * d * d;  // the plain estimate; charts add their rims

#include <gi/bake_input.h>

#include <cstdint>
#include <vector>

namespace gi {

/// One estimated chart: a connected, coplanar piece of one static mesh instance.
struct ChartExtent {
  double area_m2 = 0.0;
  double width_m = 0.0;  ///< Sides of its minimal-area rectangle (over its edge directions), width >= height.
  double height_m = 0.0;
};

struct StaticSurfaceCensus {
  double area_m2 = 0.0;
  double albedo = 0.0;        ///< Area-weighted mean luminance of the base colour factors.
  std::size_t triangles = 0;  ///< Non-degenerate triangles (the bake's ray-tracing scene size).
  std::vector<ChartExtent> charts;
};

/// The Static instances of `input`.
StaticSurfaceCensus census_static_surfaces(const BakeInput& input);

}  // namespace gi
