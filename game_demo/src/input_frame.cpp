#include <game_demo/input_frame.h>

#include "byte_io.h"

namespace game_demo {

void append_input_frame(std::vector<std::uint8_t>& out, const InputFrame& in) {
  detail::ByteWriter w(out);
  w.u32(in.keys);
  w.f32(in.mouse_dx_px);
  w.f32(in.mouse_dy_px);
}

std::optional<InputFrame> read_input_frame(std::span<const std::uint8_t> bytes) {
  detail::ByteReader r(bytes);
  InputFrame in;
  if (!r.u32(in.keys) || !r.f32(in.mouse_dx_px) || !r.f32(in.mouse_dy_px)) return std::nullopt;
  if ((in.keys >> kKeyCount) != 0) return std::nullopt;
  return in;
}

}  // namespace game_demo
