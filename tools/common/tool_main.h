#pragma once
// The contract every command-line tool keeps with its caller:
//   exit 0 done, 1 failed (the error named on stderr), 2 bad usage (CLI11's parse errors
//   included, which CLI11 would exit with 105+), 130 cancelled by Ctrl-C (SIGINT/SIGTERM:
//   the work stops at its next progress check and nothing half-written is left; a second
//   Ctrl-C ends the process at once);
//   --version prints "<tool> <gi::kVersion> (<gi::kSourceRevision>)".
//   CLI::App app{"..."};
//   if (auto rc = tools::parse(app, "gi-bake", argc, argv)) return *rc;
//   tools::install_interrupt_handler();
//   if (!result) return tools::fail("gi-bake", result.error());

#include <glm/vec3.hpp>
#include <engine/result.h>
#include <engine/scene_asset.h>

#include <optional>
#include <string>
#include <string_view>
#include <CLI/CLI.hpp>

namespace tools {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailure = 1;
inline constexpr int kExitUsage = 2;
inline constexpr int kExitCancelled = 130;

/// The exit code of an error: Invalid -> 2, Cancelled -> 130, anything else -> 1.
int exit_code(const engine::Error& error);

/// Prints "<tool>: <error>" on stderr and returns exit_code(error).
int fail(std::string_view tool, const engine::Error& error);
/// Prints "<tool>: <message>" on stderr and returns `code`.
int fail(std::string_view tool, const std::string& message, int code);

/// Adds --version, parses. nullopt: go on; otherwise the exit code to return now (0 after
/// --help or --version, 2 after a parse error, which is printed with the usage hint).
std::optional<int> parse(CLI::App& app, std::string_view tool, int argc, char** argv);

/// SIGINT and SIGTERM set the flag interrupted() reads (and restore the default action, so
/// a second signal ends the process).
/// `--sky` in either form (engine::parse_sky_text), replacing the scene's whole sky
/// (docs/scene-format.md). False (env untouched) when malformed.
bool set_sky(engine::Environment& env, const std::string& text);
inline constexpr const char* kSkyUsage =
    "--sky wants R,G,B or 'zenith:R,G,B;horizon:R,G,B;ground:R,G,B': finite radiances >= 0";

void install_interrupt_handler();
bool interrupted();

}  // namespace tools
