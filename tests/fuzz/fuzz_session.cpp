// Fuzz target: recorded play sessions (.girec, game_demo::decode_session, what
// game_demo::load_session parses). Check: a session that decodes encodes back to exactly
// the input bytes (the format has one encoding per session).
#include <game_demo/session_file.h>

#include <cstring>
#include <span>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::byte> bytes(reinterpret_cast<const std::byte*>(data), size);
  engine::Result<game_demo::Session> session = game_demo::decode_session(bytes, "fuzz.girec");
  if (!session) {
    gi_fuzz::refused(session.error().to_string());
    return 0;
  }
  gi_fuzz::accepted();
  const std::vector<std::byte> again = game_demo::encode_session(*session);
  if (again.size() != size || (size > 0 && std::memcmp(again.data(), data, size) != 0))
    gi_fuzz::fail("a decoded session does not encode back to its bytes");
  return 0;
}
