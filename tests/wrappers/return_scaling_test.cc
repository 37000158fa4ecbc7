// ReturnScaling: each env's discounted return, merged as one batch per step into the running
// statistics; rewards divided by the standard deviation; returns restarting after an episode's
// end and at a reset; skipped rows neither grow nor merge; bad settings refused by name.
#include "pixelgym/wrappers/return_scaling.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

namespace pixelgym::wrappers {
namespace {

// The statistics after merging `batches` (each a batch of returns) from the initial ones.
RunningStatistics merged(const std::vector<std::vector<double>>& batches) {
  RunningStatistics statistics = RunningStatistics::initial(1);
  for (const std::vector<double>& batch : batches) {
    statistics.update_batch(batch.size(),
                            [&batch](std::size_t row, std::size_t) { return batch[row]; });
  }
  return statistics;
}

TEST(ReturnScalingTest, DiscountsMergesAndScalesEachStep) {
  constexpr double kEpsilon = 1e-8;
  ReturnScaling scaling(2, 0.5, kEpsilon, "test");
  std::vector<double> out(2);

  // Step 1: env 1's episode ends.
  const double rewards1[] = {1.0, 2.0};
  const std::uint8_t ended1[] = {0, 1};
  scaling.scale(rewards1, ended1, nullptr, out.data());
  RunningStatistics expected = merged({{1.0, 2.0}});
  EXPECT_EQ(scaling.statistics().var[0], expected.var[0]);
  EXPECT_DOUBLE_EQ(out[0], 1.0 / std::sqrt(expected.var[0] + kEpsilon));
  EXPECT_DOUBLE_EQ(out[1], 2.0 / std::sqrt(expected.var[0] + kEpsilon));
  EXPECT_EQ(scaling.discounted_returns(), (std::vector<double>{1.0, 0.0}));

  // Step 2: env 1 skipped (NextStep's reset row): only env 0's 0.5 * 1 + 4 merges.
  const double rewards2[] = {4.0, 8.0};
  const std::uint8_t ended2[] = {0, 0};
  const std::uint8_t skipped2[] = {0, 1};
  scaling.scale(rewards2, ended2, skipped2, out.data());
  expected = merged({{1.0, 2.0}, {4.5}});
  EXPECT_EQ(scaling.statistics().var[0], expected.var[0]);
  EXPECT_EQ(scaling.statistics().count, expected.count);
  EXPECT_DOUBLE_EQ(out[1], 8.0 / std::sqrt(expected.var[0] + kEpsilon));
  EXPECT_EQ(scaling.discounted_returns(), (std::vector<double>{4.5, 0.0}));

  // A reset of env 0 alone; frozen statistics still scale.
  const bool mask[] = {true, false};
  scaling.reset(mask);
  scaling.set_update_statistics(false);
  const double rewards3[] = {1.0, 1.0};
  scaling.scale(rewards3, ended2, nullptr, out.data());
  EXPECT_EQ(scaling.discounted_returns(), (std::vector<double>{1.0, 1.0}));
  EXPECT_EQ(scaling.statistics().count, expected.count);
  EXPECT_DOUBLE_EQ(out[0], 1.0 / std::sqrt(expected.var[0] + kEpsilon));
}

TEST(ReturnScalingTest, RefusesBadSettingsNamingItsOwner) {
  try {
    ReturnScaling(2, 1.5, 1e-8, "Trainer");
    ADD_FAILURE() << "gamma 1.5 accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "Trainer: gamma must be in [0, 1], got 1.5");
  }
  EXPECT_THROW(ReturnScaling(2, 0.9, 0.0, "x"), std::invalid_argument);
  ReturnScaling scaling(2, 0.9, 1e-8, "Trainer");
  try {
    scaling.set_discounted_returns({1.0});
    ADD_FAILURE() << "one return for two envs accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "Trainer: 2 discounted returns expected (num_envs), got 1");
  }
  EXPECT_THROW(scaling.set_discounted_returns({1.0, std::numeric_limits<double>::quiet_NaN()}),
               std::invalid_argument);
  EXPECT_EQ(scaling.discounted_returns(), (std::vector<double>{0.0, 0.0}));  // unchanged
  EXPECT_THROW(scaling.set_statistics(RunningStatistics::initial(2)), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::wrappers
