// Fuzz target: recorded play sessions (.girec, game_demo::decode_session, what
// game_demo::load_session parses). Every input is "re-sealed" first (the FNV-1a checksum at
// offset 16 set to that of bytes 24..end) so mutations reach the header and frame checks
// (the checksum check itself has its unit tests, tests/demo/replay_test.cpp). Check:
// a session that decodes encodes back to exactly the bytes decoded (one encoding per session).
#include <game_demo/session_file.h>
#include <game_demo/state_checksum.h>

#include <cstring>
#include <span>
#include <vector>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::uint8_t> input(data, data + size);
  constexpr std::size_t kChecksumAt = 16, kChecksummedFrom = 24;
  if (size >= kChecksummedFrom) {
    game_demo::Fnv1a64 h;
    h.bytes(std::span(input).subspan(kChecksummedFrom));
    const std::uint64_t sum = h.value();
    std::memcpy(input.data() + kChecksumAt, &sum, sizeof sum);  // little-endian hosts, as the format
  }
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(input.data()), input.size());
  engine::Result<game_demo::Session> session = game_demo::decode_session(bytes, "fuzz.girec");
  if (!session) {
    gi_fuzz::refused(session.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  const std::vector<std::byte> again = game_demo::encode_session(*session);
  if (again.size() != input.size() || (size > 0 && std::memcmp(again.data(), input.data(), input.size()) != 0))
    gi_fuzz::fail("a decoded session does not encode back to its bytes");
  return 0;
}
