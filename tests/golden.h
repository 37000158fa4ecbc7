// Compares a rendered frame with a golden PNG under tests/golden/.
//
// Tolerance: mean absolute difference <= 1.0 (over all channels) and at most 1% of pixels with a
// channel off by more than 8. On one machine and one Mesa build frames are identical bytes; the
// tolerance absorbs what another llvmpipe/LLVM build changes (rounding in shading, a few edge
// pixels rasterized differently) without letting a real change through (a moved object, a
// wrong colour or lighting change moves far more than 1% of pixels or the mean).
//
// On failure the actual frame and a diff image (|difference| x 8) are written to
// build/test_output/golden/. To regenerate every golden: PIXELGYM_UPDATE_GOLDENS=1 make test
// (or `make goldens`), then look at each PNG before committing it.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "render/image_io.h"

namespace pixelgym::testing {

inline ::testing::AssertionResult matches_golden(const std::string& name, const std::uint8_t* rgb, int height,
                                                 int width) {
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
    return ::testing::AssertionFailure() << "no golden " << golden << "; the frame is in " << out_dir
                                         << " (PIXELGYM_UPDATE_GOLDENS=1 writes goldens)";
  }
  const render::Image expected = render::read_png(golden);
  if (expected.height != height || expected.width != width || expected.channels != 3) {
    return ::testing::AssertionFailure() << golden << " is " << expected.width << "x" << expected.height << "x"
                                         << expected.channels << ", the frame " << width << "x" << height << "x3";
  }
  const std::size_t pixels = static_cast<std::size_t>(height) * static_cast<std::size_t>(width);
  double total = 0.0;
  std::size_t far_off = 0;
  std::vector<std::uint8_t> diff(pixels * 3);
  for (std::size_t p = 0; p < pixels; ++p) {
    int worst = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const int d = std::abs(int{rgb[p * 3 + c]} - int{expected.pixels[p * 3 + c]});
      total += d;
      worst = std::max(worst, d);
      diff[p * 3 + c] = static_cast<std::uint8_t>(std::min(255, d * 8));
    }
    if (worst > 8) ++far_off;
  }
  const double mean = total / static_cast<double>(pixels * 3);
  const double far_fraction = static_cast<double>(far_off) / static_cast<double>(pixels);
  if (mean <= 1.0 && far_fraction <= 0.01) return ::testing::AssertionSuccess();
  render::write_png(out_dir + "/" + name + ".actual.png", {rgb, height, width, 3});
  render::write_png(out_dir + "/" + name + ".diff.png", {diff.data(), height, width, 3});
  return ::testing::AssertionFailure() << name << ": mean absolute difference " << mean << " (limit 1.0), "
                                       << 100.0 * far_fraction << "% of pixels off by more than 8 (limit 1%); "
                                       << "actual and diff images in " << out_dir;
}

}  // namespace pixelgym::testing
