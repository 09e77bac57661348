// The driver of a fuzz target in the normal build (no libFuzzer), run by the ctest
// Fuzz.<target>.ReplaysSeedsAndRegressions:
//   fuzz_<target>_replay --seeds DIR [--regressions DIR]
// feeds every file of the directories to LLVMFuzzerTestOneInput in name order. Every seed
// must be accepted by the reader (a refused seed, e.g. after a format change, no longer
// reaches the parser's depths: regenerate the corpus, tools/fuzz-seeds.sh); regression
// inputs may be refused or accepted, they must not crash, trip a sanitizer or fail a
// target's check. The regressions directory may be absent (no finding yet).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> files_of(const fs::path& dir) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) return files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Replays `files`; returns how many were refused.
int replay(const std::vector<fs::path>& files) {
  int refused = 0;
  for (const fs::path& p : files) {
    std::ifstream in(p, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    gi_fuzz::refused("the target set no verdict");
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    const gi_fuzz::Verdict& v = gi_fuzz::last_verdict();
    std::printf("%s (%zu bytes): %s%s\n", p.c_str(), bytes.size(),
                v.accepted ? "accepted" : "refused: ", v.reason.c_str());
    std::fflush(stdout);
    if (!v.accepted) ++refused;
  }
  return refused;
}

}  // namespace

int main(int argc, char** argv) {
  fs::path seeds, regressions;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--seeds") == 0)
      seeds = argv[i + 1];
    else if (std::strcmp(argv[i], "--regressions") == 0)
      regressions = argv[i + 1];
  }
  const std::vector<fs::path> seed_files = files_of(seeds);
  if (seeds.empty() || seed_files.empty()) {
    std::fprintf(stderr, "usage: %s --seeds DIR [--regressions DIR]; no seeds found in '%s'\n", argv[0], seeds.c_str());
    return 1;
  }
  const int refused_seeds = replay(seed_files);
  const std::vector<fs::path> regression_files = files_of(regressions);
  replay(regression_files);
  std::printf("%zu seeds (%d refused), %zu regression inputs replayed\n", seed_files.size(), refused_seeds,
              regression_files.size());
  if (refused_seeds > 0) {
    std::fprintf(stderr, "every seed must be accepted by the reader: regenerate the corpus (tools/fuzz-seeds.sh)\n");
    return 1;
  }
  return 0;
}
