#pragma once
// Writing a file so that readers see either the old file or the complete new one: write a
// temporary file in the same directory, flush and check it, then rename it over the target.
//   engine::Status s = gi::write_file_atomically("out/sweep.csv", csv_text);
//   if (!s) std::cerr << s.error().to_string() << '\n';

#include <engine/result.h>

#include <filesystem>
#include <string_view>

namespace gi {

/// Writes `bytes` to `path` atomically (temporary "<name>.tmp-<pid>-<n>" + rename). On any
/// failure the temporary file is removed, the target is untouched and an Error says what
/// failed. The parent directory must exist.
engine::Status write_file_atomically(const std::filesystem::path& path, std::string_view bytes);

}  // namespace gi
