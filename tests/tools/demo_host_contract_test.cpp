// The demo's executables (gi_demo, gi-replay-quality) keep the tools' host contract
// (tools/common/tool_main.h): --version, exit 2 on bad usage, 130 on Ctrl-C. Run as real
// processes, as tools_test.cpp runs the tools.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>
#include <gtest/gtest.h>
#include <gi/version.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#if defined(GI_DEMO_EXE) && defined(GI_REPLAY_QUALITY_EXE)

namespace fs = std::filesystem;

namespace {

struct ProgramRun {
  int exit_code = -1;  ///< The exit status; 128 + N when killed by signal N.
  std::string output;  ///< stdout and stderr together.
};

/// Runs `exe args...` (stdout and stderr into one file); with `interrupt_after_s` > 0 sends
/// SIGINT after that long unless the process ended first.
ProgramRun run(const std::string& exe, const std::vector<std::string>& args, double interrupt_after_s = 0.0) {
  const fs::path log = fs::path(GI_BINARY_DIR) / "test_output" / "demo_host_contract" /
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
  int status = 0;
  bool reaped = false;
  if (interrupt_after_s > 0.0) {
    const auto start = std::chrono::steady_clock::now();
    while (!(reaped = waitpid(pid, &status, WNOHANG) == pid)) {
      if (std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() >= interrupt_after_s) {
        kill(pid, SIGINT);
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  if (!reaped) waitpid(pid, &status, 0);
  ProgramRun r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  std::ifstream in(log);
  std::stringstream text;
  text << in.rdbuf();
  r.output = text.str();
  fs::remove(log);
  return r;
}

const std::vector<std::string>& demo_programs() {
  static const std::vector<std::string> p{GI_DEMO_EXE, GI_REPLAY_QUALITY_EXE};
  return p;
}

const std::string kSession = GI_SOURCE_DIR "/tests/sessions/walk_flashlight.girec";

}  // namespace

TEST(DemoPrograms, AnswerVersionAsTheToolsDo) {
  for (const std::string& exe : demo_programs()) {
    const ProgramRun r = run(exe, {"--version"});
    EXPECT_EQ(r.exit_code, 0) << exe << "\n" << r.output;
    const std::string name = fs::path(exe).filename().string();
    EXPECT_EQ(r.output, name + " " + gi::kVersion + " (" + gi::kSourceRevision + ")\n") << exe;
  }
}

TEST(DemoPrograms, ExitTwoOnBadUsage) {
  for (const std::string& exe : demo_programs()) {
    const ProgramRun r = run(exe, {"--no-such-option"});
    EXPECT_EQ(r.exit_code, 2) << exe << "\n" << r.output;
    EXPECT_NE(r.output.find("--help"), std::string::npos) << exe << "\n" << r.output;
  }
  // Combinations and values the programs themselves refuse, after CLI11 accepted them.
  const ProgramRun no_render =
      run(GI_DEMO_EXE, {"--headless", "--no-render", "--out", GI_BINARY_DIR "/test_output/never"});
  EXPECT_EQ(no_render.exit_code, 2) << no_render.output;
  EXPECT_NE(no_render.output.find("--no-render"), std::string::npos) << no_render.output;
  const ProgramRun frames = run(GI_REPLAY_QUALITY_EXE, {"--session", kSession, "--bundle", "none", "--frames", "3,x"});
  EXPECT_EQ(frames.exit_code, 2) << frames.output;
  EXPECT_NE(frames.output.find("--frames"), std::string::npos) << frames.output;
}

TEST(DemoPrograms, AFailureExitsOne) {
  const ProgramRun r =
      run(GI_DEMO_EXE, {"--headless", "--no-render", "--replay", GI_SOURCE_DIR "/no/such/session.girec"});
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("session.girec"), std::string::npos) << r.output;
}

TEST(DemoPrograms, CtrlCStopsAHeadlessRunWith130AndRecordsNothing) {
  const fs::path recording = fs::path(GI_BINARY_DIR) / "test_output" / "demo_host_contract" / "cancelled.girec";
  fs::create_directories(recording.parent_path());
  fs::remove(recording);
  // Simulation only, far more steps than the few seconds before the interrupt can run.
  const ProgramRun r =
      run(GI_DEMO_EXE, {"--headless", "--no-render", "--frames", "1000000000", "--record", recording.string()}, 5.0);
  EXPECT_EQ(r.exit_code, 130) << r.output;
  EXPECT_NE(r.output.find("cancelled"), std::string::npos) << "stopped by its handler, not killed:\n" << r.output;
  EXPECT_FALSE(fs::exists(recording)) << "a cancelled run writes no half session";
}

#endif  // GI_DEMO_EXE && GI_REPLAY_QUALITY_EXE
