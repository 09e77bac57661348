#pragma once
// One simulation step's worth of player input: held keys and the mouse movement since the
// previous step. Produced by GLFW (windowed), a ScriptedPilot (headless) or a session file.
//   game_demo::InputFrame in{.keys = game_demo::key_bit(game_demo::Key::W), .mouse_dx_px = 4.0f};
//   if (in.held(game_demo::Key::W)) ...

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace game_demo {

/// The keys the demo reacts to. Movement keys (W, A, S, D, Up, Down) act while held; F, E, G
/// and O act on the step where they go from released to held (edge-triggered in the
/// gameplay systems).
enum class Key : std::uint8_t {
  W = 0,     ///< forward
  A = 1,     ///< strafe left
  S = 2,     ///< backward
  D = 3,     ///< strafe right
  F = 4,     ///< toggle the flashlight
  E = 5,     ///< push the crate in front of the camera
  G = 6,     ///< toggle the split screen (direct only | full)
  O = 7,     ///< close / open the corridor door (a deforming node: antiradiance relights it)
  Up = 8,    ///< fly up (Locomotion::Fly; the window maps Space)
  Down = 9,  ///< fly down (Locomotion::Fly; the window maps C)
};
inline constexpr int kKeyCount = 10;

/// The bit of `k` in InputFrame::keys.
constexpr std::uint32_t key_bit(Key k) { return 1u << static_cast<std::uint32_t>(k); }

struct InputFrame {
  std::uint32_t keys = 0;    ///< Bitmask of held keys (key_bit).
  float mouse_dx_px = 0.0f;  ///< Mouse movement since the previous step, pixels, +x right.
  float mouse_dy_px = 0.0f;  ///< Mouse movement since the previous step, pixels, +y down.

  constexpr bool held(Key k) const { return (keys & key_bit(k)) != 0; }
  friend bool operator==(const InputFrame&, const InputFrame&) = default;
};

/// Live keys for a front end that polls once per rendered frame while the simulation steps
/// at a fixed rate: at 2-3 frames/s a key pressed and released between two polls was never
/// seen (the flashlight ignored a quick F). press() on every key-down event (GLFW's key
/// callback queues them); keys(held) is what is held now plus what was pressed since the
/// last step that used it; stepped() after a simulation step consumed the keys.
class KeyLatch {
 public:
  void press(Key k) { pressed_ |= key_bit(k); }
  std::uint32_t keys(std::uint32_t held) const { return held | pressed_; }
  void stepped() { pressed_ = 0; }

 private:
  std::uint32_t pressed_ = 0;
};

/// Size of one serialized InputFrame in bytes.
inline constexpr std::size_t kInputFrameBytes = 12;

/// Appends `in` as 12 little-endian bytes: u32 keys, f32 mouse_dx_px, f32 mouse_dy_px
/// (floats by bit pattern, so the round trip is exact).
void append_input_frame(std::vector<std::byte>& out, const InputFrame& in);

/// Reads one InputFrame from the first 12 bytes of `bytes`; nullopt when there are fewer
/// bytes or the key mask has bits no key uses.
std::optional<InputFrame> read_input_frame(std::span<const std::byte> bytes);

}  // namespace game_demo
