#pragma once
// CPU images and their files: tonemapped PNG and linear OpenEXR.
//   engine::ImageRgba8 ldr = renderer.read_ldr();
//   engine::save_png("frame_0001.png", ldr);

#include <cstdint>
#include <filesystem>
#include <vector>

#include <engine/result.h>

namespace engine {

/// 8-bit RGBA, sRGB-encoded, rows top to bottom.
struct ImageRgba8 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  ///< width*height*4
};

/// 32-bit float RGBA, linear, rows top to bottom.
struct ImageRgbaF {
  int width = 0;
  int height = 0;
  std::vector<float> pixels;  ///< width*height*4
};

/// Writes a PNG (temporary file + rename).
Status save_png(const std::filesystem::path& path, const ImageRgba8& image);
/// Reads a PNG into RGBA8.
Result<ImageRgba8> load_png(const std::filesystem::path& path);
/// Channel precision of a written OpenEXR.
enum class ExrPixelType : std::uint8_t {
  Half,   ///< 16-bit floats: pictures (11-bit mantissa, max 65504).
  Float,  ///< 32-bit floats: data that must round-trip bit-exactly (baked irradiance).
};

/// Writes a linear OpenEXR (RGBA; temporary file + rename, so readers never see a half file).
Status save_exr(const std::filesystem::path& path, const ImageRgbaF& image, ExrPixelType type = ExrPixelType::Half);
/// What load_exr accepts: one scanline part (no tiles, parts or deep data) of at most
/// kMaxExrSide texels per side and kMaxExrPixels in all, in a file of at most kMaxExrFileBytes.
inline constexpr std::int64_t kMaxExrSide = 32768;
inline constexpr std::int64_t kMaxExrPixels = std::int64_t{1} << 28;
inline constexpr std::uintmax_t kMaxExrFileBytes = std::uintmax_t{4} << 30;
/// Reads an OpenEXR into RGBA32F. The header is checked against the limits above before
/// anything is sized from it; errors name the file.
Result<ImageRgbaF> load_exr(const std::filesystem::path& path);

}  // namespace engine
