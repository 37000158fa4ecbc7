#include "render/image_io.h"

#include <gtest/gtest.h>

#include <filesystem>

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
