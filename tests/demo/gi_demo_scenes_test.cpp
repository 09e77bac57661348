// gi_demo on glTF files nobody here made (GI_EXTERNAL_ASSETS_DIR, ../shared/external-assets;
// read there, never copied; the test skips with a message without them): every file that
// loads, has a camera or lights, and has triangles to see, rendered headless with gi_demo's
// defaults (its first camera or a view framing its bounds, automatic exposure) writes a frame
// that is neither black nor white. The files are found by loading them, not from a list
// (today: LightsPunctualLamp, MultiUVTest .gltf and .glb, draco-google-testdata's
// sphere_lights; Dabrovic Sponza has neither camera nor lights). About 10 s on 2 cores.
//
// Criterion, on the last frame: of the pixels with any light (HDR radiance > 0 in the frame's
// EXR: a scene without a sky has a black background, which says nothing of its exposure), at
// least 1% of the frame, the mean display luminance (0.2126 R + 0.7152 G + 0.0722 B of the
// sRGB values / 255; a metered middle grey is about 0.4) lies in [0.15, 0.9], and under 10% of
// them are clipped (every channel at 250/255 or more). Automatic exposure gives 0.31-0.43
// with under 1% clipped; gi_demo's old fixed exposure 0.3 fails every file (0.004-0.09), and
// --exposure 100 fails MultiUVTest as white (44% clipped).
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/image.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

struct DemoRun {
  int exit_code = -1;
  std::string output;  ///< stdout and stderr together
};

DemoRun run(const std::string& exe, const std::vector<std::string>& args, const fs::path& log) {
  fs::create_directories(log.parent_path());
  const pid_t pid = fork();
  if (pid == 0) {
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    std::vector<char*> argv{const_cast<char*>(exe.c_str())};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  waitpid(pid, &status, 0);
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  return {WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), text.str()};
}

// Loads, has a camera or a light, and has a mesh node with triangles in its scene. The
// glTF-Validator's test inputs (a FILE.report.json beside them: the validator's expected
// findings) are inputs for validators, not scenes to look at (node/valid.gltf puts its
// camera in the plane of its one triangle); the loader's tests read them.
bool worth_viewing(const fs::path& file) {
  if (fs::exists(fs::path(file.string() + ".report.json"))) return false;
  auto loaded = engine::load_gltf(file, {.load_images = false});
  if (!loaded) return false;  // bad files are the loader tests' business (gltf_external_assets_test)
  const engine::SceneAsset& a = *loaded;
  bool camera = false, light = false, triangles = false;
  for (const engine::Node& n : a.nodes) {
    camera |= n.camera >= 0;
    light |= n.light >= 0;
    if (n.mesh >= 0)
      for (const engine::Primitive& p : a.meshes[static_cast<std::size_t>(n.mesh)].primitives)
        triangles |= p.indices.size() >= 3 || p.positions.size() >= 3;
  }
  return (camera || light) && triangles;
}

struct FrameStats {
  double shown = 0.0;           ///< share of the pixels with any radiance (HDR > 0)
  double mean_luminance = 0.0;  ///< of those, display luminance of the sRGB values, 0..1
  double clipped = 0.0;         ///< of those, the share with every channel >= 250
};

FrameStats frame_stats(const engine::ImageRgba8& ldr, const engine::ImageRgbaF& hdr) {
  FrameStats s;
  std::size_t shown = 0, clipped = 0;
  double sum = 0.0;
  const std::size_t n = ldr.pixels.size() / 4;
  for (std::size_t i = 0; i < n; ++i) {
    const float* h = &hdr.pixels[4 * i];
    if (!(h[0] > 0.0f || h[1] > 0.0f || h[2] > 0.0f)) continue;
    const std::uint8_t* p = &ldr.pixels[4 * i];
    ++shown;
    sum += (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
    clipped += p[0] >= 250 && p[1] >= 250 && p[2] >= 250 ? 1 : 0;
  }
  s.shown = static_cast<double>(shown) / static_cast<double>(n);
  if (shown > 0) {
    s.mean_luminance = sum / static_cast<double>(shown);
    s.clipped = static_cast<double>(clipped) / static_cast<double>(shown);
  }
  return s;
}

TEST(GiDemoScenes, EveryExternalGltfWithACameraOrLightsShowsAFrameNeitherBlackNorWhite) {
  const fs::path assets(GI_EXTERNAL_ASSETS_DIR);
  if (!fs::is_directory(assets)) GTEST_SKIP() << "external assets not found: " << assets;
  std::vector<fs::path> files;
  for (const fs::directory_entry& e : fs::recursive_directory_iterator(assets)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb") && worth_viewing(e.path())) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  ASSERT_FALSE(files.empty()) << "no glTF with a camera or lights and triangles under " << assets;
  const fs::path out_root = fs::path(GI_BINARY_DIR) / "test_output" / "gi_demo_scenes";
  fs::remove_all(out_root);
  for (std::size_t k = 0; k < files.size(); ++k) {
    const fs::path& file = files[k];
    const fs::path out = out_root / (std::to_string(k) + "_" + file.stem().string());
    // Two frames: the first snaps the automatic exposure to its target, the second adapts
    // from it over one 1/60 s step (as a player sees it start).
    const DemoRun r = run(GI_DEMO_EXE,
                          {"--headless", "--scene", file.string(), "--frames", "2", "--width", "96", "--height", "54",
                           "--out", out.string(), "--exr"},
                          out_root / (std::to_string(k) + ".log"));
    ASSERT_EQ(r.exit_code, 0) << file << ":\n" << r.output;
    EXPECT_NE(r.output.find("exposure: automatic"), std::string::npos) << file << ":\n" << r.output;
    auto ldr = engine::load_png(out / "frame_0001.png");
    ASSERT_TRUE(ldr) << ldr.error().to_string();
    auto hdr = engine::load_exr(out / "frame_0001.exr");
    ASSERT_TRUE(hdr) << hdr.error().to_string();
    ASSERT_EQ(hdr->pixels.size(), ldr->pixels.size());
    const FrameStats s = frame_stats(*ldr, *hdr);
    SCOPED_TRACE(file.string() + " (frame in " + out.string() + ")");
    EXPECT_GE(s.shown, 0.01) << "black: nothing shows";
    EXPECT_GE(s.mean_luminance, 0.15) << "too dark";
    EXPECT_LE(s.mean_luminance, 0.9) << "too bright";
    EXPECT_LT(s.clipped, 0.1) << "white: clipped";
    std::printf("%-90s shown %5.1f%%  mean %.3f  clipped %4.1f%%\n", file.string().c_str(), 100.0 * s.shown,
                s.mean_luminance, 100.0 * s.clipped);
  }
}

}  // namespace
