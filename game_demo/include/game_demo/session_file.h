#pragma once
// Recorded play sessions (.girec): the inputs of every fixed step and the state checksum
// after it, with a header naming the scene and the settings they were recorded with.
//   game_demo::Session s;  s.header.scene_path = "assets/demo_level.gltf";  s.frames.push_back({in, sum});
//   engine::Status ok = game_demo::save_session("walk.girec", s);  auto back = game_demo::load_session("walk.girec");
//
// File layout, all integers little-endian, floats by IEEE bit pattern:
//   offset 0   8 bytes  magic "GIREC\0\r\n"
//          8   u32      format version (kSessionFormatVersion)
//         12   u32      reserved, 0
//         16   u64      FNV-1a 64 checksum of every byte from offset 24 to the end
//         24   u32      length L of the scene path in bytes (1..4096), then L bytes UTF-8
//              u64      hash of the scene file bytes (hash_scene_file)
//              u64      seed
//              u32 u32  width, height in pixels (1..16384)
//              f64      fixed step in seconds (0 < dt < 1)
//              u32      frame count N (<= kMaxSessionFrames)
//              N x 20   per frame: InputFrame (u32 keys, f32 mouse dx, f32 mouse dy), u64 state checksum
// Nothing may follow the last frame.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <engine/result.h>

#include <game_demo/input_frame.h>

namespace game_demo {

inline constexpr std::uint32_t kSessionFormatVersion = 1;
inline constexpr std::uint32_t kMaxSessionFrames = 10'000'000;  ///< ~46 h at 60 Hz
inline constexpr std::uint32_t kMaxScenePathBytes = 4096;

struct SessionHeader {
  std::string scene_path;        ///< The scene as given on the command line when recording.
  std::uint64_t scene_hash = 0;  ///< hash_scene_file() of that scene when recording.
  std::uint64_t seed = 0;
  std::uint32_t width = 960;  ///< Render size of the recording, pixels.
  std::uint32_t height = 540;
  double fixed_dt_s = 1.0 / 60.0;
};

struct SessionFrame {
  InputFrame input;
  std::uint64_t checksum = 0;  ///< State checksum after this step.
  friend bool operator==(const SessionFrame&, const SessionFrame&) = default;
};

struct Session {
  SessionHeader header;
  std::vector<SessionFrame> frames;
};

/// Serializes a session (layout above).
std::vector<std::byte> encode_session(const Session& session);

/// Parses a session; `file` names the source in errors. Rejects bad magic, other format
/// versions, truncated or oversized data, absurd header values and checksum mismatches,
/// each with a message saying which.
engine::Result<Session> decode_session(std::span<const std::byte> bytes, const std::string& file);

/// Writes a session to a temporary file beside `path`, then renames it into place.
engine::Status save_session(const std::filesystem::path& path, const Session& session);

/// Reads and decodes a session file.
engine::Result<Session> load_session(const std::filesystem::path& path);

/// FNV-1a 64 of the scene file's bytes; for a .gltf also of the external buffers and
/// images it references (their URIs and bytes), so regenerating any of them is noticed.
engine::Result<std::uint64_t> hash_scene_file(const std::filesystem::path& path);

}  // namespace game_demo
