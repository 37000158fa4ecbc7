// GoogleTest adapter for testing/snapshot.h: link pixelgym::testing_gtest (which brings
// pixelgym::testing) and GoogleTest.
//
//   TEST(MyEnvTest, FirstFrameMatchesItsGolden) {
//     auto env = pixelgym::make("CartPoleSwingup-v0");
//     env->reset(0);
//     EXPECT_MATCHES_GOLDEN(env->render(), "tests/golden/cartpole.png");
//   }
//
// The failure message holds the figures against their limits and the paths of the frame and the
// diff image; PIXELGYM_UPDATE_GOLDENS=1 (re)writes the goldens instead, and says so on stdout.
#pragma once

#include <gtest/gtest.h>

#include <iostream>
#include <string>

#include "pixelgym/testing/snapshot.h"

namespace pixelgym::testing {

/// A SnapshotResult as a GoogleTest assertion result (its message either way); a rewritten
/// golden is reported on stdout, as GoogleTest does not print a success's message.
inline ::testing::AssertionResult to_assertion_result(const SnapshotResult& result) {
  if (result.status == SnapshotResult::Status::kUpdated) {
    std::cout << "[ UPDATED  ] " << result.message() << std::endl;
  }
  if (result.matched()) return ::testing::AssertionSuccess() << result.message();
  return ::testing::AssertionFailure() << result.message();
}

/// For EXPECT_PRED_FORMAT2: compare_to_golden(frame, golden_path) with the default tolerance.
template <typename Frame>
::testing::AssertionResult matches_golden_format(const char* frame_text, const char* path_text,
                                                 const Frame& frame,
                                                 const std::string& golden_path) {
  const ::testing::AssertionResult result =
      to_assertion_result(compare_to_golden(frame, golden_path));
  if (result) return result;
  return ::testing::AssertionFailure()
         << frame_text << " does not match the golden " << path_text << ":\n"
         << result.message();
}

/// For EXPECT_PRED_FORMAT3: compare_to_golden(frame, golden_path, tolerance).
template <typename Frame>
::testing::AssertionResult matches_golden_within_format(const char* frame_text,
                                                        const char* path_text, const char*,
                                                        const Frame& frame,
                                                        const std::string& golden_path,
                                                        const SnapshotTolerance& tolerance) {
  const ::testing::AssertionResult result =
      to_assertion_result(compare_to_golden(frame, golden_path, tolerance));
  if (result) return result;
  return ::testing::AssertionFailure()
         << frame_text << " does not match the golden " << path_text << ":\n"
         << result.message();
}

/// For EXPECT_PRED_FORMAT2: compare_segmentation_to_golden(labels, golden_path).
template <typename Labels>
::testing::AssertionResult segmentation_matches_golden_format(const char* labels_text,
                                                              const char* path_text,
                                                              const Labels& labels,
                                                              const std::string& golden_path) {
  const ::testing::AssertionResult result =
      to_assertion_result(compare_segmentation_to_golden(labels, golden_path));
  if (result) return result;
  return ::testing::AssertionFailure()
         << labels_text << " does not match the golden " << path_text << ":\n"
         << result.message();
}

}  // namespace pixelgym::testing

/// frame: an (H, W, 3) uint8 pixelgym::Array or a render::ImageView; golden_path: a PNG path.
#define EXPECT_MATCHES_GOLDEN(frame, golden_path) \
  EXPECT_PRED_FORMAT2(::pixelgym::testing::matches_golden_format, frame, golden_path)
/// As EXPECT_MATCHES_GOLDEN, ending the test on a failure.
#define ASSERT_MATCHES_GOLDEN(frame, golden_path) \
  ASSERT_PRED_FORMAT2(::pixelgym::testing::matches_golden_format, frame, golden_path)
/// With a pixelgym::testing::SnapshotTolerance of your own.
#define EXPECT_MATCHES_GOLDEN_WITHIN(frame, golden_path, tolerance)                          \
  EXPECT_PRED_FORMAT3(::pixelgym::testing::matches_golden_within_format, frame, golden_path, \
                      tolerance)
/// As EXPECT_MATCHES_GOLDEN_WITHIN, ending the test on a failure.
#define ASSERT_MATCHES_GOLDEN_WITHIN(frame, golden_path, tolerance)                          \
  ASSERT_PRED_FORMAT3(::pixelgym::testing::matches_golden_within_format, frame, golden_path, \
                      tolerance)
/// labels: an (H, W) or (H, W, 1) int32 pixelgym::Array of segmentation labels (default
/// SegmentationTolerance).
#define EXPECT_SEGMENTATION_MATCHES_GOLDEN(labels, golden_path) \
  EXPECT_PRED_FORMAT2(::pixelgym::testing::segmentation_matches_golden_format, labels, golden_path)
/// As EXPECT_SEGMENTATION_MATCHES_GOLDEN, ending the test on a failure.
#define ASSERT_SEGMENTATION_MATCHES_GOLDEN(labels, golden_path) \
  ASSERT_PRED_FORMAT2(::pixelgym::testing::segmentation_matches_golden_format, labels, golden_path)
