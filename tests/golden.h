// Compares a rendered frame with a golden PNG under tests/golden/.
//
// On this machine and Mesa build frames are identical bytes. The criterion must still admit
// another Mesa build, whose differences are of two kinds: shading rounded a level or two apart,
// and edges rasterized one pixel over (a pixel centre that falls on the other side of an edge) —
// for a straight edge that can be a whole row, such as the horizon. It must not admit a moved
// object: at 84 x 84 a pole or a link is one or two pixels wide and moves a few pixels for a few
// hundredths of a radian. A frame passes when all three hold ("off" means some channel differs by
// more than 8):
//
//  1. Thick changes: at most 4 windows of 2 x 2 pixels that are all off. A rasterization
//     difference moves an edge by at most one pixel, which changes a line one pixel wide. An
//     object moved by two pixels or more, or a one-pixel-wide part (a pole or a link at 84 x 84)
//     moved by one, changes a band at least two pixels wide (old and new place side by side).
//  2. Displaced pixels: at most 0.2 % of the pixels (14 at 84 x 84) whose colour appears nowhere
//     in the other image's 3 x 3 neighbourhood of the same place, within 32 per channel, looked
//     for both ways. An edge one pixel over finds its colour next door; an object somewhere else
//     (a thin pole flipped upright, where the thick test sees two separate one-pixel lines) does
//     not.
//  3. Shading: the mean absolute difference over all channels, each clipped at 8, at most 1.5 —
//     every channel a level apart passes (with edges one pixel over, up to about 1.1); a light
//     or colour changed by two levels everywhere does not. (Clipping
//     keeps the few edge pixels that flip between sky and floor, off by up to 120, from counting
//     as a shading change: the unclipped mean was the old criterion, and one horizon row moved by
//     softpipe put it at 1.4.)
//
// What it admits: any edge one pixel over — so a wide object moved by about a pixel, whose edges
// each move by one, passes (the cart body moved 0.05 m, one pixel, changes only a one-pixel column
// at each side; the cart-pole frame fails because the pole on it, one pixel wide, moves too);
// shading within about a level everywhere; a few isolated pixels.
//
// Measured (2x2 windows / displaced pixels / clipped mean) against the goldens:
//  - Mesa softpipe (GALLIUM_DRIVER=softpipe) instead of llvmpipe, every golden: at most 0 / 5 /
//    0.17 at 84 x 84 (5 displaced in env_ArmPush-v0), 2 / 1 / 0.04 in cartpole_256 and 0 / 27 /
//    0.07 in arm_256 (0.04 % displaced): it passes. (The old criterion, unclipped mean <= 1.0 and
//    <= 1 % of pixels off by more than 8, failed it: mean up to 1.56, up to 1.9 % off.)
//  - Mutants planted in the tasks' initialize_episode (first observation at 84 x 84), each fails:
//    cart-pole pole +-0.05 rad: 11-19 windows (and 5-19 displaced); cart +-0.05 m (one pixel):
//    23-25 windows, from the pole; swing-up starting upright (kPi dropped): 2 windows but 48
//    displaced; acrobot lower link +-0.1 rad: 31-34 windows; pendulum +-0.05 rad: 14-19 windows.
//    None moves the clipped mean past 0.09: it is there for colour and light, not for motion.
//  - Smaller mutants, for the edge of what it sees: pole +0.02 rad fails both swing-up frames (6
//    windows) but passes the balance frames; +0.03 rad fails all four (6-8 windows); pendulum
//    +0.02 rad fails (5 windows); acrobot lower link +0.05 rad fails (23 windows).
//
// On failure the actual frame and a diff image are written to build/test_output/golden/: grey is
// |difference| x 8, red marks the 2 x 2 windows all off, blue the displaced pixels (magenta both).
// To regenerate every golden: PIXELGYM_UPDATE_GOLDENS=1 make test (or `make goldens`), then look
// at each PNG before committing it.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "render/image_io.h"

