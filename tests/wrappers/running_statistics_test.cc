// RunningStatistics::update_batch: a batch of one row is `update` bit for bit; a batch of n rows
// is n updates up to rounding, and the pooled mean and variance of the samples with the prior.
#include "pixelgym/wrappers/running_statistics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstddef>
#include <vector>

#include "pixelgym/envs/rng.h"

namespace pixelgym::wrappers {
namespace {

// rows x 3 samples, element i around 2 i - 1 with a spread of i + 1.
std::vector<std::vector<double>> samples(std::size_t rows, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<std::vector<double>> out(rows, std::vector<double>(3));
  for (auto& row : out) {
    for (std::size_t i = 0; i < 3; ++i) {
      row[i] =
          2.0 * static_cast<double>(i) - 1.0 + static_cast<double>(i + 1) * rng.uniform(-1.0, 1.0);
    }
  }
  return out;
}

TEST(RunningStatisticsTest, ABatchOfOneIsUpdateBitForBit) {
  RunningStatistics one = RunningStatistics::initial(3);
  RunningStatistics batch = RunningStatistics::initial(3);
  // Compared after every update: a rounding difference made early is absorbed by later ones.
  int step = 0;
  for (const auto& row : samples(50, 1)) {
    one.update([&row](std::size_t i) { return row[i]; });
    batch.update_batch(1, [&row](std::size_t /*r*/, std::size_t i) { return row[i]; });
    for (std::size_t i = 0; i < 3; ++i) {
      ASSERT_EQ(one.mean[i], batch.mean[i]) << "update " << step << ", element " << i;
      ASSERT_EQ(one.var[i], batch.var[i]) << "update " << step << ", element " << i;
    }
    ASSERT_EQ(one.count, batch.count);
    ++step;
  }
}

TEST(RunningStatisticsTest, BatchesAgreeWithSingleUpdatesAndTheDirectPooledStatistics) {
  const auto data = samples(60, 2);
  RunningStatistics single = RunningStatistics::initial(3);
  RunningStatistics batched = RunningStatistics::initial(3);
  for (const auto& row : data) single.update([&row](std::size_t i) { return row[i]; });
  // Batches of 1, 2, 3, ... rows (and an empty one, which changes nothing).
  std::size_t first = 0;
  batched.update_batch(0, [](std::size_t, std::size_t) -> double { return 1e9; });
  for (std::size_t size = 1; first < data.size(); ++size) {
    const std::size_t rows = std::min(size, data.size() - first);
    batched.update_batch(rows, [&](std::size_t r, std::size_t i) { return data[first + r][i]; });
    first += rows;
  }
  const double n = static_cast<double>(data.size());
  const double total = RunningStatistics::kInitialCount + n;
  EXPECT_DOUBLE_EQ(batched.count, total);
  for (std::size_t i = 0; i < 3; ++i) {
    // The samples pooled with the prior (mean 0, var 1, count 1e-4).
    double sum = 0.0;
    for (const auto& row : data) sum += row[i];
    const double mean = sum / total;
    double squares = RunningStatistics::kInitialCount * (1.0 + mean * mean);
    for (const auto& row : data) squares += (row[i] - mean) * (row[i] - mean);
    const double var = squares / total;
    EXPECT_NEAR(batched.mean[i], mean, 1e-12 * (1.0 + std::abs(mean))) << i;
    EXPECT_NEAR(batched.var[i], var, 1e-12 * var) << i;
    EXPECT_NEAR(single.mean[i], batched.mean[i], 1e-12 * (1.0 + std::abs(mean))) << i;
    EXPECT_NEAR(single.var[i], batched.var[i], 1e-12 * var) << i;
  }
}

}  // namespace
}  // namespace pixelgym::wrappers
