// SingleProcessCommunicator: the collectives of a world of one rank.
#include "pixelgym/trainer/communicator.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

TEST(SingleProcessCommunicatorTest, IsRankZeroOfOneAndItsCollectivesKeepItsOwnValues) {
  SingleProcessCommunicator communicator;
  EXPECT_EQ(communicator.rank(), 0);
  EXPECT_EQ(communicator.world_size(), 1);
  std::vector<float> floats{1.5f, -2.0f};
  communicator.all_reduce_sum(floats.data(), floats.size(), "floats");
  EXPECT_EQ(floats, (std::vector<float>{1.5f, -2.0f}));
  std::vector<double> doubles{3.25};
  communicator.all_reduce_sum(doubles.data(), doubles.size(), "doubles");
  EXPECT_EQ(doubles, std::vector<double>{3.25});
  communicator.broadcast(floats.data(), floats.size(), "broadcast");
  EXPECT_EQ(floats, (std::vector<float>{1.5f, -2.0f}));
  EXPECT_EQ(communicator.all_gather(42, "digest"), std::vector<std::uint64_t>{42});
  EXPECT_EQ(communicator.gather_bytes("abc", "bytes"), std::vector<std::string>{"abc"});
  EXPECT_EQ(communicator.scatter_bytes({"mine"}, "start"), "mine");
  EXPECT_THROW(communicator.scatter_bytes({"a", "b"}, "start"), std::invalid_argument);
  // A merge of statistics across one rank is the rank's own.
  wrappers::RunningStatistics before = wrappers::RunningStatistics::initial(1);
  wrappers::RunningStatistics mine = before;
  mine.mean = {2.0};
  mine.var = {0.5};
  mine.count = before.count + 4.0;
  wrappers::RunningStatistics merged = mine;
  merge_statistics_across_ranks(communicator, before, merged, "statistics");
  EXPECT_NEAR(merged.mean[0], mine.mean[0], 1e-12);
  EXPECT_NEAR(merged.var[0], mine.var[0], 1e-12);
  EXPECT_DOUBLE_EQ(merged.count, mine.count);
  communicator.finish();
}

TEST(SingleProcessCommunicatorTest, CountsARolloutDoneOnceItIsMarked) {
  SingleProcessCommunicator communicator;
  EXPECT_EQ(communicator.rollouts_done(0), 0);
  EXPECT_EQ(communicator.mark_rollout_done(0), 1);
  EXPECT_EQ(communicator.rollouts_done(0), 1);
  EXPECT_EQ(communicator.rollouts_done(1), 0);
}

}  // namespace
}  // namespace pixelgym::trainer
