#include <gtest/gtest.h>
#include <game_demo/input_frame.h>

#include <bit>
#include <cmath>
#include <limits>

namespace {

using game_demo::InputFrame;
using game_demo::Key;

TEST(InputFrame, SerializationRoundTripIsBitExact) {
  const InputFrame frames[] = {
      {},
      {.keys = game_demo::key_bit(Key::W) | game_demo::key_bit(Key::G), .mouse_dx_px = 3.25f, .mouse_dy_px = -0.1f},
      {.keys = 0x7f, .mouse_dx_px = -0.0f, .mouse_dy_px = std::numeric_limits<float>::denorm_min()},
      {.keys = game_demo::key_bit(Key::E), .mouse_dx_px = 1e30f, .mouse_dy_px = -123456.789f},
  };
  std::vector<std::byte> bytes;
  for (const InputFrame& f : frames) game_demo::append_input_frame(bytes, f);
  ASSERT_EQ(bytes.size(), std::size(frames) * game_demo::kInputFrameBytes);
  for (std::size_t i = 0; i < std::size(frames); ++i) {
    const auto back = game_demo::read_input_frame(std::span(bytes).subspan(i * game_demo::kInputFrameBytes));
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(back->keys, frames[i].keys);
    EXPECT_EQ(std::bit_cast<std::uint32_t>(back->mouse_dx_px), std::bit_cast<std::uint32_t>(frames[i].mouse_dx_px));
    EXPECT_EQ(std::bit_cast<std::uint32_t>(back->mouse_dy_px), std::bit_cast<std::uint32_t>(frames[i].mouse_dy_px));
  }
}

TEST(InputFrame, LayoutIsLittleEndian) {
  std::vector<std::byte> bytes;
  game_demo::append_input_frame(bytes, {.keys = 0x41, .mouse_dx_px = 1.0f, .mouse_dy_px = 0.0f});
  const std::vector<int> expected = {0x41, 0, 0, 0, 0x00, 0x00, 0x80, 0x3f, 0, 0, 0, 0};
  ASSERT_EQ(bytes.size(), expected.size());
  for (std::size_t i = 0; i < bytes.size(); ++i) EXPECT_EQ(std::to_integer<int>(bytes[i]), expected[i]) << i;
}

TEST(InputFrame, RejectsShortBuffersAndUnknownKeys) {
  std::vector<std::byte> bytes;
  game_demo::append_input_frame(bytes, {.keys = 1});
  EXPECT_FALSE(game_demo::read_input_frame(std::span(bytes).first(11)).has_value());
  bytes[1] = std::byte{0x04};  // bit 10: no such key (bit 9 is Down)
  EXPECT_FALSE(game_demo::read_input_frame(bytes).has_value());
}

TEST(InputFrame, HeldReportsEachKey) {
  const InputFrame in{.keys = game_demo::key_bit(Key::A) | game_demo::key_bit(Key::F)};
  EXPECT_TRUE(in.held(Key::A));
  EXPECT_TRUE(in.held(Key::F));
  EXPECT_FALSE(in.held(Key::W));
  EXPECT_FALSE(in.held(Key::E));
}

}  // namespace
