#include "tool_main.h"

#include <engine/sky.h>
#include <gi/version.h>

#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <vector>

namespace tools {

namespace {

volatile std::sig_atomic_t g_interrupted = 0;

extern "C" void on_interrupt(int signal) {
  g_interrupted = 1;
  std::signal(signal, SIG_DFL);
}

}  // namespace

int exit_code(const engine::Error& error) {
  switch (error.kind) {
    case engine::ErrorKind::Invalid:
      return kExitUsage;
    case engine::ErrorKind::Cancelled:
      return kExitCancelled;
    case engine::ErrorKind::Failure:
      return kExitFailure;
  }
  return kExitFailure;
}

int fail(std::string_view tool, const engine::Error& error) {
  std::cerr << tool << ": " << error.to_string() << '\n';
  return exit_code(error);
}

int fail(std::string_view tool, const std::string& message, int code) {
  std::cerr << tool << ": " << message << '\n';
  return code;
}

std::optional<int> parse(CLI::App& app, std::string_view tool, int argc, char** argv) {
  app.set_version_flag("--version", std::string(tool) + " " + gi::kVersion + " (" + gi::kSourceRevision + ")");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    app.exit(e);
    return kExitOk;
  } catch (const CLI::CallForAllHelp& e) {
    app.exit(e);
    return kExitOk;
  } catch (const CLI::CallForVersion& e) {
    app.exit(e);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::cerr << tool << ": " << e.what() << "\n"
              << "Run with --help for more information.\n";
    return kExitUsage;
  }
  return std::nullopt;
}

void install_interrupt_handler() {
  g_interrupted = 0;
  std::signal(SIGINT, on_interrupt);
  std::signal(SIGTERM, on_interrupt);
}

bool interrupted() { return g_interrupted != 0; }

bool set_sky(engine::Environment& env, const std::string& text) {
  const std::optional<engine::SkyText> sky = engine::parse_sky_text(text);
  if (!sky) return false;
  env.sky_radiance = sky->uniform;
  env.sky_gradient = sky->gradient;
  return true;
}

}  // namespace tools
