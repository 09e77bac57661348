#include <engine/byte_stream.h>
#include <game_demo/session_file.h>
#include <game_demo/state_checksum.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <system_error>
#include <nlohmann/json.hpp>

namespace game_demo {

namespace {

constexpr char kMagic[8] = {'G', 'I', 'R', 'E', 'C', '\0', '\r', '\n'};
constexpr std::size_t kChecksummedFrom = 24;
constexpr std::size_t kFrameBytes = kInputFrameBytes + 8;

std::uint64_t fnv_of(std::span<const std::byte> bytes) {
  Fnv1a64 h;
  h.bytes(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
  return h.value();
}

engine::Result<std::vector<std::uint8_t>> read_bytes(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    return engine::Error{path.string(), "", "no such file (or not a regular file)"};
  std::ifstream in(path, std::ios::binary);
  if (!in) return engine::Error{path.string(), "", "cannot open for reading"};
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) return engine::Error{path.string(), "", "read error"};
  return bytes;
}

std::string at(std::size_t offset) { return "byte " + std::to_string(offset); }

}  // namespace

std::vector<std::byte> encode_session(const Session& s) {
  GI_EXPECTS(!s.header.scene_path.empty() && s.header.scene_path.size() <= kMaxScenePathBytes,
             "a session names its scene (at most 4096 bytes)");
  GI_EXPECTS(s.frames.size() <= kMaxSessionFrames, "session too long");
  std::vector<std::byte> out;
  out.reserve(kChecksummedFrom + 64 + s.header.scene_path.size() + s.frames.size() * kFrameBytes);
  engine::ByteWriter w(out);
  w.put_bytes(kMagic, sizeof kMagic);
  w.put<std::uint32_t>(kSessionFormatVersion);
  w.put<std::uint32_t>(0);
  w.put<std::uint64_t>(0);  // checksum, patched below
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.header.scene_path.size()));
  w.put_bytes(s.header.scene_path.data(), s.header.scene_path.size());
  w.put<std::uint64_t>(s.header.scene_hash);
  w.put<std::uint64_t>(s.header.seed);
  w.put<std::uint32_t>(s.header.width);
  w.put<std::uint32_t>(s.header.height);
  w.put<double>(s.header.fixed_dt_s);
  w.put<std::uint32_t>(static_cast<std::uint32_t>(s.frames.size()));
  for (const SessionFrame& f : s.frames) {
    append_input_frame(out, f.input);
    w.put<std::uint64_t>(f.checksum);
  }
  const std::uint64_t sum = fnv_of(std::span(out).subspan(kChecksummedFrom));
  for (int i = 0; i < 8; ++i) out[16 + static_cast<std::size_t>(i)] = static_cast<std::byte>(sum >> (8 * i));
  return out;
}

