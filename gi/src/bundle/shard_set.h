#pragma once
// The shard files of one merge (gi-bake --merge, gi-reference --merge): listed from their
// directory, placed by index (a duplicate is refused naming both files), and checked complete
// (the first missing index is named). What makes a shard foreign is each merge's own check.
//   auto files = list_shard_files(dir, ".gishard");
//   ShardSet<ShardFile> set;
//   for (path : *files) { ...read, check foreign...; if (auto ok = set.place(path, index, count, file); !ok) ... }
//   if (auto ok = set.complete(count, [&](std::uint32_t i) { return dir / name(i, count); }); !ok) ...

#include <engine/result.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace gi {

/// The files DIR/*EXTENSION in name order. Errors: the directory cannot be listed, or holds none.
inline engine::Result<std::vector<std::filesystem::path>> list_shard_files(const std::filesystem::path& dir,
                                                                           std::string_view extension) {
  std::error_code ec;
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == extension) files.push_back(e.path());
  if (ec) return engine::Error{dir.string(), "", "cannot list the shard directory: " + ec.message()};
  std::sort(files.begin(), files.end());
  if (files.empty()) return engine::Error{dir.string(), "", "no shard file (*" + std::string(extension) + ") to merge"};
  return files;
}

/// Shard files by index, each with the path it was read from.
template <class File>
struct ShardSet {
  std::vector<std::optional<File>> shards;
  std::vector<std::filesystem::path> where;

  /// Places `file` (shard `index` of `count`, index < count, read from `path`). Error: that
  /// index is already placed.
  engine::Status place(const std::filesystem::path& path, std::uint32_t index, std::uint32_t count, File file) {
    if (shards.empty()) shards.resize(count), where.resize(count);
    if (shards[index])
      return engine::Error{path.string(), "",
                           "duplicate shard " + std::to_string(index) + " of " + std::to_string(count) + " (also in " +
                               where[index].string() + ")"};
    shards[index] = std::move(file);
    where[index] = path;
    return {};
  }

  /// Error naming the first missing shard's file (`name_of(index)`), if any is missing.
  template <class NameOf>
  engine::Status complete(std::uint32_t count, NameOf name_of) const {
    for (std::uint32_t i = 0; i < count; ++i)
      if (i >= shards.size() || !shards[i])
        return engine::Error{name_of(i).string(), "",
                             "shard " + std::to_string(i) + " of " + std::to_string(count) + " is missing"};
    return {};
  }
};

}  // namespace gi
