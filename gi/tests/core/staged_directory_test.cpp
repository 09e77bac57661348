// io/staged_directory.h: a directory replaced as a whole. Readers see the old contents until
// commit() and the new ones after; a writer that gives up leaves the old directory and no
// staging copy; one writer at a time; a killed writer's staging copy is cleared by the next.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>
#include <string>

#include "io/staged_directory.h"

namespace {

namespace fs = std::filesystem;

fs::path scratch_dir(const std::string& name) {
  const fs::path dir = fs::path(GI_BINARY_DIR) / "test_output" / "staged_directory_test" / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << text;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

fs::path staging_of(const fs::path& dir) { return dir.parent_path() / ("." + dir.filename().string() + ".staging"); }

TEST(StagedDirectory, StartsFromACopyAndCommitReplacesTheDirectory) {
  const fs::path dir = scratch_dir("commit") / "bundle";
  fs::create_directories(dir);
  write_text(dir / "kept.txt", "kept");
  write_text(dir / "changed.txt", "old");
  {
    auto staged = gi::StagedDirectory::begin(dir, "test writer");
    ASSERT_TRUE(staged.ok()) << staged.error().to_string();
    EXPECT_EQ(staged->path(), staging_of(dir));
    EXPECT_EQ(read_text(staged->path() / "kept.txt"), "kept");  // the old contents, copied
    write_text(staged->path() / "changed.txt", "new");
    write_text(staged->path() / "added.txt", "added");
    EXPECT_EQ(read_text(dir / "changed.txt"), "old");  // not visible before the commit
    EXPECT_FALSE(fs::exists(dir / "added.txt"));
    ASSERT_TRUE(staged->commit().ok());
  }
  EXPECT_EQ(read_text(dir / "kept.txt"), "kept");
  EXPECT_EQ(read_text(dir / "changed.txt"), "new");
  EXPECT_EQ(read_text(dir / "added.txt"), "added");
  EXPECT_FALSE(fs::exists(staging_of(dir))) << "the previous contents were left behind";
}

TEST(StagedDirectory, CommitCreatesADirectoryThatDidNotExist) {
  const fs::path dir = scratch_dir("create") / "nested" / "bundle";
  {
    auto staged = gi::StagedDirectory::begin(dir, "test writer");
    ASSERT_TRUE(staged.ok()) << staged.error().to_string();
    EXPECT_TRUE(fs::is_directory(staged->path()));
    EXPECT_TRUE(fs::is_empty(staged->path()));
    write_text(staged->path() / "a.txt", "a");
    ASSERT_TRUE(staged->commit().ok());
  }
  EXPECT_EQ(read_text(dir / "a.txt"), "a");
  EXPECT_FALSE(fs::exists(staging_of(dir)));
}

TEST(StagedDirectory, AWriterThatDoesNotCommitLeavesTheOldDirectoryAsItWas) {
  const fs::path dir = scratch_dir("abandon") / "bundle";
  fs::create_directories(dir);
  write_text(dir / "a.txt", "old");
  {
    auto staged = gi::StagedDirectory::begin(dir, "test writer");
    ASSERT_TRUE(staged.ok()) << staged.error().to_string();
    write_text(staged->path() / "a.txt", "half-written");
    fs::remove(staged->path() / "a.txt");
  }
  EXPECT_EQ(read_text(dir / "a.txt"), "old");
  EXPECT_FALSE(fs::exists(staging_of(dir)));
}

TEST(StagedDirectory, ASecondWriterIsRefusedWhileTheFirstHoldsTheLock) {
  const fs::path dir = scratch_dir("lock") / "bundle";
  std::optional<gi::StagedDirectory> first;
  {
    auto staged = gi::StagedDirectory::begin(dir, "test writer");
    ASSERT_TRUE(staged.ok()) << staged.error().to_string();
    first.emplace(std::move(staged).value());
  }
  auto second = gi::StagedDirectory::begin(dir, "test writer");
  ASSERT_FALSE(second.ok());
  EXPECT_EQ(second.error().file, dir.string());
  EXPECT_NE(second.error().message.find("another test writer is running"), std::string::npos)
      << second.error().to_string();
  EXPECT_TRUE(fs::exists(first->path())) << "the refused writer removed the first one's staging copy";
  first.reset();  // releases the lock
  auto third = gi::StagedDirectory::begin(dir, "test writer");
  EXPECT_TRUE(third.ok()) << third.error().to_string();
}

TEST(StagedDirectory, AKilledWritersStagingCopyIsClearedByTheNext) {
  const fs::path dir = scratch_dir("leftover") / "bundle";
  fs::create_directories(dir);
  write_text(dir / "a.txt", "a");
  fs::create_directories(staging_of(dir));
  write_text(staging_of(dir) / "junk.txt", "from a killed writer");
  auto staged = gi::StagedDirectory::begin(dir, "test writer");
  ASSERT_TRUE(staged.ok()) << staged.error().to_string();
  EXPECT_FALSE(fs::exists(staged->path() / "junk.txt"));
  EXPECT_EQ(read_text(staged->path() / "a.txt"), "a");
}

TEST(StagedDirectory, AFileWhereTheDirectoryShouldBeIsRefused) {
  const fs::path dir = scratch_dir("file") / "bundle";
  write_text(dir, "not a directory");
  auto staged = gi::StagedDirectory::begin(dir, "test writer");
  ASSERT_FALSE(staged.ok());
  EXPECT_EQ(staged.error().file, dir.string());
  EXPECT_NE(staged.error().message.find("not a directory"), std::string::npos) << staged.error().to_string();
  EXPECT_EQ(read_text(dir), "not a directory");
}

}  // namespace
