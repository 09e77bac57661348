#pragma once
// What the sweep tests share: a scratch directory under the build tree and a scene built in
// memory (its one light's colour changes the content, so the reference cache's key).
//   sweeptest::TempDir dir("dlm");  // <build>/sweep_test_tmp/dlm-<pid>, removed at the end
//   const gi::SweepScene scene = sweeptest::make_scene(0.5f);
//   auto rows = sweeptest::read_rows(report->csv);  // the rows of a sweep's CSV
#include <unistd.h>
#include <engine/scene.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

#include "sweep/sweep_csv.h"
#include "sweep/sweep_scene.h"

namespace sweeptest {

namespace fs = std::filesystem;

/// A fresh directory under the build tree, removed at the end of the test.
class TempDir {
 public:
  explicit TempDir(const std::string& name)
      : path_(fs::path(GI_BINARY_DIR) / "sweep_test_tmp" / (name + "-" + std::to_string(::getpid()))) {
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// The rows of the sweep CSV at `csv` (gi::parse_sweep_csv of the file's text).
inline engine::Result<std::vector<gi::SweepRow>> read_rows(const fs::path& csv) {
  std::ifstream in(csv);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return gi::parse_sweep_csv(text, csv.string());
}

/// A scene built in memory: one light whose colour the tests change to change the content.
inline gi::SweepScene make_scene(float light_red = 1.0f) {
  gi::SweepScene s;
  engine::NamedLight l;
  l.name = "key";
  l.light.color = {light_red, 1.0f, 1.0f};
  s.asset.lights.push_back(l);
  s.content_hash = gi::scene_fingerprint({}, s.asset).value();
  return s;
}

}  // namespace sweeptest
