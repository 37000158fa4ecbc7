// The golden criterion of tests/golden.h on synthetic 84 x 84 frames: what it admits (what another
// Mesa build changes) and what it must catch (a moved or misplaced object).
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "tests/golden.h"

namespace pixelgym::testing {
namespace {

constexpr int kSize = 84;

struct Frame {
  std::vector<std::uint8_t> rgb = std::vector<std::uint8_t>(kSize * kSize * 3);
  void fill(int row0, int row1, int col0, int col1, std::uint8_t r, std::uint8_t g,
            std::uint8_t b) {
    for (int row = row0; row < row1; ++row) {
      for (int col = col0; col < col1; ++col) {
        const std::size_t p = static_cast<std::size_t>(row * kSize + col) * 3;
        rgb[p] = r;
        rgb[p + 1] = g;
        rgb[p + 2] = b;
      }
    }
  }
};

// Sky above row `horizon`, floor below, a one-pixel-wide dark pole at column `pole` from row 20 to
// 60, and a 10-pixel-wide red cart at columns [cart, cart + 10) over rows 58 to 66.
Frame scene(int horizon = 42, int pole = 40, int cart = 36) {
  Frame f;
  f.fill(0, horizon, 0, kSize, 190, 210, 235);
  f.fill(horizon, kSize, 0, kSize, 90, 100, 115);
  f.fill(58, 66, cart, cart + 10, 200, 60, 50);
  f.fill(20, 60, pole, pole + 1, 120, 80, 40);
  return f;
}

GoldenDifference compare(const Frame& actual, const Frame& expected) {
  return golden_difference(actual.rgb.data(), expected.rgb.data(), kSize, kSize);
}

bool passes(const Frame& actual, const Frame& expected) {
  return within_golden_limits(compare(actual, expected), kSize, kSize);
}

TEST(GoldenCriterionTest, IdenticalFramesHaveNoDifference) {
  const GoldenDifference d = compare(scene(), scene());
  EXPECT_EQ(d.thick_windows, 0);
  EXPECT_EQ(d.displaced_pixels, 0);
  EXPECT_EQ(d.clipped_mean, 0.0);
}

// What softpipe does to llvmpipe's frames: a whole horizon row on the other side, a few edge
// pixels, shading a level apart.
TEST(GoldenCriterionTest, AdmitsEdgesOnePixelOverAndShadingALevelApart) {
  const Frame golden = scene();
  EXPECT_TRUE(passes(scene(43), golden));  // 84 pixels off by about 100, in one row
  Frame rounded = scene(43);
  for (std::uint8_t& v : rounded.rgb) v = static_cast<std::uint8_t>(v + 1);
  EXPECT_TRUE(passes(rounded, golden)) << "every channel a level up, and the horizon row";
  Frame specks = scene();
  for (int k = 0; k < 10; ++k) specks.fill(5 + 7 * k, 6 + 7 * k, 70, 71, 0, 0, 0);
  EXPECT_TRUE(passes(specks, golden)) << "10 isolated black pixels";
}

TEST(GoldenCriterionTest, CatchesAThinPoleMovedByOnePixel) {
  const GoldenDifference d = compare(scene(42, 41), scene());
  EXPECT_EQ(d.thick_windows, 39);  // a band two pixels wide and 40 tall
  EXPECT_FALSE(within_golden_limits(d, kSize, kSize));
}

// Two separate one-pixel lines: not thick, but nothing near the new pole was pole before.
TEST(GoldenCriterionTest, CatchesAThinPoleFarFromItsPlace) {
  const GoldenDifference d = compare(scene(42, 50), scene());
  EXPECT_EQ(d.thick_windows, 0);
  EXPECT_EQ(d.displaced_pixels, 2 * 40);  // the old pole and the new
  EXPECT_FALSE(within_golden_limits(d, kSize, kSize));
}

TEST(GoldenCriterionTest, CatchesAWideObjectMovedByTwoPixels) {
  const GoldenDifference moved_one = compare(scene(42, 40, 37), scene());
  EXPECT_LE(moved_one.thick_windows, kGoldenMaxThickWindows)
      << "one pixel: admitted (see golden.h)";
  const GoldenDifference moved_two = compare(scene(42, 40, 38), scene());
  EXPECT_GT(moved_two.thick_windows, kGoldenMaxThickWindows);
  EXPECT_FALSE(within_golden_limits(moved_two, kSize, kSize));
}

TEST(GoldenCriterionTest, CatchesAColourOrLightChangedEverywhere) {
  Frame darker = scene();
  for (std::uint8_t& v : darker.rgb) v = static_cast<std::uint8_t>(v - 2);
  const GoldenDifference d = compare(darker, scene());
  EXPECT_EQ(d.thick_windows, 0);
  EXPECT_EQ(d.displaced_pixels, 0);
  EXPECT_NEAR(d.clipped_mean, 2.0, 1e-9);
  EXPECT_FALSE(within_golden_limits(d, kSize, kSize));
}

TEST(GoldenCriterionTest, DiffImageMarksWhatFailed) {
  const GoldenDifference d = compare(scene(42, 50), scene());
  // The new pole's pixel at (30, 50) is displaced: blue.
  const std::size_t p = static_cast<std::size_t>(30 * kSize + 50) * 3;
  EXPECT_EQ(d.diff_rgb[p + 1], 0);
  EXPECT_EQ(d.diff_rgb[p + 2], 255);
}

}  // namespace
}  // namespace pixelgym::testing
