#pragma once
// The one zstd stream a bake file may hold (PRM panes, BRF coefficients, antiradiance links):
// written as one frame recording its size and checksum, read back checked before anything
// is allocated for it:
//   auto frame = gi::write_zstd_stream(path, planes, 9);
//   auto planes = gi::read_zstd_stream(path, "panes", frame, clusters * texels * 6);
//   if (!planes) return planes.error();
// Header-only: the targets that use it link zstd (gi_core for the atlas layout file).

#include <zstd.h>
#include <engine/result.h>

#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "io/blob_file.h"

namespace gi {

/// Compresses `bytes` at `level` into one zstd frame with its content size and checksum
/// recorded (what read_zstd_stream requires). Errors name `path`.
inline engine::Result<std::vector<std::uint8_t>> write_zstd_stream(const std::filesystem::path& path,
                                                                   std::span<const std::uint8_t> bytes, int level) {
  const auto error = [&](const std::string& message) { return engine::Error{path.string(), "", message}; };
  std::vector<std::uint8_t> frame(ZSTD_compressBound(bytes.size()));
  ZSTD_CCtx* cctx = ZSTD_createCCtx();
  if (cctx == nullptr) return error("cannot create a zstd compression context");
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_compressionLevel, level);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_checksumFlag, 1);
  ZSTD_CCtx_setParameter(cctx, ZSTD_c_contentSizeFlag, 1);
  const std::size_t packed = ZSTD_compress2(cctx, frame.data(), frame.size(), bytes.data(), bytes.size());
  ZSTD_freeCCtx(cctx);
  if (ZSTD_isError(packed) != 0) return error(std::string("zstd compression failed: ") + ZSTD_getErrorName(packed));
  frame.resize(packed);
  return frame;
}

/// Decompresses `frame`, which must be exactly one zstd frame recording its content size,
/// that size equal to `expected` (what the file's own counts need) and at most
/// kMaxDecompressedBytes, and the frame large enough for it (a block holds at most 128 KiB
/// and takes at least 4 bytes). Errors name `path` and `location` (the stream's field).
inline engine::Result<std::vector<std::uint8_t>> read_zstd_stream(const std::filesystem::path& path,
                                                                  const std::string& location,
                                                                  std::span<const std::uint8_t> frame,
                                                                  std::uint64_t expected) {
  const auto error = [&](const std::string& message) { return engine::Error{path.string(), location, message}; };
  const unsigned long long content = ZSTD_getFrameContentSize(frame.data(), frame.size());
  if (content == ZSTD_CONTENTSIZE_ERROR || content == ZSTD_CONTENTSIZE_UNKNOWN)
    return error("not a zstd frame with a recorded size (corrupt)");
  if (content > kMaxDecompressedBytes)
    return error("the zstd frame would decompress to " + std::to_string(content) + " bytes, above the " +
                 std::to_string(kMaxDecompressedBytes) + "-byte limit of a bake stream");
  if (content != expected)
    return error("the zstd frame holds " + std::to_string(content) + " bytes, the file's counts need " +
                 std::to_string(expected));
  const std::size_t frame_bytes = ZSTD_findFrameCompressedSize(frame.data(), frame.size());
  if (ZSTD_isError(frame_bytes) != 0 || frame_bytes != frame.size())
    return error("not exactly one zstd frame (corrupt)");
  if (content / 131072 > frame.size() / 4 + 1)
    return error("the zstd frame is too small for the size it claims (corrupt)");
  std::vector<std::uint8_t> out(static_cast<std::size_t>(content));
  const std::size_t unpacked = ZSTD_decompress(out.data(), out.size(), frame.data(), frame.size());
  if (ZSTD_isError(unpacked) != 0)
    return error(std::string("zstd decompression failed: ") + ZSTD_getErrorName(unpacked));
  if (unpacked != out.size())
    return error("decompressed " + std::to_string(unpacked) + " bytes, " + std::to_string(out.size()) + " expected");
  return out;
}

}  // namespace gi
