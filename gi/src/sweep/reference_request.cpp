#include "sweep/reference_request.h"

#include <engine/check.h>

#include <algorithm>

#include "sweep/knob_spec.h"

namespace gi {
namespace {

bool plain(std::string_view s) {
  if (s.empty()) return false;
  return std::none_of(s.begin(), s.end(), [](char c) {
    return c == ',' || c == '=' || c == '(' || c == ')' || c == ' ' || c == '\t' || c == '\n' || c == '"';
  });
}

}  // namespace

std::string ReferenceRequest::key() const {
  GI_EXPECTS(plain(kind), "ReferenceRequest::kind must be non-empty without , = ( ) \" or whitespace");
  auto sorted = params;
  std::sort(sorted.begin(), sorted.end());
  std::string k = kind + "(";
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    GI_EXPECTS(plain(sorted[i].first) && plain(sorted[i].second),
               "ReferenceRequest parameters must be non-empty without , = ( ) \" or whitespace");
    GI_EXPECTS(i == 0 || sorted[i].first != sorted[i - 1].first, "ReferenceRequest parameter given twice");
    k += (i ? "," : "") + sorted[i].first + "=" + sorted[i].second;
  }
  return k + ")";
}

std::string ReferenceRequest::param(std::string_view name) const {
  for (const auto& [n, v] : params)
    if (n == name) return v;
  return {};
}

ReferenceRequest ReferenceRequest::camera_image(int camera_index, int width, int height, int spp) {
  return {"camera_image",
          {{"camera", std::to_string(camera_index)},
           {"width", std::to_string(width)},
           {"height", std::to_string(height)},
           {"spp", std::to_string(spp)}}};
}

ReferenceRequest ReferenceRequest::atlas_indirect_irradiance(double texels_per_m, int spp, TexelPlacement placement) {
  ReferenceRequest r{"atlas_indirect_irradiance",
                     {{"texels_per_m", format_number(texels_per_m)}, {"spp", std::to_string(spp)}}};
  // Raster keys (and cache files) are the ones from before the placement existed.
  if (placement == TexelPlacement::VisibleSurface) r.params.emplace_back("texels", "visible_surface");
  return r;
}

ReferenceRequest ReferenceRequest::atlas_split_truth(double texels_per_m, int spp, TexelPlacement placement) {
  return {"atlas_split_truth",
          {{"texels_per_m", format_number(texels_per_m)},
           {"spp", std::to_string(spp)},
           {"estimates", "2"},
           {"texels", placement == TexelPlacement::VisibleSurface ? "visible_surface" : "raster"}}};
}

}  // namespace gi
