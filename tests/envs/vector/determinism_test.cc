// Same seeds and actions give byte-identical batches — pixels included — from SyncVectorEnv,
// from AsyncVectorEnv on 1, 2 and 4 threads, and from the envs stepped one by one with Env
// (with NextStep's autoreset done by hand), for 1, 3 and 8 envs. Episodes are cut at 4 steps so
// that autoresets happen inside the 9 steps compared; renders are small to keep this quick.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "envs/registry.h"
#include "envs/vector/batch_space.h"
#include "envs/vector/make_vec.h"
#include "wrappers/wrapper_spec.h"

namespace pixelgym::vector {
namespace {

constexpr int kSteps = 9;
constexpr std::uint64_t kSeed = 123;

struct Case {
  std::string name;
  std::string id;
  Params kwargs;
  std::vector<std::string> wrappers;
};

// One step of one env.
struct EnvStep {
  Value obs;
  double reward = 0.0;
  bool terminated = false;
  bool truncated = false;
};

// trajectory[t][i]: env i after step t (t = 0: the reset).
using Trajectory = std::vector<std::vector<EnvStep>>;

std::vector<Value> batched_actions(const Space& action_space) {
  Rng rng(99);
  std::vector<Value> actions;
  for (int t = 0; t < kSteps; ++t) actions.push_back(action_space.sample(rng));
  return actions;
}

Trajectory one_by_one(const Case& c, int num_envs, const std::vector<Value>& actions) {
  Trajectory trajectory(kSteps + 1);
  for (int i = 0; i < num_envs; ++i) {
    std::unique_ptr<Env> env = wrappers::apply_wrappers(make(c.id, c.kwargs), c.wrappers);
    trajectory[0].push_back({env->reset(kSeed + static_cast<std::uint64_t>(i)).obs.clone()});
    bool done = false;
    for (int t = 0; t < kSteps; ++t) {
      EnvStep step;
      if (done) {
        step.obs = env->reset().obs.clone();
        done = false;
      } else {
        const StepResult result = env->step(batch_slot(actions[static_cast<std::size_t>(t)], i));
        step = {result.obs.clone(), result.reward, result.terminated, result.truncated};
        done = result.terminated || result.truncated;
      }
      trajectory[static_cast<std::size_t>(t) + 1].push_back(step);
    }
  }
  return trajectory;
}

void expect_same(const Trajectory& expected, const VectorEnv& env, const Value& obs,
                 const VectorStepResult* step, int t, const std::string& runner) {
  for (int i = 0; i < env.num_envs(); ++i) {
    const EnvStep& want = expected[static_cast<std::size_t>(t)][static_cast<std::size_t>(i)];
    EXPECT_TRUE(batch_slot(obs, i).equals(want.obs)) << runner << " step " << t << " env " << i;
    if (step == nullptr) continue;
    EXPECT_EQ(step->rewards.data<double>()[i], want.reward) << runner << " step " << t;
    EXPECT_EQ(step->terminated.data<bool>()[i], want.terminated) << runner << " step " << t;
    EXPECT_EQ(step->truncated.data<bool>()[i], want.truncated) << runner << " step " << t;
  }
}

class VectorDeterminismTest : public ::testing::TestWithParam<Case> {};

TEST_P(VectorDeterminismTest, SyncAndPoolsEqualSingleEnvsByteForByte) {
  const Case& c = GetParam();
  for (const int num_envs : {1, 3, 8}) {
    std::vector<Value> actions;
    {
      const auto probe = make_vec(c.id, num_envs, c.kwargs, c.wrappers);
      actions = batched_actions(probe->action_space());
    }
    const Trajectory expected = one_by_one(c, num_envs, actions);
    bool ended = false;
    for (const auto& row : expected) {
      for (const EnvStep& step : row) ended = ended || step.terminated || step.truncated;
    }
    EXPECT_TRUE(ended) << "no episode ended: the autoreset is not exercised";
    for (const int threads : {0, 1, 2, 4}) {
      const std::string runner =
          std::to_string(num_envs) + " envs, " +
          (threads == 0 ? std::string("sync") : std::to_string(threads) + " threads");
      const VectorOptions options{threads == 0 ? VectorMode::kSync : VectorMode::kAsync, threads,
                                  AutoresetMode::kNextStep};
      const auto env = make_vec(c.id, num_envs, c.kwargs, c.wrappers, options);
      expect_same(expected, *env, env->reset(kSeed).obs, nullptr, 0, runner);
      for (int t = 0; t < kSteps; ++t) {
        const VectorStepResult& step = env->step(actions[static_cast<std::size_t>(t)]);
        expect_same(expected, *env, step.obs, &step, t + 1, runner);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(
    Envs, VectorDeterminismTest,
    ::testing::Values(Case{"CartPoleSwingup",
                           "CartPoleSwingup-v0",
                           {{"width", 24}, {"height", 24}, {"max_episode_steps", 4}},
                           {}},
                      Case{"ArmReach",
                           "ArmReach-v0",
                           {{"width", 24}, {"height", 24}, {"max_episode_steps", 4}},
                           {}},
                      Case{"CartPoleSwingupWrapped",
                           "CartPoleSwingup-v0",
                           {{"width", 32}, {"height", 32}, {"max_episode_steps", 4}},
                           {"resize=20x20", "grayscale", "frame_stack=3"}}),
    [](const ::testing::TestParamInfo<Case>& param_info) { return param_info.param.name; });

}  // namespace
}  // namespace pixelgym::vector
