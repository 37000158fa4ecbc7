// Refusing settings that need more memory than is available: the message names the total, the
// memory available and where that figure comes from, and the member that takes the most.
#include "pixelgym/trainer/memory_budget.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

const std::vector<MemoryUse> kUses = {
    {"replay_capacity", 1e6, "the replay buffer", 5e9},
    {"batch_size", 256, "the batches", 2e9},
};

TEST(MemoryBudgetTest, SettingsThatFitPass) {
  EXPECT_NO_THROW(require_memory("drqv2", kUses, 7e9, "test"));
  EXPECT_NO_THROW(require_memory("drqv2", kUses, 8e9, "test"));
  // Unknown availability refuses nothing.
  EXPECT_NO_THROW(require_memory("drqv2", kUses, -1, "unknown"));
}

TEST(MemoryBudgetTest, TooMuchIsRefusedNamingTheLargestMemberTheEstimateAndTheAvailable) {
  try {
    require_memory("drqv2", kUses, 6.9e9, "MemAvailable in /proc/meminfo");
    FAIL() << "7 GB fitted in 6.9 GB";
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()),
              "drqv2: these settings need about 6.5 GiB of memory, but 6.4 GiB is available "
              "(MemAvailable in /proc/meminfo); the most is replay_capacity 1000000: about "
              "4.7 GiB for the replay buffer. Lower replay_capacity. The estimate: "
              "replay_capacity 1000000, 4.7 GiB (the replay buffer); batch_size 256, 1.9 GiB "
              "(the batches).");
  }
}

}  // namespace
}  // namespace pixelgym::trainer