namespace pixelgym::testing {

/// The figures the golden criterion bounds (see the top of this file).
struct GoldenDifference {
  /// 2 x 2 windows whose four pixels all have a channel off by more than 8.
  int thick_windows = 0;
  /// Pixels whose colour is not within 32 per channel of any pixel in the other image's 3 x 3
  /// neighbourhood, looked for both ways.
  int displaced_pixels = 0;
  /// Mean absolute difference over all channels, each clipped at 8.
  double clipped_mean = 0.0;
  /// |difference| x 8 in grey, 2 x 2 windows all off in red, displaced pixels in blue.
  std::vector<std::uint8_t> diff_rgb;
};

inline constexpr int kGoldenOffBy = 8;
inline constexpr int kGoldenMaxThickWindows = 4;
inline constexpr int kGoldenNeighbourTolerance = 32;
inline constexpr double kGoldenMaxDisplacedFraction = 0.002;
inline constexpr double kGoldenMaxClippedMean = 1.5;

/// Compares two RGB images of `height` x `width` pixels.
inline GoldenDifference golden_difference(const std::uint8_t* actual, const std::uint8_t* expected,
                                          int height, int width) {
  const auto index = [width](int row, int col) {
    return static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
           static_cast<std::size_t>(col);
  };
  const auto distance = [](const std::uint8_t* a, std::size_t p, const std::uint8_t* b,
                           std::size_t q) {
    int worst = 0;
    for (std::size_t c = 0; c < 3; ++c)
      worst = std::max(worst, std::abs(a[p * 3 + c] - b[q * 3 + c]));
    return worst;
  };
  const std::size_t pixels = index(height, 0);
  GoldenDifference result;
  result.diff_rgb.resize(pixels * 3);
  std::vector<char> off(pixels);
  double clipped_total = 0.0;
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t c = 0; c < 3; ++c) {
      const int d = std::abs(actual[p * 3 + c] - expected[p * 3 + c]);
      clipped_total += std::min(d, kGoldenOffBy);
    }
    const int worst = distance(actual, p, expected, p);
    off[p] = worst > kGoldenOffBy ? 1 : 0;
    const auto grey = static_cast<std::uint8_t>(std::min(255, worst * 8));
    for (std::size_t c = 0; c < 3; ++c) result.diff_rgb[p * 3 + c] = grey;
  }
  result.clipped_mean = clipped_total / static_cast<double>(pixels * 3);
  for (int row = 0; row + 1 < height; ++row) {
    for (int col = 0; col + 1 < width; ++col) {
      const std::size_t window[4] = {index(row, col), index(row, col + 1), index(row + 1, col),
                                     index(row + 1, col + 1)};
      if (!(off[window[0]] && off[window[1]] && off[window[2]] && off[window[3]])) continue;
      ++result.thick_windows;
      for (std::size_t p : window) {
        result.diff_rgb[p * 3] = 255;
        result.diff_rgb[p * 3 + 1] = 0;
      }
    }
  }
  // Whether pixel (row, col) of `a` has a match in `b`'s 3 x 3 neighbourhood of the same place.
  const auto found_near = [&](const std::uint8_t* a, const std::uint8_t* b, int row, int col) {
    for (int r = std::max(0, row - 1); r <= std::min(height - 1, row + 1); ++r) {
      for (int c = std::max(0, col - 1); c <= std::min(width - 1, col + 1); ++c) {
        if (distance(a, index(row, col), b, index(r, c)) <= kGoldenNeighbourTolerance) return true;
      }
    }
    return false;
  };
  for (int row = 0; row < height; ++row) {
    for (int col = 0; col < width; ++col) {
      const std::size_t p = index(row, col);
      if (!off[p]) continue;  // within 8 of the same place: found
      if (found_near(actual, expected, row, col) && found_near(expected, actual, row, col))
        continue;
      ++result.displaced_pixels;
      result.diff_rgb[p * 3 + 1] = 0;
      result.diff_rgb[p * 3 + 2] = 255;
    }
  }
  return result;
}

/// Whether `difference` (of two images of `height` x `width` pixels) is within the limits above.
inline bool within_golden_limits(const GoldenDifference& difference, int height, int width) {
  const double pixels = static_cast<double>(height) * static_cast<double>(width);
  return difference.thick_windows <= kGoldenMaxThickWindows &&
         difference.displaced_pixels <= static_cast<int>(kGoldenMaxDisplacedFraction * pixels) &&
         difference.clipped_mean <= kGoldenMaxClippedMean;
}

inline ::testing::AssertionResult matches_golden(const std::string& name, const std::uint8_t* rgb,
                                                 int height, int width) {
  const std::string golden = std::string(PIXELGYM_SOURCE_DIR) + "/tests/golden/" + name + ".png";
  const std::string out_dir = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/golden";
  std::filesystem::create_directories(out_dir);
  const char* update = std::getenv("PIXELGYM_UPDATE_GOLDENS");
  if (update != nullptr && std::string(update) == "1") {
    render::write_png(golden, {rgb, height, width, 3});
    return ::testing::AssertionSuccess() << "updated " << golden;
  }
  if (!std::filesystem::exists(golden)) {
    render::write_png(out_dir + "/" + name + ".actual.png", {rgb, height, width, 3});
    return ::testing::AssertionFailure()
           << "no golden " << golden << "; the frame is in " << out_dir
           << " (PIXELGYM_UPDATE_GOLDENS=1 writes goldens)";
  }
  const render::Image expected = render::read_png(golden);
  if (expected.height != height || expected.width != width || expected.channels != 3) {
    return ::testing::AssertionFailure()
           << golden << " is " << expected.width << "x" << expected.height << "x"
           << expected.channels << ", the frame " << width << "x" << height << "x3";
  }
  const GoldenDifference difference = golden_difference(rgb, expected.pixels.data(), height, width);
  const std::size_t pixels = static_cast<std::size_t>(height) * static_cast<std::size_t>(width);
  const auto max_displaced =
      static_cast<int>(kGoldenMaxDisplacedFraction * static_cast<double>(pixels));
  if (within_golden_limits(difference, height, width)) return ::testing::AssertionSuccess();
  render::write_png(out_dir + "/" + name + ".actual.png", {rgb, height, width, 3});
  render::write_png(out_dir + "/" + name + ".diff.png",
                    {difference.diff_rgb.data(), height, width, 3});
  return ::testing::AssertionFailure()
         << name << ": " << difference.thick_windows << " 2x2 windows of pixels off by more than "
         << kGoldenOffBy << " (limit " << kGoldenMaxThickWindows << "), "
         << difference.displaced_pixels << " pixels with no match within "
         << kGoldenNeighbourTolerance << " in the other image's 3x3 neighbourhood (limit "
         << max_displaced << "), mean difference (clipped at " << kGoldenOffBy << ") "
         << difference.clipped_mean << " (limit " << kGoldenMaxClippedMean
         << "); actual and diff images in " << out_dir << " (see tests/golden.h)";
}

}  // namespace pixelgym::testing
