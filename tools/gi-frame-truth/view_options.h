#pragma once
// gi-frame-truth's command-line forms of what it looks at (the light: tools/common):
//   --camera NAME=px,py,pz,tx,ty,tz[,yfov_deg]       a camera at p looking at t (default 60 degrees)
//   --region NAME:minx,miny,minz,maxx,maxy,maxz       a world box, metres
// Each parser returns nothing when the text is malformed (the tool says so and exits 2).
//   auto cam = parse_camera("floor=-10,1.7,1,8,3,-2,60");

#include <gi/frame_truth.h>

#include <optional>
#include <string>
#include <vector>
#include <glm/glm.hpp>

namespace frame_truth_tool {

/// N comma-separated finite numbers.
std::optional<std::vector<float>> parse_numbers(const std::string& text);
/// NAME=px,py,pz,tx,ty,tz[,yfov_deg]: a non-empty name, position != target, 1 < fov < 170 degrees.
std::optional<gi::FrameCamera> parse_camera(const std::string& text);
/// NAME:minx,miny,minz,maxx,maxy,maxz with min <= max.
std::optional<gi::WorldRegion> parse_region(const std::string& text);

}  // namespace frame_truth_tool