engine::Result<Session> decode_session(std::span<const std::byte> bytes, const std::string& file) {
  auto fail = [&](std::string location, std::string message) {
    return engine::Error{file, std::move(location), std::move(message)};
  };
  if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
    return fail("header", "not a recorded session: bad magic (expected \"GIREC\")");
  engine::ByteReader r(bytes.subspan(sizeof kMagic));
  std::uint32_t version = 0, reserved = 0;
  std::uint64_t stored_sum = 0;
  if (!r.get<std::uint32_t>(version)) return fail("header", "truncated: file ends inside the header");
  if (version != kSessionFormatVersion)
    return fail("header", "unsupported format version " + std::to_string(version) + " (this build reads version " +
                              std::to_string(kSessionFormatVersion) + ")");
  if (!r.get<std::uint32_t>(reserved) || !r.get<std::uint64_t>(stored_sum))
    return fail("header", "truncated: file ends inside the header");
  // Outside the checksum: a nonzero value would load and be re-saved as 0 (found by fuzzing).
  if (reserved != 0) return fail("header", "reserved field is " + std::to_string(reserved) + ", must be 0");

  Session s;
  SessionHeader& h = s.header;
  std::uint32_t path_len = 0;
  if (!r.get<std::uint32_t>(path_len)) return fail("header", "truncated: file ends inside the header");
  if (path_len == 0 || path_len > kMaxScenePathBytes)
    return fail(at(kChecksummedFrom), "absurd scene path length " + std::to_string(path_len) + " (1.." +
                                          std::to_string(kMaxScenePathBytes) + ")");
  std::uint32_t frame_count = 0;
  if (!r.get_chars(h.scene_path, path_len) || !r.get<std::uint64_t>(h.scene_hash) || !r.get<std::uint64_t>(h.seed) ||
      !r.get<std::uint32_t>(h.width) || !r.get<std::uint32_t>(h.height) || !r.get<double>(h.fixed_dt_s) ||
      !r.get<std::uint32_t>(frame_count))
    return fail("header", "truncated: file ends inside the header");
  if (h.width == 0 || h.height == 0 || h.width > 16384 || h.height > 16384)
    return fail("header", "absurd render size " + std::to_string(h.width) + "x" + std::to_string(h.height));
  if (!(h.fixed_dt_s > 0.0 && h.fixed_dt_s < 1.0))
    return fail("header", "absurd fixed step " + std::to_string(h.fixed_dt_s) + " s (must be in (0, 1))");
  if (frame_count > kMaxSessionFrames)
    return fail("header", "absurd frame count " + std::to_string(frame_count) + " (at most " +
                              std::to_string(kMaxSessionFrames) + ")");
  const std::size_t frames_at = sizeof kMagic + r.offset();
  const std::size_t need = std::size_t{frame_count} * kFrameBytes;
  if (r.remaining() < need)
    return fail(at(frames_at), "truncated: header declares " + std::to_string(frame_count) +
                                   " frames but the file holds " + std::to_string(r.remaining() / kFrameBytes));
  if (r.remaining() > need)
    return fail(at(frames_at + need), std::to_string(r.remaining() - need) + " unexpected bytes after the last frame");
  const std::uint64_t actual_sum = fnv_of(bytes.subspan(kChecksummedFrom));
  if (actual_sum != stored_sum) return fail("header", "contents corrupted: checksum mismatch");

  s.frames.resize(frame_count);
  for (std::uint32_t i = 0; i < frame_count; ++i) {
    const std::size_t off = frames_at + std::size_t{i} * kFrameBytes;
    const std::optional<InputFrame> in = read_input_frame(bytes.subspan(off, kInputFrameBytes));
    if (!in) return fail(at(off), "frame " + std::to_string(i) + ": key mask has unknown bits");
    engine::ByteReader cr(bytes.subspan(off + kInputFrameBytes, 8));
    s.frames[i].input = *in;
    (void)cr.get<std::uint64_t>(s.frames[i].checksum);
  }
  return s;
}

engine::Status save_session(const std::filesystem::path& path, const Session& session) {
  const std::vector<std::byte> bytes = encode_session(session);
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return engine::Error{tmp.string(), "", "cannot open for writing"};
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.flush();
    if (!out) {
      std::error_code ec;
      std::filesystem::remove(tmp, ec);
      return engine::Error{tmp.string(), "", "write failed"};
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    return engine::Error{path.string(), "", "cannot rename the temporary file into place: " + ec.message()};
  }
  return {};
}

engine::Result<Session> load_session(const std::filesystem::path& path) {
  auto bytes = read_bytes(path);
  if (!bytes) return bytes.error();
  return decode_session(std::as_bytes(std::span(*bytes)), path.string());
}

engine::Result<std::uint64_t> hash_scene_file(const std::filesystem::path& path) {
  auto bytes = read_bytes(path);
  if (!bytes) return bytes.error();
  Fnv1a64 h;
  h.bytes(*bytes);
  if (path.extension() == ".gltf") {
    const nlohmann::json doc = nlohmann::json::parse(bytes->begin(), bytes->end(), nullptr, false);
    if (!doc.is_discarded() && doc.is_object()) {
      for (const char* list : {"buffers", "images"}) {
        const auto it = doc.find(list);
        if (it == doc.end() || !it->is_array()) continue;
        for (const nlohmann::json& item : *it) {
          if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
          const std::string uri = item["uri"].get<std::string>();
          if (uri.rfind("data:", 0) == 0) continue;  // embedded: already hashed with the file
          h.bytes(std::span(reinterpret_cast<const std::uint8_t*>(uri.data()), uri.size()));
          auto ext = read_bytes(path.parent_path() / uri);
          if (ext)
            h.bytes(*ext);
          else
            h.u64(0);  // missing: the loader will say so
        }
      }
    }
  }
  return h.value();
}

}  // namespace game_demo
