#include "pixelgym/trainer/atomic_file.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/examples/trainer/run/test_folders.h"

namespace pixelgym::trainer {
namespace {

using test_folders::entries;
using test_folders::fresh_folder;
using test_folders::mount_tmpfs;
using ::testing::HasSubstr;

// What write_file_atomically threw, or "" when it did not throw.
std::string write_error(const std::filesystem::path& path, const std::string& text) {
  try {
    write_file_atomically(path, {text}, "test");
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

TEST(AtomicFileTest, WritesTheConcatenationAndLeavesOnlyTheFile) {
  const auto folder = fresh_folder("atomic_concat");
  const std::string a = "hello ";
  const std::string b(3, '\0');
  write_file_atomically(folder / "x.bin", {a, b, "world"}, "test");
  EXPECT_EQ(read_whole_file(folder / "x.bin", "test"), a + b + "world");
  EXPECT_EQ(entries(folder), std::vector<std::string>{"x.bin"});
}

TEST(AtomicFileTest, ReplacesAnExistingFile) {
  const auto folder = fresh_folder("atomic_replace");
  write_file_atomically(folder / "x.txt", {"a much longer first version"}, "test");
  write_file_atomically(folder / "x.txt", {"short"}, "test");
  EXPECT_EQ(read_whole_file(folder / "x.txt", "test"), "short");
  EXPECT_EQ(entries(folder), std::vector<std::string>{"x.txt"});
}

TEST(AtomicFileTest, TemporaryNamesStartWithTheDocumentedPrefix) {
  EXPECT_EQ(temporary_file_prefix("ckpt-000001.pgck"), ".ckpt-000001.pgck.tmp.");
}

TEST(AtomicFileTest, MissingFolderThrowsNamingThePath) {
  const auto folder = fresh_folder("atomic_missing");
  const auto path = folder / "no" / "x.txt";
  EXPECT_THAT(write_error(path, "x"),
              HasSubstr("test: cannot write " + path.string() + ": No such file or directory"));
}

TEST(AtomicFileTest, AFolderUnderTheNameIsRefused) {
  const auto folder = fresh_folder("atomic_folder");
  std::filesystem::create_directories(folder / "x.txt");
  EXPECT_THAT(write_error(folder / "x.txt", "x"), HasSubstr("not a regular file"));
  EXPECT_EQ(entries(folder), std::vector<std::string>{"x.txt"});
}

TEST(AtomicFileTest, ReadOnlyFolderThrowsTheOsErrorAndLeavesNothing) {
  const auto folder = mount_tmpfs("atomic_read_only", MS_RDONLY, "size=64k");
  if (folder.empty()) GTEST_SKIP() << "mounting a tmpfs is not permitted here";
  const auto path = folder / "x.txt";
  EXPECT_THAT(write_error(path, "x"),
              HasSubstr("cannot write " + path.string() + ": Read-only file system"));
  EXPECT_TRUE(entries(folder).empty());
}

// 64 kB of tmpfs: 100 kB does not fit. The old file keeps its content, no temporary is left.
TEST(AtomicFileTest, FullDiskKeepsTheOldFileAndLeavesNoTemporary) {
  const auto folder = mount_tmpfs("atomic_full", 0, "size=64k");
  if (folder.empty()) GTEST_SKIP() << "mounting a tmpfs is not permitted here";
  const auto path = folder / "x.bin";
  write_file_atomically(path, {"old"}, "test");
  EXPECT_THAT(write_error(path, std::string(100000, 'x')),
              HasSubstr("cannot write " + path.string() + ": No space left on device"));
  EXPECT_EQ(read_whole_file(path, "test"), "old");
  EXPECT_EQ(entries(folder), std::vector<std::string>{"x.bin"});
}

TEST(AtomicFileTest, ReadingAMissingFileThrowsNamingIt) {
  const auto path = fresh_folder("atomic_read") / "absent.bin";
  try {
    read_whole_file(path, "reader");
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("reader: cannot read " + path.string() + ": No such file or directory"));
  }
}

}  // namespace
}  // namespace pixelgym::trainer
