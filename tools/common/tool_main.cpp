#include "tool_main.h"

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

std::optional<glm::vec3> parse_sky(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ',');) parts.push_back(item);
  if (parts.size() != 3) return std::nullopt;
  glm::vec3 radiance(0.0f);
  for (int i = 0; i < 3; ++i) {
    const std::string& p = parts[static_cast<std::size_t>(i)];
    char* end = nullptr;
    radiance[i] = std::strtof(p.c_str(), &end);
    if (end == p.c_str() || *end != '\0' || !std::isfinite(radiance[i]) || radiance[i] < 0.0f) return std::nullopt;
  }
  return radiance;
}

bool set_sky(engine::Environment& env, const std::string& text) {
  if (text.find(':') == std::string::npos) {
    const std::optional<glm::vec3> radiance = parse_sky(text);
    if (!radiance) return false;
    env.sky_radiance = *radiance;
    env.sky_gradient = {};
    return true;
  }
  engine::SkyGradient g;
  bool seen[3] = {false, false, false};
  std::stringstream ss(text);
  for (std::string item; std::getline(ss, item, ';');) {
    const std::size_t colon = item.find(':');
    if (colon == std::string::npos) return false;
    const std::string key = item.substr(0, colon);
    const std::optional<glm::vec3> value = parse_sky(item.substr(colon + 1));
    const int k = key == "zenith" ? 0 : key == "horizon" ? 1 : key == "ground" ? 2 : -1;
    if (k < 0 || !value || seen[k]) return false;
    seen[k] = true;
    (k == 0 ? g.zenith : k == 1 ? g.horizon : g.ground) = *value;
  }
  if (!seen[0] || !seen[1] || !seen[2]) return false;
  env.sky_radiance = glm::vec3(0.0f);
  env.sky_gradient = g;
  return true;
}

}  // namespace tools
