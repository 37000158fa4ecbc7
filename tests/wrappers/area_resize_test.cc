// AreaResize against cv::resize's INTER_AREA over many size pairs and channel counts.
#include "pixelgym/wrappers/area_resize.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace pixelgym::wrappers {
namespace {

struct Comparison {
  int max_difference = 0;
  long differing = 0;  // elements
  long elements = 0;
};

Comparison compare_with_opencv(int source_height, int source_width, int height, int width,
                               int channels, unsigned seed, bool allow_avx2) {
  cv::Mat source(source_height, source_width, CV_8UC(channels));
  cv::theRNG().state = seed;
  cv::randu(source, 0, 256);
  cv::Mat expected;
  cv::resize(source, expected, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  std::vector<std::uint8_t> actual(static_cast<std::size_t>(height * width * channels));
  AreaResize resize(source_height, source_width, height, width, channels, allow_avx2);
  resize(source.data, actual.data());
  Comparison result;
  result.elements = static_cast<long>(actual.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    const int difference = std::abs(actual[i] - expected.data[i]);
    result.max_difference = std::max(result.max_difference, difference);
    result.differing += difference != 0;
  }
  return result;
}

// Both kernels: the portable one, and AVX2 + FMA where this CPU has them.
class AreaResizeKernelTest : public ::testing::TestWithParam<bool> {};

TEST_P(AreaResizeKernelTest, MatchesOpenCvWithinOneLevelOnRareElements) {
  const bool allow_avx2 = GetParam();
  if (allow_avx2 && !AreaResize(2, 2, 1, 1, 1).uses_avx2()) {
    GTEST_SKIP() << "this CPU has no AVX2 + FMA: the portable kernel is the one that runs";
  }
  long differing = 0;
  long elements = 0;
  const std::vector<std::vector<int>> sizes = {
      {84, 84, 64, 64}, {84, 84, 63, 37}, {84, 84, 17, 80},  {84, 84, 83, 1},
      {84, 84, 1, 84},  {84, 84, 1, 1},   {96, 128, 84, 84}, {256, 256, 84, 84},
      {48, 64, 20, 28}, {7, 5, 3, 2},     {84, 84, 84, 50},  {100, 3, 99, 3}};
  for (const auto& size : sizes) {
    for (int channels : {1, 3, 4}) {
      const Comparison c = compare_with_opencv(size[0], size[1], size[2], size[3], channels,
                                               7u + channels, allow_avx2);
      EXPECT_LE(c.max_difference, 1)
          << size[0] << "x" << size[1] << " -> " << size[2] << "x" << size[3] << " x" << channels;
      differing += c.differing;
      elements += c.elements;
    }
  }
  std::printf("AreaResize (%s) vs cv::resize INTER_AREA: %ld of %ld elements one level apart\n",
              allow_avx2 ? "AVX2" : "portable", differing, elements);
  EXPECT_LT(differing, elements / 100);  // rare: float sums in another order
}

INSTANTIATE_TEST_SUITE_P(Kernels, AreaResizeKernelTest, ::testing::Values(false, true),
                         [](const ::testing::TestParamInfo<bool>& kernel) {
                           return kernel.param ? "Avx2" : "Portable";
                         });

TEST(AreaResizeTest, KeepsAFlatImageFlat) {
  cv::Mat source(84, 84, CV_8UC3, cv::Scalar(10, 128, 255));
  std::vector<std::uint8_t> out(64 * 64 * 3);
  AreaResize resize(84, 84, 64, 64, 3);
  resize(source.data, out.data());
  for (std::size_t i = 0; i < out.size(); i += 3) {
    ASSERT_EQ(out[i], 10);
    ASSERT_EQ(out[i + 1], 128);
    ASSERT_EQ(out[i + 2], 255);
  }
}

TEST(AreaResizeTest, RefusesAnythingButAShrink) {
  EXPECT_THROW(AreaResize(10, 10, 11, 10, 3), std::invalid_argument);
  EXPECT_THROW(AreaResize(10, 10, 0, 10, 3), std::invalid_argument);
  EXPECT_THROW(AreaResize(10, 10, 5, 5, 0), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::wrappers
