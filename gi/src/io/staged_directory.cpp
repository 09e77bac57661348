#include "io/staged_directory.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <system_error>
#include <utility>

namespace gi {

namespace {

namespace fs = std::filesystem;

// fsync of one file or directory.
engine::Status sync_path(const fs::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return engine::Error{path.string(), "", std::string("cannot open to flush: ") + std::strerror(errno)};
  const bool ok = ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) return engine::Error{path.string(), "", std::string("cannot flush to disk: ") + std::strerror(err)};
  return {};
}

// The files in `dir` (one level), then the directory itself, flushed to disk.
engine::Status sync_tree(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file(ec))
      if (auto ok = sync_path(e.path(), O_RDONLY); !ok) return ok;
  if (ec) return engine::Error{dir.string(), "", "cannot list the staging directory: " + ec.message()};
  return sync_path(dir, O_RDONLY | O_DIRECTORY);
}

// A sibling of `dir` named ".<name><suffix>".
fs::path sibling(const fs::path& dir, const char* suffix) {
  return dir.parent_path() / ("." + dir.filename().string() + suffix);
}

}  // namespace

engine::Result<StagedDirectory> StagedDirectory::begin(const fs::path& dir, const std::string& job) {
  StagedDirectory s;
  s.dir_ = dir;
  s.staging_ = sibling(dir, ".staging");
  std::error_code ec;
  if (!dir.parent_path().empty()) fs::create_directories(dir.parent_path(), ec);
  const fs::path lock = sibling(dir, ".lock");
  s.lock_fd_ = ::open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (s.lock_fd_ < 0)
    return engine::Error{lock.string(), "", std::string("cannot open the lock: ") + std::strerror(errno)};
  if (::flock(s.lock_fd_, LOCK_EX | LOCK_NB) != 0)
    return engine::Error{dir.string(), "", "another " + job + " is running (lock " + lock.string() + ")"};
  fs::remove_all(s.staging_, ec);
  if (ec) return engine::Error{s.staging_.string(), "", "cannot clear the staging directory: " + ec.message()};
  if (fs::exists(dir, ec)) {
    if (!fs::is_directory(dir, ec)) return engine::Error{dir.string(), "", "exists and is not a directory"};
    fs::copy(dir, s.staging_, fs::copy_options::recursive, ec);
  } else {
    fs::create_directories(s.staging_, ec);
  }
  if (ec) return engine::Error{s.staging_.string(), "", "cannot prepare the staging directory: " + ec.message()};
  s.active_ = true;
  return s;
}

StagedDirectory::StagedDirectory(StagedDirectory&& o) noexcept
    : dir_(std::move(o.dir_)),
      staging_(std::move(o.staging_)),
      active_(std::exchange(o.active_, false)),
      lock_fd_(std::exchange(o.lock_fd_, -1)) {}

StagedDirectory::~StagedDirectory() {
  if (active_) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the lock
}

engine::Status StagedDirectory::commit() {
  std::error_code ec;
  if (auto ok = sync_tree(staging_); !ok) return ok;
  if (!fs::exists(dir_, ec)) {
    fs::rename(staging_, dir_, ec);
    if (ec) return engine::Error{dir_.string(), "", "cannot move the staged directory into place: " + ec.message()};
  } else if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, dir_.c_str(), RENAME_EXCHANGE) != 0) {
    return engine::Error{dir_.string(), "",
                         std::string("cannot exchange the staged directory with the old one: ") + std::strerror(errno)};
  }
  // staging_ now holds the previous contents (or nothing); the destructor removes it.
  return sync_path(dir_.parent_path().empty() ? fs::path(".") : dir_.parent_path(), O_RDONLY | O_DIRECTORY);
}

}  // namespace gi
