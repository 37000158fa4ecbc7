// compute_gae against advantages worked out by hand (gamma 0.9, lambda 0.8: gamma lambda = 0.72),
// including episode ends inside a rollout, truncation bootstrapping and the step-major layout of
// several envs.
#include "examples/trainer/ppo/gae.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <stdexcept>
#include <vector>

namespace pixelgym::ppo {
namespace {

constexpr double kGamma = 0.9;
constexpr double kLambda = 0.8;
constexpr float kTolerance = 1e-5f;

// The arrays of a rollout, step-major, with GaeInputs viewing them.
struct Rollout {
  std::int64_t steps;
  std::int64_t envs;
  std::vector<float> rewards, values, final_values, last_values;
  std::vector<std::uint8_t> terminated, truncated;

  GaeInputs inputs() const {
    GaeInputs in;
    in.num_steps = steps;
    in.num_envs = envs;
    in.rewards = rewards.data();
    in.values = values.data();
    in.terminated = terminated.data();
    in.truncated = truncated.data();
    in.final_values = final_values.data();
    in.last_values = last_values.data();
    return in;
  }
};

void expect_near(const std::vector<float>& actual, const std::vector<float>& expected) {
  ASSERT_EQ(actual.size(), expected.size());
  for (std::size_t i = 0; i < actual.size(); ++i) {
    EXPECT_NEAR(actual[i], expected[i], kTolerance) << "entry " << i;
  }
}

TEST(Gae, NoEpisodeEndBootstrapsFromLastValues) {
  // delta2 = 3 + 0.9 * 2 - 1.5 = 3.3; delta1 = 2 + 0.9 * 1.5 - 1 = 2.35;
  // delta0 = 1 + 0.9 * 1 - 0.5 = 1.4. A2 = 3.3, A1 = 2.35 + 0.72 * 3.3 = 4.726,
  // A0 = 1.4 + 0.72 * 4.726 = 4.80272.
  const Rollout r{3, 1, {1, 2, 3}, {0.5f, 1, 1.5f}, {100, 100, 100}, {2}, {0, 0, 0}, {0, 0, 0}};
  const GaeOutputs out = compute_gae(r.inputs(), kGamma, kLambda);
  expect_near(out.advantages, {4.80272f, 4.726f, 3.3f});
  expect_near(out.returns, {5.30272f, 5.726f, 4.8f});
}

TEST(Gae, TerminationAndTruncationInsideTheRolloutOfTwoEnvs) {
  // Env 0 terminates at t = 1: no bootstrap, and A0 does not reach past it.
  //   A2 = 3.3 (as above); A1 = 2 - 1 = 1; A0 = 1.4 + 0.72 * 1 = 2.12.
  // Env 1 is truncated at t = 1 with V(final obs) = 4:
  //   A2 = 0 + 0.9 * 5 - 3 = 1.5; A1 = 1 + 0.9 * 4 - 2 = 2.6; A0 = 0 + 0.9 * 2 - 1 + 0.72 * 2.6
  //   = 2.672.
  // Step-major: entry t * 2 + n. Env 0's final value (100) must be ignored: it terminated.
  const Rollout r{3,
                  2,
                  /*rewards=*/{1, 0, 2, 1, 3, 0},
                  /*values=*/{0.5f, 1, 1, 2, 1.5f, 3},
                  /*final_values=*/{0, 0, 100, 4, 0, 0},
                  /*last_values=*/{2, 5},
                  /*terminated=*/{0, 0, 1, 0, 0, 0},
                  /*truncated=*/{0, 0, 0, 1, 0, 0}};
  const GaeOutputs out = compute_gae(r.inputs(), kGamma, kLambda);
  expect_near(out.advantages, {2.12f, 2.672f, 1.0f, 2.6f, 3.3f, 1.5f});
  expect_near(out.returns, {2.62f, 3.672f, 2.0f, 4.6f, 4.8f, 4.5f});
}

TEST(Gae, TruncationAtTheLastStepUsesTheFinalValueNotLastValues) {
  // t = 1 truncated with V(final obs) = 4; last_values (the next episode's first value, 50) must
  // not be used. A1 = 1 + 0.9 * 4 - 2 = 2.6; A0 = 0 + 0.9 * 2 - 1 + 0.72 * 2.6 = 2.672.
  const Rollout r{2, 1, {0, 1}, {1, 2}, {0, 4}, {50}, {0, 0}, {0, 1}};
  const GaeOutputs out = compute_gae(r.inputs(), kGamma, kLambda);
  expect_near(out.advantages, {2.672f, 2.6f});
}

TEST(Gae, TerminatedAndTruncatedTogetherCountAsTerminated) {
  // A0 = 1 + 0 - 2 = -1: no bootstrap from the final value 4.
  const Rollout r{1, 1, {1}, {2}, {4}, {50}, {1}, {1}};
  const GaeOutputs out = compute_gae(r.inputs(), kGamma, kLambda);
  expect_near(out.advantages, {-1.0f});
  expect_near(out.returns, {1.0f});
}

TEST(Gae, LambdaOneGivesDiscountedReturnsToTheEpisodeEnd) {
  // gamma 0.5, lambda 1: returns are the discounted sums of rewards, whatever the values:
  // episode 1 = steps 0..1 (terminated), episode 2 = steps 2..3, bootstrapped with V(s_4) = 8.
  // G1 = 2, G0 = 1 + 0.5 * 2 = 2; G3 = 4 + 0.5 * 8 = 8, G2 = 3 + 0.5 * 8 = 7.
  const Rollout r{4,           1, {1, 2, 3, 4}, {9, -3, 0.25f, 7}, {0, 0, 0, 0}, {8}, {0, 1, 0, 0},
                  {0, 0, 0, 0}};
  const GaeOutputs out = compute_gae(r.inputs(), 0.5, 1.0);
  expect_near(out.returns, {2, 2, 7, 8});
}

TEST(Gae, RejectsBadInputs) {
  const Rollout r{1, 1, {1}, {2}, {0}, {0}, {0}, {0}};
  GaeInputs in = r.inputs();
  EXPECT_THROW(compute_gae(in, 1.5, 0.9), std::invalid_argument);
  EXPECT_THROW(compute_gae(in, 0.9, -0.1), std::invalid_argument);
  in.final_values = nullptr;
  EXPECT_THROW(compute_gae(in, 0.9, 0.9), std::invalid_argument);
  in = r.inputs();
  in.num_steps = 0;
  EXPECT_THROW(compute_gae(in, 0.9, 0.9), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::ppo
