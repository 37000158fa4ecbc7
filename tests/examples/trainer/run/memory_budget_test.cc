// Refusing settings that need more memory than is available: the message names the total, the
// memory available and where that figure comes from, and the member that takes the most.
#include "examples/trainer/run/memory_budget.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

using ::testing::HasSubstr;

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
              "drqv2: these settings need about 7.0 GB of memory, but 6.9 GB is available "
              "(MemAvailable in /proc/meminfo); the most is replay_capacity 1000000: about "
              "5.0 GB for the replay buffer. Lower replay_capacity. The estimate: "
              "replay_capacity 1000000, 5.0 GB (the replay buffer); batch_size 256, 2.0 GB "
              "(the batches).");
  }
}

TEST(MemoryBudgetTest, BytesAreWrittenInTheirLargestUnit) {
  EXPECT_EQ(format_bytes(640), "640 bytes");
  EXPECT_EQ(format_bytes(1500), "1.5 kB");
  EXPECT_EQ(format_bytes(2.34e9), "2.3 GB");
  EXPECT_EQ(format_bytes(1.2e13), "12.0 TB");
  EXPECT_THAT(format_bytes(1e30), HasSubstr("EB"));
}

TEST(MemoryBudgetTest, TheAvailableMemoryIsReadAndSaysWhereFrom) {
  std::string source;
  const double available = available_memory_bytes(&source);
  EXPECT_GT(available, 0.0);
  EXPECT_FALSE(source.empty());
}

}  // namespace
}  // namespace pixelgym::trainer
