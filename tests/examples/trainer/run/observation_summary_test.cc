#include "pixelgym/trainer/observation_summary.h"

#include <gtest/gtest.h>

#include <string>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/discrete.h"

namespace pixelgym::trainer {
namespace {

std::string summary(const std::string& id, const Params& kwargs) {
  return observation_summary(*describe(id, kwargs).observation_space);
}

// The line names every part the policy reads: the default pixels+state shows the state beside
// the image, with the kwarg that keeps the image alone.
TEST(ObservationSummaryTest, NamesEveryPartWithItsDtypeAndShape) {
  EXPECT_EQ(
      summary("CartPoleSwingup-v1", {}),
      "pixels uint8 (84, 84, 3) + joint_pos float32 (2,) + joint_vel float32 (2,) (the policy "
      "reads every part; --set obs_mode=rgb for the image alone, obs_mode=state for the "
      "state alone)");
  EXPECT_EQ(summary("CartPoleSwingup-v1", {{"obs_mode", "rgb"}, {"width", 64}}),
            "image uint8 (84, 64, 3)");
  EXPECT_EQ(summary("CartPoleSwingup-v1", {{"obs_mode", "pixels"}}), "pixels uint8 (84, 84, 3)");
  EXPECT_EQ(summary("CartPoleSwingup-v1", {{"obs_mode", "state"}}),
            "joint_pos float32 (2,) + joint_vel float32 (2,)");
  EXPECT_EQ(observation_summary(spaces::Discrete(16)), spaces::Discrete(16).to_string());
}

}  // namespace
}  // namespace pixelgym::trainer
