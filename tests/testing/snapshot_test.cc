// compare_to_golden as a user meets it: the files it writes and reads, its messages, the update
// switch, segmentation goldens, and EXPECT_MATCHES_GOLDEN.
#include "pixelgym/testing/snapshot.h"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/render/image_io.h"
#include "pixelgym/testing/gtest.h"

namespace pixelgym::testing {
namespace {

namespace fs = std::filesystem;

// These tests set the update switch themselves where they test it; `make goldens`
// (PIXELGYM_UPDATE_GOLDENS=1 ctest -R Golden) must not reach the others.
[[maybe_unused]] const bool kUpdateSwitchCleared = [] {
  ::unsetenv("PIXELGYM_UPDATE_GOLDENS");
  return true;
}();

using Status = SnapshotResult::Status;

constexpr int kSize = 32;

// Sky above row 16, floor below, a one-pixel pole at column `pole`.
Array frame(int pole = 10, int size = kSize) {
  Array image(DType::kUInt8, {size, size, 3});
  std::uint8_t* p = image.data<std::uint8_t>();
  for (int row = 0; row < size; ++row) {
    for (int col = 0; col < size; ++col) {
      std::uint8_t* px = p + (row * size + col) * 3;
      const bool sky = row < size / 2;
      px[0] = sky ? 190 : 90;
      px[1] = sky ? 210 : 100;
      px[2] = sky ? 235 : 115;
      if (col == pole && row >= 4 && row < 28) px[0] = px[1] = px[2] = 30;
    }
  }
  return image;
}

// A fresh folder for one test, with `golden` and `out` inside.
struct Folder {
  explicit Folder(const std::string& name)
      : root(fs::path(PIXELGYM_TEST_OUTPUT_DIR) / "snapshot" / name) {
    fs::remove_all(root);
    fs::create_directories(root);
    options.output_dir = (root / "out").string();
    options.update = SnapshotOptions::Update::kNever;
  }
  std::string golden(const std::string& name = "scene.png") const {
    return (root / "golden" / name).string();
  }
  fs::path root;
  SnapshotOptions options;
};

// Segmentation labels: 0 above row 16, -1 below, a two-pixel pole labelled 7 at column `pole`.
Array labels(int pole) {
  Array image(DType::kInt32, {kSize, kSize});
  std::int32_t* p = image.data<std::int32_t>();
  for (int row = 0; row < kSize; ++row) {
    for (int col = 0; col < kSize; ++col) {
      p[row * kSize + col] = (col == pole || col == pole + 1) && row > 4 ? 7 : (row < 16 ? 0 : -1);
    }
  }
  return image;
}

SnapshotResult write_golden(const Array& image, const std::string& path) {
  SnapshotOptions options;
  options.update = SnapshotOptions::Update::kAlways;
  return compare_to_golden(image, path, {}, options);
}

SnapshotResult write_segmentation_golden(const Array& labels, const std::string& path) {
  SnapshotOptions options;
  options.update = SnapshotOptions::Update::kAlways;
  return compare_segmentation_to_golden(labels, path, {}, options);
}

TEST(SnapshotTest, UpdateWritesTheGoldenAndSaysSo) {
  Folder folder("update");
  const SnapshotResult result = write_golden(frame(), folder.golden());
  EXPECT_EQ(result.status, Status::kUpdated);
  EXPECT_TRUE(result);
  EXPECT_NE(result.message().find("wrote golden " + folder.golden()), std::string::npos);
  const render::Image written = render::read_png(folder.golden());
  const Array expected = frame();
  EXPECT_EQ(written.pixels, std::vector<std::uint8_t>(expected.data<std::uint8_t>(),
                                                      expected.data<std::uint8_t>() + 32 * 32 * 3));
}

TEST(SnapshotTest, EnvironmentVariableUpdates) {
  Folder folder("update_env");
  SnapshotOptions options = folder.options;
  options.update = SnapshotOptions::Update::kFromEnvironment;
  ::setenv("PIXELGYM_UPDATE_GOLDENS", "1", 1);
  const SnapshotResult result = compare_to_golden(frame(), folder.golden(), {}, options);
  ::unsetenv("PIXELGYM_UPDATE_GOLDENS");
  EXPECT_EQ(result.status, Status::kUpdated);
  EXPECT_TRUE(fs::exists(folder.golden()));
  EXPECT_EQ(compare_to_golden(frame(3), folder.golden(), {}, options).status, Status::kDiffered);
}

TEST(SnapshotTest, MatchWritesNothing) {
  Folder folder("match");
  write_golden(frame(), folder.golden());
  const SnapshotResult result = compare_to_golden(frame(), folder.golden(), {}, folder.options);
  EXPECT_EQ(result.status, Status::kMatched) << result.message();
  EXPECT_TRUE(result.actual_path.empty());
  EXPECT_FALSE(fs::exists(folder.root / "out"));
}

TEST(SnapshotTest, MismatchWritesActualAndDiffAndGivesTheFigures) {
  Folder folder("mismatch");
  write_golden(frame(10), folder.golden());
  const SnapshotResult result = compare_to_golden(frame(11), folder.golden(), {}, folder.options);
  EXPECT_FALSE(result);
  EXPECT_EQ(result.status, Status::kDiffered);
  EXPECT_EQ(result.figures.thick_windows, 23);  // the pole moved by one: a band 2 wide, 24 tall
  EXPECT_EQ(result.figures.off_pixels, 48);
  EXPECT_EQ(result.actual_path, (folder.root / "out" / "scene.actual.png").string());
  EXPECT_EQ(result.diff_path, (folder.root / "out" / "scene.diff.png").string());
  EXPECT_EQ(render::read_png(result.actual_path).height, kSize);
  // The diff: red where 2 x 2 windows are all off (the pole's band), grey elsewhere.
  const render::Image diff = render::read_png(result.diff_path);
  const std::size_t pole = (10 * kSize + 10) * 3;
  EXPECT_EQ(diff.pixels[pole], 255);
  EXPECT_EQ(diff.pixels[pole + 1], 0);
  EXPECT_EQ(diff.pixels[0], 0);
  const std::string message = result.message();
  for (const std::string& part :
       {std::string("differs from golden ") + folder.golden(),
        std::string("23 2x2 windows of pixels off by more than 8 (limit 4)"),
        std::string("mean absolute difference"),
        std::string("48 pixels (4.69 %) off by more than 8"),
        std::string("Actual: ") + result.actual_path, std::string("diff: ") + result.diff_path,
        std::string("PIXELGYM_UPDATE_GOLDENS=1")}) {
    EXPECT_NE(message.find(part), std::string::npos) << part << "\n" << message;
  }
}

TEST(SnapshotTest, MissingGoldenSaysHowToCreateIt) {
  Folder folder("missing");
  const SnapshotResult result = compare_to_golden(frame(), folder.golden(), {}, folder.options);
  EXPECT_EQ(result.status, Status::kMissingGolden);
  EXPECT_FALSE(result);
  EXPECT_TRUE(fs::exists(result.actual_path));
  EXPECT_NE(result.message().find("no golden " + folder.golden()), std::string::npos);
  EXPECT_NE(result.message().find("PIXELGYM_UPDATE_GOLDENS=1"), std::string::npos);
  EXPECT_FALSE(fs::exists(folder.golden())) << "a missing golden is not created by a comparison";
}

TEST(SnapshotTest, GoldenOfAnotherSizeNamesBothSizes) {
  Folder folder("size");
  write_golden(frame(10, 24), folder.golden());
  const SnapshotResult result = compare_to_golden(frame(), folder.golden(), {}, folder.options);
  EXPECT_EQ(result.status, Status::kSizeMismatch);
  EXPECT_EQ(result.golden_width, 24);
  EXPECT_NE(result.message().find("golden " + folder.golden() + " is 24x24, the frame 32x32"),
            std::string::npos)
      << result.message();
  // An RGBA golden of the right size is another size too.
  const std::vector<std::uint8_t> rgba(kSize * kSize * 4, 255);
  render::write_png(folder.golden("rgba.png"), {rgba.data(), kSize, kSize, 4});
  const SnapshotResult rgba_result =
      compare_to_golden(frame(), folder.golden("rgba.png"), {}, folder.options);
  EXPECT_EQ(rgba_result.status, Status::kSizeMismatch);
  EXPECT_NE(rgba_result.message().find("is 32x32 RGBA, the frame 32x32"), std::string::npos)
      << rgba_result.message();
}

TEST(SnapshotTest, UnreadableGoldenIsAFailureNotAThrow) {
  Folder folder("unreadable");
  fs::create_directories(fs::path(folder.golden()).parent_path());
  std::ofstream(folder.golden()) << "not a png";
  const SnapshotResult result = compare_to_golden(frame(), folder.golden(), {}, folder.options);
  EXPECT_EQ(result.status, Status::kUnreadableGolden);
  EXPECT_NE(result.message().find("cannot be read"), std::string::npos) << result.message();
}

TEST(SnapshotTest, OutputFolderFromTheEnvironment) {
  Folder folder("output_env");
  write_golden(frame(10), folder.golden());
  SnapshotOptions options;
  options.update = SnapshotOptions::Update::kNever;
  const std::string dir = (folder.root / "from_env").string();
  ::setenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR", dir.c_str(), 1);
  const SnapshotResult result = compare_to_golden(frame(20), folder.golden(), {}, options);
  ::unsetenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR");
  EXPECT_EQ(result.diff_path, dir + "/scene.diff.png");
  EXPECT_TRUE(fs::exists(result.diff_path));
}

TEST(SnapshotTest, WrongFrameIsAnInvalidArgument) {
  EXPECT_THROW(compare_to_golden(Array(DType::kFloat32, {4, 4, 3}), "x.png"),
               std::invalid_argument);
  EXPECT_THROW(compare_to_golden(Array(DType::kUInt8, {4, 4, 4}), "x.png"), std::invalid_argument);
}

TEST(SnapshotTest, SegmentationGoldenRoundTripsAndCatchesAMove) {
  Folder folder("segmentation");
  EXPECT_EQ(write_segmentation_golden(labels(10), folder.golden("seg.png")).status,
            Status::kUpdated);
  const SnapshotResult same =
      compare_segmentation_to_golden(labels(10), folder.golden("seg.png"), {}, folder.options);
  EXPECT_EQ(same.status, Status::kMatched) << same.message();
  const SnapshotResult moved =
      compare_segmentation_to_golden(labels(14), folder.golden("seg.png"), {}, folder.options);
  EXPECT_EQ(moved.status, Status::kDiffered);
  EXPECT_NE(moved.message().find("2x2 windows of differing labels"), std::string::npos)
      << moved.message();
  EXPECT_TRUE(fs::exists(moved.diff_path));
}

// --- the GoogleTest adapter ---

TEST(SnapshotGtestTest, ExpectMatchesGoldenPassesAndFails) {
  Folder folder("gtest");
  write_golden(frame(), folder.golden());
  ::setenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR", (folder.root / "out").c_str(), 1);
  EXPECT_MATCHES_GOLDEN(frame(), folder.golden());
  EXPECT_NONFATAL_FAILURE(EXPECT_MATCHES_GOLDEN(frame(20), folder.golden()),
                          "does not match the golden");
  EXPECT_NONFATAL_FAILURE(EXPECT_MATCHES_GOLDEN(frame(20), folder.golden()),
                          "2x2 windows of pixels off by more than 8");
  SnapshotTolerance loose;
  loose.max_thick_windows = 1000;
  loose.max_displaced_fraction = 1.0;
  EXPECT_MATCHES_GOLDEN_WITHIN(frame(20), folder.golden(), loose);
  // Under /dev/null no golden can exist, nor be written by a run with the update switch on.
  EXPECT_FATAL_FAILURE(ASSERT_MATCHES_GOLDEN(frame(20), "/dev/null/golden.png"),
                       "no golden /dev/null/golden.png");
  ::unsetenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR");
}

TEST(SnapshotGtestTest, SegmentationMacrosPassAndFail) {
  Folder folder("gtest_segmentation");
  ASSERT_EQ(write_segmentation_golden(labels(10), folder.golden("seg.png")).status,
            Status::kUpdated);
  ::setenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR", (folder.root / "out").c_str(), 1);
  EXPECT_SEGMENTATION_MATCHES_GOLDEN(labels(10), folder.golden("seg.png"));
  ASSERT_SEGMENTATION_MATCHES_GOLDEN(labels(10), folder.golden("seg.png"));
  EXPECT_NONFATAL_FAILURE(EXPECT_SEGMENTATION_MATCHES_GOLDEN(labels(14), folder.golden("seg.png")),
                          "2x2 windows of differing labels");
  EXPECT_FATAL_FAILURE(ASSERT_SEGMENTATION_MATCHES_GOLDEN(labels(14), "/dev/null/seg.png"),
                       "no golden /dev/null/seg.png");
  ::unsetenv("PIXELGYM_SNAPSHOT_OUTPUT_DIR");
}

}  // namespace
}  // namespace pixelgym::testing
