// The command-line tools' contract (tools/common/tool_main.h): --version, exit codes 0 / 1 /
// 2 / 130, Ctrl-C cancels cleanly; and the one progress bar's text. The tools run as real
// processes, as a user or a build script runs them.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <gtest/gtest.h>
#include <engine/gltf.h>
#include <engine/scene.h>
#include <gi/gi_system.h>
#include <gi/version.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "console_progress.h"
#include "tool_main.h"

namespace fs = std::filesystem;

namespace {

struct ToolRun {
  int exit_code = -1;  ///< The process's exit status; 128 + N when killed by signal N.
  std::string output;  ///< stdout and stderr together.
};

/// Runs `exe args...` with stdout+stderr into a file; when `interrupt_after` is positive,
/// sends `signal` (SIGINT: Ctrl-C) once the output contains `interrupt_when` (or that many
/// seconds passed).
ToolRun run(const std::string& exe, const std::vector<std::string>& args, double interrupt_after = 0.0,
            const std::string& interrupt_when = {}, int signal = SIGINT) {
  const fs::path log = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" /
                       ("run-" + std::to_string(::getpid()) + "-" + std::to_string(std::rand()) + ".log");
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
  const auto slurp = [&] {
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
  };
  int status = 0;
  bool reaped = false;
  if (interrupt_after > 0.0) {
    const auto start = std::chrono::steady_clock::now();
    while (!(reaped = waitpid(pid, &status, WNOHANG) == pid)) {
      const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (waited >= interrupt_after || (!interrupt_when.empty() && slurp().find(interrupt_when) != std::string::npos)) {
        kill(pid, signal);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  if (!reaped) waitpid(pid, &status, 0);
  ToolRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.output = slurp();
  fs::remove(log);
  return r;
}

const std::vector<std::string>& tools_under_test() {
  static const std::vector<std::string> t{GI_BAKE_EXE, GI_REFERENCE_EXE, GI_SWEEP_EXE};
  return t;
}

}  // namespace

TEST(ConsoleProgress, FormatsFractionElapsedAndEta) {
  // A quarter done after 10 s: 30 s to go.
  EXPECT_EQ(tools::format_progress("bake", 0.25, 10.0, "texels", 8),
            "bake [##......]  25%  texels  elapsed 0:10  ETA 0:30");
  EXPECT_EQ(tools::format_progress("bake", 0.0, 3.0, {}, 4), "bake [....]   0%  elapsed 0:03  ETA --:--");
  EXPECT_EQ(tools::format_progress("bake", 7.0, 3.0, {}, 4), "bake [####] 100%  elapsed 0:03  ETA 0:00");
  EXPECT_EQ(tools::format_duration(3723.0), "1:02:03");
  EXPECT_EQ(tools::format_duration(65.0), "1:05");
  EXPECT_EQ(tools::format_duration(-1.0), "--:--");
}

TEST(ConsoleProgress, WritesOneLinePerStageOffTerminal) {
  std::FILE* f = std::tmpfile();
  ASSERT_NE(f, nullptr);
  {
    tools::ConsoleProgress bar(f, false);
    const gi::ProgressCallback a = bar.stage("walks");
    EXPECT_TRUE(a(0.5));
    EXPECT_TRUE(a(1.0));
    EXPECT_TRUE(bar.stages()("panes", 1.0));
  }
  std::rewind(f);
  std::string text;
  for (int c; (c = std::fgetc(f)) != EOF;) text += static_cast<char>(c);
  std::fclose(f);
  EXPECT_EQ(text.find('\r'), std::string::npos) << "no in-place redraws in a log";
  EXPECT_NE(text.find("walks ["), std::string::npos) << text;
  EXPECT_NE(text.find("panes [####################] 100%"), std::string::npos) << text;
}

TEST(ToolMain, ErrorKindsMapToExitCodes) {
  EXPECT_EQ(tools::exit_code(engine::Error{"f", "w", "broken"}), tools::kExitFailure);
  EXPECT_EQ(tools::exit_code(engine::invalid_request("unknown preset 'ultra'")), tools::kExitUsage);
  EXPECT_EQ(tools::exit_code(engine::cancelled_error("the bake")), tools::kExitCancelled);
}

TEST(Tools, EveryToolAnswersVersion) {
  for (const std::string& exe : tools_under_test()) {
    const ToolRun r = run(exe, {"--version"});
    EXPECT_EQ(r.exit_code, 0) << exe << "\n" << r.output;
    const std::string name = fs::path(exe).filename().string();
    EXPECT_EQ(r.output, name + " " + gi::kVersion + " (" + gi::kSourceRevision + ")\n") << exe;
  }
}

TEST(Tools, EveryToolExitsTwoOnBadUsage) {
  for (const std::string& exe : tools_under_test()) {
    const ToolRun r = run(exe, {"--no-such-option"});
    EXPECT_EQ(r.exit_code, 2) << exe << "\n" << r.output;
    EXPECT_NE(r.output.find("--help"), std::string::npos) << exe << "\n" << r.output;
  }
  // A value CLI11 checks (a file that does not exist) and one the library refuses (a preset).
  EXPECT_EQ(run(GI_BAKE_EXE, {"--scene", "/no/such/scene.gltf"}).exit_code, 2);
  const ToolRun preset = run(GI_BAKE_EXE, {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--preset", "ultra",
                                           "--out", GI_BINARY_DIR "/test_output/tools_test/never.gibake"});
  EXPECT_EQ(preset.exit_code, 2) << preset.output;
  EXPECT_NE(preset.output.find("ultra"), std::string::npos) << preset.output;
  EXPECT_FALSE(fs::exists(GI_BINARY_DIR "/test_output/tools_test/never.gibake"));
}

TEST(Tools, AFailureExitsOneNamingTheFile) {
  const fs::path bad = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "broken.gltf";
  fs::create_directories(bad.parent_path());
  std::ofstream(bad) << "{ \"asset\": { \"version\": \"2.0\" }, \"nodes\": [ {\"mesh\": 7} ] }";
  for (const std::string& exe : {std::string(GI_BAKE_EXE), std::string(GI_REFERENCE_EXE)}) {
    const ToolRun r = run(exe, {"--scene", bad.string(), "--out", (bad.parent_path() / "broken-out").string()});
    EXPECT_EQ(r.exit_code, 1) << exe << "\n" << r.output;
    EXPECT_NE(r.output.find("broken.gltf"), std::string::npos) << exe << "\n" << r.output;
  }
  EXPECT_FALSE(fs::exists(bad.parent_path() / "broken-out"));
}

TEST(Tools, CtrlCCancelsABakeAndLeavesNoBundle) {
  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "cancelled.gibake";
  fs::remove_all(out);
  // The high preset takes tens of seconds; the interrupt comes as soon as the bar shows.
  const ToolRun r = run(GI_BAKE_EXE,
                        {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--methods", "light_atlas", "--preset",
                         "high", "--threads", "2", "--out", out.string()},
                        20.0, "light atlas [");
  EXPECT_EQ(r.exit_code, 130) << r.output;
  EXPECT_NE(r.output.find("cancel"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out)) << "a cancelled bake writes nothing";
}

TEST(Tools, CtrlCCancelsAReferenceRender) {
  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "cancelled-reference.exr";
  fs::remove(out);
  const ToolRun r =
      run(GI_REFERENCE_EXE,
          {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--spp", "100000", "--out", out.string()}, 20.0, "[");
  EXPECT_EQ(r.exit_code, 130) << r.output;
  EXPECT_FALSE(fs::exists(out)) << "a cancelled render writes no image";
}

// gi-bake --sky: a scene without lights (the Avocado, as Khronos ships it) plans and bakes
// the light atlas under a uniform sky. Skips without the external assets.
TEST(GiBake, SkyMakesASceneWithoutLightsBakeable) {
  const fs::path avocado = fs::path(GI_EXTERNAL_ASSETS_DIR) / "Avocado" / "glTF-Draco" / "Avocado.gltf";
  if (!fs::exists(avocado)) GTEST_SKIP() << "external asset not found: " << avocado;
  const ToolRun dark = run(GI_BAKE_EXE, {"--plan", avocado.string(), "--preset", "preview"});
  EXPECT_EQ(dark.exit_code, 0) << dark.output;
  EXPECT_NE(dark.output.find("no light and no emissive surface"), std::string::npos) << dark.output;
  const ToolRun plan = run(GI_BAKE_EXE, {"--plan", avocado.string(), "--preset", "preview", "--sky", "1,1,1"});
  EXPECT_EQ(plan.exit_code, 0) << plan.output;
  EXPECT_NE(plan.output.find("the sky lights"), std::string::npos) << plan.output;
  EXPECT_NE(plan.output.find("bake: light_atlas"), std::string::npos) << plan.output;

  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "avocado_sky.gibake";
  fs::remove_all(out);
  const ToolRun bake = run(
      GI_BAKE_EXE, {"--scene", avocado.string(), "--preset", "preview", "--sky", "0.8,0.9,1.0", "--out", out.string()});
  EXPECT_EQ(bake.exit_code, 0) << bake.output;
  EXPECT_NE(bake.output.find("gi-bake: light_atlas:"), std::string::npos) << bake.output;
  EXPECT_TRUE(fs::exists(out / "manifest.json")) << bake.output;
}

TEST(GiBake, BadSkyIsAUsageError) {
  for (const char* sky :
       {"1,2", "1,-1,1", "a,b,c", "1,1,1,1", "zenith:1,1,1;horizon:1,1,1", "zenith:1,1,1;horizon:1,1,1;ground:1,1",
        "zenith:1,1,1;horizon:1,1,1;ground:1,1,1;ground:1,1,1", "zenith:1,1,1;horizon:1,1,1;sun:1,1,1",
        "zenith:1,1,1;horizon:1,1,1;ground:-1,1,1"}) {
    const ToolRun r = run(GI_BAKE_EXE, {"--plan", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--sky", sky});
    EXPECT_EQ(r.exit_code, 2) << sky << "\n" << r.output;
    EXPECT_NE(r.output.find("--sky"), std::string::npos) << sky << "\n" << r.output;
  }
}

// The gradient form of --sky (docs/scene-format.md): the planner counts it as the sky.
TEST(GiBake, GradientSkyIsAcceptedAndPlanned) {
  const ToolRun plan = run(GI_BAKE_EXE, {"--plan", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--preset", "preview",
                                         "--sky", "horizon:0.8,0.9,1;zenith:0.2,0.4,1;ground:0.1,0.1,0.1"});
  EXPECT_EQ(plan.exit_code, 0) << plan.output;
  EXPECT_NE(plan.output.find("the sky too"), std::string::npos) << plan.output;
}

// gi-reference --sky: the same parser (tools/common), so the reference of a sky-lit bake can be
// rendered from the same command line; a sky the scene lacks shows in the image.
TEST(GiReference, SkyOptionIsParsedAsGiBakes) {
  const ToolRun bad =
      run(GI_REFERENCE_EXE, {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--sky", "1,1", "--out", "x.exr"});
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--sky"), std::string::npos) << bad.output;
  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "reference_sky.exr";
  fs::create_directories(out.parent_path());
  const ToolRun ok = run(GI_REFERENCE_EXE, {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--sky", "0.5,0.5,0.5",
                                            "--width", "8", "--height", "8", "--spp", "2", "--out", out.string()});
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_TRUE(fs::exists(out));
}

// gi-reference --sun: the same parser as gi-bake's and gi-frame-truth's (tools/common), so the
// truth of a sun-lit bake (issue 35's Sponza) is rendered from the same command line: a bad
// sun is a usage error naming the option, a good one renders the atlas truth.
TEST(GiReference, SunOptionIsParsedAsGiBakes) {
  const ToolRun bad = run(GI_REFERENCE_EXE, {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--sun",
                                             "direction:0,0,0;irradiance:1,1,1", "--out", "x.exr"});
  EXPECT_EQ(bad.exit_code, 2) << bad.output;
  EXPECT_NE(bad.output.find("--sun"), std::string::npos) << bad.output;
  const fs::path out = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "reference_sun";
  fs::remove_all(out);
  const ToolRun ok = run(GI_REFERENCE_EXE, {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--sun",
                                            "direction:0.2,-0.6,1;irradiance:50,50,50", "--atlas-density", "4", "--spp",
                                            "2", "--threads", "2", "--atlas-out", out.string()});
  EXPECT_EQ(ok.exit_code, 0) << ok.output;
  EXPECT_TRUE(fs::exists(out / "atlas_direct.exr")) << ok.output;
}

// gi-bake --export-uv1: the scene with the light-atlas UVs as TEXCOORD_1, nothing baked
// (tests/gi/light_atlas_uv_test.cpp checks they are the runtime's).
TEST(GiBake, ExportUv1WritesTheSceneWithLightmapUvs) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "export_uv1";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "cornell_box_uv1.glb";
  const ToolRun r = run(GI_BAKE_EXE, {"--scene", GI_SOURCE_DIR "/assets/cornell_box.gltf", "--preset", "preview",
                                      "--export-uv1", out.string()});
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("TEXCOORD_1"), std::string::npos) << r.output;
  auto asset = engine::load_gltf(out);
  ASSERT_TRUE(asset) << asset.error().to_string();
  std::size_t static_meshes = 0;
  for (const engine::Node& n : asset->nodes) {
    if (n.mesh < 0) continue;
    ++static_meshes;
    for (const engine::Primitive& p : asset->meshes[static_cast<std::size_t>(n.mesh)].primitives) {
      ASSERT_EQ(p.uv1.size(), p.positions.size()) << n.name;
      for (const glm::vec2& uv : p.uv1) EXPECT_TRUE(uv.x >= 0.0f && uv.x <= 1.0f && uv.y >= 0.0f && uv.y <= 1.0f);
    }
  }
  EXPECT_EQ(static_meshes, 4u);  // walls, two blocks, the lamp's quad
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1) << "nothing but the export";
}

namespace {

// A bundle's files but bake_stats.json (when and how long; it differs between any two bakes).
std::map<std::string, std::string> bundle_bytes(const fs::path& dir) {
  std::map<std::string, std::string> out;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (e.path().filename() == "bake_stats.json") continue;
    std::ifstream in(e.path(), std::ios::binary);
    out[e.path().filename().string()] = std::string(std::istreambuf_iterator<char>(in), {});
  }
  return out;
}

}  // namespace

// gi-bake killed (SIGKILL: no handler runs) at several points of a re-bake over a working
// bundle: what is left is, byte for byte, the old bundle or the finished new one — never a
// mix — and it loads; the next bake clears what the killed one left and succeeds.
TEST(GiBake, AKilledRebakeLeavesTheOldBundleOrTheNewOneNeverAMix) {
  const fs::path root = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "killed";
  fs::remove_all(root);
  fs::create_directories(root);
  const fs::path dir = root / "cornell.gibake";
  const std::string scene = GI_SOURCE_DIR "/assets/cornell_box.gltf";
  const std::vector<std::string> old_bake{"--scene",         scene,       "--preset", "preview", "--methods",
                                          "light_atlas,prm", "--threads", "2",        "--out",   dir.string()};
  const std::vector<std::string> new_bake{"--scene",         scene,       "--preset", "medium", "--methods",
                                          "light_atlas,prm", "--threads", "2",        "--out",  dir.string()};
  // The new bundle, baked once without interruption (to know its bytes), then the old one.
  ASSERT_EQ(run(GI_BAKE_EXE, new_bake).exit_code, 0);
  const auto new_files = bundle_bytes(dir);
  ASSERT_EQ(run(GI_BAKE_EXE, old_bake).exit_code, 0);
  const auto old_files = bundle_bytes(dir);
  ASSERT_NE(old_files, new_files);

  auto asset = engine::load_gltf(scene);
  ASSERT_TRUE(asset) << asset.error().to_string();
  struct KillPoint {
    const char* when;  // output text that triggers the kill ("" = after `seconds`)
    double seconds;
  };
  const KillPoint points[] = {
      {"", 0.01},                 // while starting: lock, staging copy
      {"light atlas of", 30.0},   // the atlas baking
      {"PRM of", 30.0},           // the atlas written into staging, the PRM baking
      {"time: walks", 30.0},      // the PRM being saved
      {"", 1.5},                  // wherever the clock says
      {"gi-bake: atlas:", 30.0},  // after the exchange, while reporting
  };
  int saw_old = 0, saw_new = 0;
  for (const KillPoint& p : points) {
    const ToolRun r = run(GI_BAKE_EXE, new_bake, p.seconds, p.when, SIGKILL);
    const auto left = bundle_bytes(dir);
    const bool is_old = left == old_files, is_new = left == new_files;
    EXPECT_TRUE(is_old || is_new) << "killed at \"" << p.when << "\" / " << p.seconds
                                  << " s: the bundle is neither the old nor the new one\n"
                                  << r.output;
    saw_old += is_old;
    saw_new += is_new;
    engine::Scene s = engine::instantiate(*asset);
    auto loaded = gi::GISystem::load(dir, s);
    EXPECT_TRUE(loaded) << "killed at \"" << p.when << "\": " << loaded.error().to_string();
    // Put the old bundle back for the next kill (over a possibly left staging directory).
    if (!is_old) {
      ASSERT_EQ(run(GI_BAKE_EXE, old_bake).exit_code, 0);
    }
  }
  std::printf("%d kills left the old bundle, %d the new one\n", saw_old, saw_new);
  EXPECT_GT(saw_old, 0);
  EXPECT_GT(saw_new, 0) << "the kill after the exchange must find the new bundle";
  // A finished bake after the kills: the new bundle, and no staging directory left behind.
  ASSERT_EQ(run(GI_BAKE_EXE, new_bake).exit_code, 0);
  EXPECT_EQ(bundle_bytes(dir), new_files);
  EXPECT_FALSE(fs::exists(root / ".cornell.gibake.staging"));
}

// Distributed bakes through the CLI (docs/distributed-bake.md): --shard I/N writes the shard
// file and no bundle, --merge writes the bundle byte-identical to a one-process bake, a merge
// with a shard missing exits 1 naming it; malformed --shard values are usage errors.
TEST(GiBake, ShardAndMergeGiveTheOneProcessBundle) {
  const fs::path root = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "shards";
  std::error_code ec;
  fs::remove_all(root, ec);
  fs::create_directories(root);
  const std::vector<std::string> common{"--scene",   GI_SOURCE_DIR "/assets/cornell_box.gltf",
                                        "--preset",  "preview",
                                        "--methods", "light_atlas,prm",
                                        "--density", "12"};
  const auto with = [&](const fs::path& out, std::vector<std::string> extra) {
    std::vector<std::string> a = common;
    a.push_back("--out");
    a.push_back(out.string());
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  for (const char* bad : {"2/2", "1", "a/3", "1/0", "1/3x", "-1/3"}) {
    const ToolRun r = run(GI_BAKE_EXE, with(root / "bad.gibake", {"--shard", bad}));
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
  }
  EXPECT_EQ(run(GI_BAKE_EXE, with(root / "bad.gibake", {"--shard", "0/2", "--merge"})).exit_code, 2);
  EXPECT_FALSE(fs::exists(root / "bad.gibake.shards"));

  ASSERT_EQ(run(GI_BAKE_EXE, with(root / "whole.gibake", {})).exit_code, 0);
  const fs::path sharded = root / "sharded.gibake";
  const ToolRun s0 = run(GI_BAKE_EXE, with(sharded, {"--shard", "0/2"}));
  ASSERT_EQ(s0.exit_code, 0) << s0.output;
  EXPECT_NE(s0.output.find("shard-0000-of-0002.gishard"), std::string::npos) << s0.output;
  EXPECT_FALSE(fs::exists(sharded));
  const ToolRun early = run(GI_BAKE_EXE, with(sharded, {"--merge"}));
  EXPECT_EQ(early.exit_code, 1) << early.output;
  EXPECT_NE(early.output.find("shard-0001-of-0002.gishard"), std::string::npos) << early.output;
  EXPECT_FALSE(fs::exists(sharded));
  ASSERT_EQ(run(GI_BAKE_EXE, with(sharded, {"--shard", "1/2"})).exit_code, 0);
  const ToolRun merged = run(GI_BAKE_EXE, with(sharded, {"--merge"}));
  ASSERT_EQ(merged.exit_code, 0) << merged.output;
  for (const char* name : {"manifest.json", "light_atlas.exr", "light_atlas_vpls.bin", "prm_panes.bin"}) {
    std::ifstream a(root / "whole.gibake" / name, std::ios::binary), b(sharded / name, std::ios::binary);
    const std::string da((std::istreambuf_iterator<char>(a)), {}), db((std::istreambuf_iterator<char>(b)), {});
    EXPECT_FALSE(da.empty()) << name;
    EXPECT_TRUE(da == db) << name << " differs between the merged and the one-process bundle";
  }
}

// Distributed references through the CLI (docs/distributed-bake.md): gi-reference --shard I/N
// writes a shard file and no image or atlas, --merge writes files byte-identical to one
// process's; a merge with a shard missing exits 1 naming it and writes nothing.
TEST(GiReference, ShardAndMergeGiveTheOneProcessFiles) {
  const fs::path root = fs::path(GI_BINARY_DIR) / "test_output" / "tools_test" / "reference_shards";
  std::error_code ec;
  fs::remove_all(root, ec);
  fs::create_directories(root);
  const auto with = [&](const std::string& name, std::vector<std::string> extra) {
    std::vector<std::string> a{"--scene",         GI_SOURCE_DIR "/assets/cornell_box.gltf",
                               "--spp",           "2",
                               "--bounces",       "2",
                               "--seed",          "4",
                               "--width",         "20",
                               "--height",        "16",
                               "--atlas-density", "10",
                               "--out",           (root / (name + ".exr")).string(),
                               "--png",           (root / (name + ".png")).string(),
                               "--atlas-out",     (root / (name + "_atlas")).string()};
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  for (const char* bad : {"2/2", "1", "a/3", "1/0", "1/3x"}) {
    const ToolRun r = run(GI_REFERENCE_EXE, with("bad", {"--shard", bad}));
    EXPECT_EQ(r.exit_code, 2) << bad << "\n" << r.output;
  }
  EXPECT_EQ(run(GI_REFERENCE_EXE, with("bad", {"--shard", "0/2", "--merge"})).exit_code, 2);
  EXPECT_FALSE(fs::exists(root / "bad_atlas.shards"));

  ASSERT_EQ(run(GI_REFERENCE_EXE, with("whole", {})).exit_code, 0);
  const ToolRun s0 = run(GI_REFERENCE_EXE, with("sharded", {"--shard", "0/3", "--threads", "1"}));
  ASSERT_EQ(s0.exit_code, 0) << s0.output;
  EXPECT_TRUE(fs::exists(root / "sharded_atlas.shards" / "shard-0000-of-0003.girefshard")) << s0.output;
  EXPECT_FALSE(fs::exists(root / "sharded.exr"));
  EXPECT_FALSE(fs::exists(root / "sharded_atlas"));
  ASSERT_EQ(run(GI_REFERENCE_EXE, with("sharded", {"--shard", "2/3"})).exit_code, 0);
  const ToolRun early = run(GI_REFERENCE_EXE, with("sharded", {"--merge"}));
  EXPECT_EQ(early.exit_code, 1) << early.output;
  EXPECT_NE(early.output.find("shard-0001-of-0003.girefshard"), std::string::npos) << early.output;
  EXPECT_FALSE(fs::exists(root / "sharded.exr"));
  EXPECT_FALSE(fs::exists(root / "sharded.png"));
  EXPECT_FALSE(fs::exists(root / "sharded_atlas"));
  ASSERT_EQ(run(GI_REFERENCE_EXE, with("sharded", {"--shard", "1/3"})).exit_code, 0);
  const ToolRun merged = run(GI_REFERENCE_EXE, with("sharded", {"--merge"}));
  ASSERT_EQ(merged.exit_code, 0) << merged.output;
  const auto bytes = [](const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), {});
  };
  for (const std::string file :
       {".exr", ".png", "_atlas/atlas_direct.exr", "_atlas/atlas_indirect.exr", "_atlas/atlas_total.exr"}) {
    const std::string a = bytes(root / ("whole" + file)), b = bytes(root / ("sharded" + file));
    EXPECT_FALSE(a.empty()) << file;
    EXPECT_TRUE(a == b) << file << " differs between the merged and the one-process reference";
  }
  // An explicit --shard-dir, and a merge of other settings refused as foreign.
  const std::string dir = (root / "explicit").string();
  ASSERT_EQ(run(GI_REFERENCE_EXE, with("x", {"--shard", "0/1", "--shard-dir", dir})).exit_code, 0);
  std::vector<std::string> other = with("x", {"--merge", "--shard-dir", dir});
  other[3] = "3";  // --spp 3
  const ToolRun foreign = run(GI_REFERENCE_EXE, other);
  EXPECT_EQ(foreign.exit_code, 1) << foreign.output;
  EXPECT_NE(foreign.output.find("foreign shard"), std::string::npos) << foreign.output;
  EXPECT_FALSE(fs::exists(root / "x.exr"));
}
