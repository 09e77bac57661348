#pragma once
// Replacing a whole directory so that readers see either the old one or the complete new
// one (the directory form of atomic_file.h): the writer fills a staging copy next to it
// (".<name>.staging", a copy of the old directory when there is one), then commit() flushes
// every file and the directory to disk and swaps the copy in with one atomic exchange. A
// writer that fails or is cancelled leaves the old directory exactly as it was (the staging
// copy is removed); one that is killed leaves the staging copy, which the next begin()
// clears. One writer per directory at a time: an advisory lock ".<name>.lock" next to it,
// released by the kernel when the process ends, however it ends.
//   auto staged = gi::StagedDirectory::begin("out/level.gibake", "bake of this bundle");
//   if (!staged) return staged.error();
//   write_files_into(staged->path());
//   if (auto ok = staged->commit(); !ok) return ok.error();

#include <engine/result.h>

#include <filesystem>
#include <string>

namespace gi {

class StagedDirectory {
 public:
  /// Takes the lock of `dir`, clears a left-over staging copy and makes a new one (a copy
  /// of `dir` when it exists, else empty); creates `dir`'s parent if needed. `job` names the
  /// writer in the error when the lock is taken: "another <job> is running".
  static engine::Result<StagedDirectory> begin(const std::filesystem::path& dir, const std::string& job);

  StagedDirectory(StagedDirectory&& o) noexcept;
  StagedDirectory& operator=(StagedDirectory&&) = delete;
  StagedDirectory(const StagedDirectory&) = delete;
  StagedDirectory& operator=(const StagedDirectory&) = delete;
  /// Removes the staging directory (after commit: the previous contents) and releases the lock.
  ~StagedDirectory();

  /// The staging directory the writer fills (one level of files: subdirectories are not flushed).
  const std::filesystem::path& path() const { return staging_; }

  /// The staging directory becomes `dir` (renameat2 RENAME_EXCHANGE when `dir` exists),
  /// its files and itself flushed to disk first and the parent directory after.
  engine::Status commit();

 private:
  StagedDirectory() = default;
  std::filesystem::path dir_, staging_;
  bool active_ = false;
  int lock_fd_ = -1;
};

}  // namespace gi
