#pragma once
// Shared by the fuzz targets (tests/fuzz/, gi/fuzz/): a private scratch directory for
// readers that take a path, and the failure of a target's own check (an "oracle": what a
// reader accepted must survive its writer and read back the same).
//   std::filesystem::path p = gi_fuzz::write_scratch("scene.glb", data, size);
//   if (!same) gi_fuzz::fail("re-read differs");
//
// Each target is built twice: with libFuzzer (GI_FUZZ=ON, clang, tools/fuzz.sh) and, in the
// normal build, with tests/fuzz/replay_main.cpp as a ctest that replays the target's seed
// corpus and its regression inputs (tests/fuzz/corpus/<name>/, tests/fuzz/regressions/<name>/).

#include <unistd.h>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>
#include <utility>

namespace gi_fuzz {

/// A directory only this process writes (under /dev/shm when there is one: the readers
/// read a file per input), removed when the process exits normally.
inline const std::filesystem::path& scratch_dir() {
  struct Dir {
    std::filesystem::path path;
    Dir() {
      std::error_code ec;
      const bool shm = std::filesystem::is_directory("/dev/shm", ec) && access("/dev/shm", W_OK) == 0;
      std::string tmpl = std::string(shm ? "/dev/shm" : "/tmp") + "/gi-fuzz-XXXXXX";
      if (mkdtemp(tmpl.data()) == nullptr) {
        std::perror("gi_fuzz: mkdtemp");
        std::abort();
      }
      path = tmpl;
    }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

/// Writes the input to scratch_dir() / name (replacing it) and returns the path.
inline std::filesystem::path write_scratch(const std::string& name, const std::uint8_t* data, std::size_t size) {
  std::filesystem::path p = scratch_dir() / name;
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  if (size > 0) out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "gi_fuzz: cannot write %s\n", p.c_str());
    std::abort();
  }
  return p;
}

/// What the reader said about the last input: set by the target, read by the replay
/// driver (tests/fuzz/replay_main.cpp), which requires every seed to be accepted (a seed the
/// reader refuses, e.g. after a format change, no longer reaches the parser's depths).
struct Verdict {
  bool accepted = false;
  std::string reason;  ///< The reader's error when refused.
};
inline Verdict& last_verdict() {
  static Verdict v;
  return v;
}
inline void accepted() { last_verdict() = {true, {}}; }
inline void refused(std::string reason) { last_verdict() = {false, std::move(reason)}; }

/// A target's own check failed: a finding like a crash (libFuzzer saves the input).
[[noreturn]] inline void fail(const std::string& what) {
  std::fprintf(stderr, "gi_fuzz: check failed: %s\n", what.c_str());
  std::abort();
}

}  // namespace gi_fuzz
