#include <engine/byte_stream.h>
#include <game_demo/input_frame.h>

namespace game_demo {

void append_input_frame(std::vector<std::byte>& out, const InputFrame& in) {
  engine::ByteWriter w(out);
  w.put<std::uint32_t>(in.keys);
  w.put<float>(in.mouse_dx_px);
  w.put<float>(in.mouse_dy_px);
}

std::optional<InputFrame> read_input_frame(std::span<const std::byte> bytes) {
  engine::ByteReader r(bytes);
  InputFrame in;
  if (!r.get<std::uint32_t>(in.keys) || !r.get<float>(in.mouse_dx_px) || !r.get<float>(in.mouse_dy_px))
    return std::nullopt;
  if ((in.keys >> kKeyCount) != 0) return std::nullopt;
  return in;
}

}  // namespace game_demo
