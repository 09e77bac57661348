#include "uv/atlas_density.h"

#include <string>

namespace gi {

engine::Result<float> atlas_density_preset(std::string_view preset) {
  if (preset == "preview") return 8.0f;
  if (preset == "medium") return 16.0f;
  if (preset == "high") return 32.0f;
  return engine::invalid_request("unknown preset '" + std::string(preset) + "' (preview, medium, high)");
}

}  // namespace gi
