#include "pixelgym/render/image_io.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace pixelgym::render {
namespace {

std::string output_path(const std::string& name) {
  std::filesystem::create_directories(PIXELGYM_TEST_OUTPUT_DIR);
  return std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/" + name;
}

TEST(ImageIoTest, RoundTripsRgbExactly) {
  std::vector<std::uint8_t> pixels(5 * 7 * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = static_cast<std::uint8_t>(i * 37);
  const std::string path = output_path("image_io_roundtrip.png");
  write_png(path, {pixels.data(), 5, 7, 3});
  const Image image = read_png(path);
  EXPECT_EQ(image.height, 5);
  EXPECT_EQ(image.width, 7);
  EXPECT_EQ(image.channels, 3);
  EXPECT_EQ(image.pixels, pixels);
  // Nothing but the finished file is left behind.
  // Only this file's temporaries count: tests running beside this one write their own.
  for (const auto& entry : std::filesystem::directory_iterator(PIXELGYM_TEST_OUTPUT_DIR)) {
    EXPECT_NE(entry.path().string().rfind(path + ".tmp.", 0), 0U) << entry.path();
  }
}

TEST(ImageIoTest, RoundTripsGray) {
  const std::vector<std::uint8_t> pixels = {0, 64, 128, 255};
  const std::string path = output_path("image_io_gray.png");
  write_png(path, {pixels.data(), 2, 2, 1});
  const Image image = read_png(path);
  EXPECT_EQ(image.channels, 1);
  EXPECT_EQ(image.pixels, pixels);
}

TEST(ImageIoTest, UnwritablePathThrowsNamingItAndLeavesNothing) {
  const std::vector<std::uint8_t> pixels(12);
  const std::string path = "/nonexistent-folder/x.png";
  try {
    write_png(path, {pixels.data(), 2, 2, 3});
    FAIL();
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
  }
}

// What write_png threw for `path`, or "" when it did not throw.
std::string write_error(const std::string& path, const ImageView& image) {
  try {
    write_png(path, image);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

// Noise compresses badly: 256 x 256 RGB is a PNG of about 200 kB.
std::vector<std::uint8_t> noise(int height, int width) {
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(height * width * 3));
  std::mt19937 random(7);
  for (std::uint8_t& v : pixels) v = static_cast<std::uint8_t>(random());
  return pixels;
}

std::vector<std::string> entries(const std::string& folder) {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    names.push_back(entry.path().filename().string());
  return names;
}

// Mounts a tmpfs with `options` on a fresh folder, in a mount namespace of this process's own (so
// nothing outlives the test). Returns "" when mounting is not permitted here.
std::string mount_tmpfs(const std::string& name, unsigned long flags, const char* options) {
  if (::unshare(CLONE_NEWNS) != 0) return "";
  if (::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0) return "";
  const std::string folder = output_path(name);
  std::filesystem::create_directories(folder);
  if (::mount("tmpfs", folder.c_str(), "tmpfs", flags, options) != 0) return "";
  return folder;
}

// `pixelgym snapshot --out /dev/full` once printed "wrote /dev/full": a device is not a file.
TEST(ImageIoTest, DevFullIsRefusedNamingIt) {
  const std::vector<std::uint8_t> pixels(12);
  const std::string error = write_error("/dev/full", {pixels.data(), 2, 2, 3});
  EXPECT_NE(error.find("cannot write /dev/full: it is a character device, not a regular file"),
            std::string::npos)
      << error;
  // And the device is still a device, with no temporary left beside it.
  EXPECT_TRUE(std::filesystem::is_character_file("/dev/full"));
  for (const std::string& name : entries("/dev")) EXPECT_NE(name.rfind("full.tmp.", 0), 0U) << name;
}

TEST(ImageIoTest, FolderIsRefused) {
  const std::vector<std::uint8_t> pixels(12);
  const std::string folder = output_path("image_io_a_folder.png");
  std::filesystem::create_directories(folder);
  EXPECT_NE(write_error(folder, {pixels.data(), 2, 2, 3}).find("it is a folder"),
            std::string::npos);
}

// A path under a regular file: the folder cannot exist (root ignores permission bits, so a
// chmod-ed folder would not test anything here).
TEST(ImageIoTest, PathUnderAFileThrowsTheOsError) {
  const std::vector<std::uint8_t> pixels(12);
  const std::string file = output_path("image_io_plain_file");
  write_png(file, {pixels.data(), 2, 2, 3});
  const std::string error = write_error(file + "/x.png", {pixels.data(), 2, 2, 3});
  EXPECT_NE(error.find("cannot write " + file + "/x.png: Not a directory"), std::string::npos)
      << error;
}

TEST(ImageIoTest, ReadOnlyFolderThrowsTheOsErrorAndLeavesNothing) {
  const std::string folder = mount_tmpfs("image_io_read_only", MS_RDONLY, "size=64k");
  if (folder.empty()) GTEST_SKIP() << "mounting a tmpfs is not permitted here";
  const std::vector<std::uint8_t> pixels(12);
  const std::string path = folder + "/x.png";
  const std::string error = write_error(path, {pixels.data(), 2, 2, 3});
  EXPECT_NE(error.find("cannot write " + path + ": Read-only file system"), std::string::npos)
      << error;
  EXPECT_TRUE(entries(folder).empty());
}

// A 16 kB tmpfs: the PNG of noise does not fit. The write fails with the OS error, no temporary
// or partial file is left, and a file already under the name keeps its old content.
TEST(ImageIoTest, FullDiskThrowsTheOsErrorAndKeepsTheOldFile) {
  const std::string folder = mount_tmpfs("image_io_full", 0, "size=16k");
  if (folder.empty()) GTEST_SKIP() << "mounting a tmpfs is not permitted here";
  const std::string path = folder + "/x.png";
  const std::vector<std::uint8_t> small(12, 99);
  write_png(path, {small.data(), 2, 2, 3});
  const std::vector<std::uint8_t> big = noise(256, 256);
  const std::string error = write_error(path, {big.data(), 256, 256, 3});
  EXPECT_NE(error.find("cannot write " + path + ": No space left on device"), std::string::npos)
      << error;
  EXPECT_EQ(entries(folder), std::vector<std::string>{"x.png"});
  EXPECT_EQ(read_png(path).pixels, small);
  // A new name: nothing at all is left.
  const std::string fresh = folder + "/y.png";
  EXPECT_NE(write_error(fresh, {big.data(), 256, 256, 3}).find("No space left on device"),
            std::string::npos);
  EXPECT_EQ(entries(folder), std::vector<std::string>{"x.png"});
}

// A symbolic link to a file: the file is rewritten, the link stays.
TEST(ImageIoTest, WritesThroughASymbolicLink) {
  const std::vector<std::uint8_t> pixels(12, 5);
  const std::string file = output_path("image_io_link_target.png");
  const std::string link = output_path("image_io_link.png");
  std::filesystem::remove(link);
  write_png(file, {pixels.data(), 2, 2, 3});
  std::filesystem::create_symlink(file, link);
  const std::vector<std::uint8_t> other(12, 9);
  write_png(link, {other.data(), 2, 2, 3});
  EXPECT_TRUE(std::filesystem::is_symlink(link));
  EXPECT_EQ(read_png(file).pixels, other);
}

TEST(ImageIoTest, MalformedViewIsRejected) {
  const std::vector<std::uint8_t> pixels(12);
  EXPECT_THROW(write_png(output_path("bad.png"), {pixels.data(), 0, 2, 3}), std::invalid_argument);
  EXPECT_THROW(write_png(output_path("bad.png"), {pixels.data(), 2, 2, 2}), std::invalid_argument);
  EXPECT_THROW(write_png(output_path("bad.png"), {nullptr, 2, 2, 3}), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(output_path("bad.png")));
}

TEST(ImageIoTest, UnreadableFileThrowsNamingIt) {
  const std::string path = output_path("not_a_png.png");
  {
    std::FILE* f = std::fopen(path.c_str(), "w");
    std::fputs("hello", f);
    std::fclose(f);
  }
  EXPECT_THROW(read_png(path), std::runtime_error);
  EXPECT_THROW(read_png(output_path("missing.png")), std::runtime_error);
}

}  // namespace
}  // namespace pixelgym::render
