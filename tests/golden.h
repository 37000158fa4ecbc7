// pixelgym's own golden tests: the public snapshot helper (testing/snapshot.h, where the criterion
// and its measurements are documented) against tests/golden/<name>.png, with the actual and diff
// images of a failure under build/test_output/golden/. To regenerate every golden:
// PIXELGYM_UPDATE_GOLDENS=1 make test (or `make goldens`), then look at each PNG before committing.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "pixelgym/envs/array.h"
#include "pixelgym/testing/gtest.h"
#include "pixelgym/testing/snapshot.h"

namespace pixelgym::testing {

inline std::string golden_path(const std::string& name) {
  return std::string(PIXELGYM_SOURCE_DIR) + "/tests/golden/" + name + ".png";
}

inline SnapshotOptions golden_options() {
  SnapshotOptions options;
  options.output_dir = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/golden";
  return options;
}

/// `frame` (an (H, W, 3) uint8 Array) against tests/golden/<name>.png, default tolerance.
inline ::testing::AssertionResult matches_golden(const std::string& name, const Array& frame) {
  return to_assertion_result(compare_to_golden(frame, golden_path(name), {}, golden_options()));
}

}  // namespace pixelgym::testing
