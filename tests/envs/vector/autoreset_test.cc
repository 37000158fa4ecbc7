// Each autoreset mode pinned step by step around a done, for terminated and for truncated
// episodes, in SyncVectorEnv and in AsyncVectorEnv (2 threads): which observation, reward, flags
// and infos come back. Env 0's episodes last 2 steps, env 1's 3.
#include <gtest/gtest.h>

#include <string>
#include <tuple>

#include "tests/envs/vector/vector_test_util.h"

namespace pixelgym::vector {
namespace {

using testing::make_scripted_vector;
using testing::scripted_actions;
using testing::ScriptedVector;

bool flag(const Array& flags, int i) { return flags.data<bool>()[i]; }
double reward(const VectorStepResult& result, int i) { return result.rewards.data<double>()[i]; }
Array row(const Value& batch, int i) { return batch.array().index(i); }
// Env i's latest observation, as the scripted env recorded it (`back` = 1), or an earlier one.
const Array& recorded(const ScriptedVector& made, int i, std::size_t back = 1) {
  const auto& observations = made.scripted[static_cast<std::size_t>(i)]->observations;
  return observations[observations.size() - back].array();
}
std::size_t actions_seen(const ScriptedVector& made, int i) {
  return made.scripted[static_cast<std::size_t>(i)]->actions.size();
}
bool ended(const VectorStepResult& result, int i, bool truncate) {
  return truncate ? flag(result.truncated, i) && !flag(result.terminated, i)
                  : flag(result.terminated, i) && !flag(result.truncated, i);
}
bool neither(const VectorStepResult& result, int i) {
  return !flag(result.terminated, i) && !flag(result.truncated, i);
}
std::int64_t info_t(const VectorStepResult& result, int i) {
  return result.infos.at("t").array().data<std::int64_t>()[i];
}
bool mask(const Info& infos, const std::string& key, int i) {
  return infos.at("_" + key).array().data<bool>()[i];
}

class AutoresetTest : public ::testing::TestWithParam<std::tuple<int, bool>> {
 protected:
  int threads() const { return std::get<0>(GetParam()); }
  bool truncate() const { return std::get<1>(GetParam()); }
  ScriptedVector make(AutoresetMode mode) const {
    return make_scripted_vector({2, 3}, truncate(), mode, threads());
  }
};

TEST_P(AutoresetTest, ResetSeedsEnvIWithSeedPlusI) {
  ScriptedVector made = make(AutoresetMode::kNextStep);
  const VectorResetResult& reset = made.env->reset(40);
  testing::ScriptedEnv alone0(testing::box(-10, 10, {3}), testing::box(-1, 1, {1}));
  testing::ScriptedEnv alone1(testing::box(-10, 10, {3}), testing::box(-1, 1, {1}));
  EXPECT_TRUE(row(reset.obs, 0).equals(alone0.reset(40).obs.array()));
  EXPECT_TRUE(row(reset.obs, 1).equals(alone1.reset(41).obs.array()));
  EXPECT_TRUE(mask(reset.infos, "seeded", 0));
  EXPECT_TRUE(reset.infos.at("seeded").array().data<bool>()[1]);
  EXPECT_EQ(made.env->metadata().autoreset_mode, AutoresetMode::kNextStep);
}

TEST_P(AutoresetTest, NextStepResetsOnTheStepAfterTheDone) {
  ScriptedVector made = make(AutoresetMode::kNextStep);
  made.env->reset(1);
  // Step 1: both run.
  const VectorStepResult* result = &made.env->step(scripted_actions(2, 0.1F));
  EXPECT_TRUE(neither(*result, 0) && neither(*result, 1));
  EXPECT_EQ(reward(*result, 0), 0.5);
  // Step 2: env 0's episode ends; its row is the episode's last observation.
  result = &made.env->step(scripted_actions(2, 0.2F));
  EXPECT_TRUE(ended(*result, 0, truncate()));
  EXPECT_TRUE(neither(*result, 1));
  EXPECT_EQ(reward(*result, 0), 0.25);
  EXPECT_TRUE(row(result->obs, 0).equals(recorded(made, 0)));
  EXPECT_EQ(info_t(*result, 0), 2);
  EXPECT_FALSE(result->infos.contains("final_obs"));
  // Step 3: env 0 ignores its action and resets (reward 0, both flags false, the reset's info);
  // env 1's episode ends.
  result = &made.env->step(scripted_actions(2, 0.3F));
  EXPECT_EQ(actions_seen(made, 0), 2U);
  EXPECT_EQ(made.scripted[0]->t, 0);
  EXPECT_TRUE(neither(*result, 0));
  EXPECT_EQ(reward(*result, 0), 0.0);
  EXPECT_TRUE(row(result->obs, 0).equals(recorded(made, 0)));
  EXPECT_TRUE(mask(result->infos, "seeded", 0));
  EXPECT_FALSE(result->infos.at("seeded").array().data<bool>()[0]);  // autoresets are unseeded
  EXPECT_FALSE(mask(result->infos, "t", 0));
  EXPECT_EQ(info_t(*result, 0), 0);  // rows without the key are zero
  EXPECT_TRUE(ended(*result, 1, truncate()));
  EXPECT_EQ(reward(*result, 1), 0.125);
  EXPECT_FALSE(mask(result->infos, "seeded", 1));
  // Step 4: env 0 runs its new episode; env 1 resets.
  result = &made.env->step(scripted_actions(2, 0.4F));
  EXPECT_EQ(actions_seen(made, 0), 3U);
  EXPECT_FLOAT_EQ(made.scripted[0]->actions.back().array().data<float>()[0], 0.4F);
  EXPECT_EQ(reward(*result, 0), 0.5);
  EXPECT_EQ(actions_seen(made, 1), 3U);
  EXPECT_EQ(reward(*result, 1), 0.0);
  EXPECT_TRUE(neither(*result, 1));
  EXPECT_TRUE(row(result->obs, 1).equals(recorded(made, 1)));
}

TEST_P(AutoresetTest, SameStepResetsInTheStepOfTheDone) {
  ScriptedVector made = make(AutoresetMode::kSameStep);
  made.env->reset(1);
  const VectorStepResult* result = &made.env->step(scripted_actions(2, 0.1F));
  EXPECT_FALSE(result->infos.contains("final_obs"));
  // Step 2: env 0 ends and is reset at once: its row is the reset observation, the episode's
  // last one is in final_obs; reward and flags are the last step's.
  result = &made.env->step(scripted_actions(2, 0.2F));
  EXPECT_TRUE(ended(*result, 0, truncate()));
  EXPECT_EQ(reward(*result, 0), 0.25);
  EXPECT_EQ(made.scripted[0]->t, 0);
  EXPECT_TRUE(row(result->obs, 0).equals(recorded(made, 0)));
  const Info& infos = result->infos;
  ASSERT_TRUE(infos.contains("final_obs"));
  EXPECT_TRUE(row(infos.at("final_obs"), 0).equals(recorded(made, 0, 2)));
  EXPECT_TRUE(row(infos.at("final_obs"), 1).equals(Array(DType::kFloat32, {3})));
  EXPECT_TRUE(mask(infos, "final_obs", 0));
  EXPECT_FALSE(mask(infos, "final_obs", 1));
  EXPECT_TRUE(mask(infos, "final_info", 0));
  EXPECT_FALSE(mask(infos, "final_info", 1));
  // The last step's info is in final_info; the top level has the reset's for env 0.
  const Info& final_info = infos.at("final_info").dict();
  EXPECT_EQ(final_info.at("t").array().data<std::int64_t>()[0], 2);
  EXPECT_TRUE(mask(final_info, "t", 0));
  EXPECT_FALSE(mask(final_info, "t", 1));
  EXPECT_TRUE(mask(infos, "seeded", 0));
  EXPECT_FALSE(mask(infos, "t", 0));
  EXPECT_TRUE(mask(infos, "t", 1));
  EXPECT_EQ(info_t(*result, 1), 2);
  // Step 3: env 0 steps its new episode with its action; env 1 ends and resets.
  result = &made.env->step(scripted_actions(2, 0.3F));
  EXPECT_EQ(actions_seen(made, 0), 3U);
  EXPECT_EQ(reward(*result, 0), 0.5);
  EXPECT_TRUE(neither(*result, 0));
  EXPECT_TRUE(ended(*result, 1, truncate()));
  EXPECT_TRUE(row(result->infos.at("final_obs"), 1).equals(recorded(made, 1, 2)));
  EXPECT_TRUE(row(result->infos.at("final_obs"), 0).equals(Array(DType::kFloat32, {3})));
  EXPECT_TRUE(mask(result->infos, "final_obs", 1));
  EXPECT_FALSE(mask(result->infos, "final_obs", 0));
  // Step 4: env 0's second episode ends; env 1 runs.
  result = &made.env->step(scripted_actions(2, 0.4F));
  EXPECT_TRUE(mask(result->infos, "final_obs", 0));
  EXPECT_FALSE(mask(result->infos, "final_obs", 1));
  // Step 5: no env ends, and the infos have no final entries.
  result = &made.env->step(scripted_actions(2, 0.5F));
  EXPECT_TRUE(neither(*result, 0) && neither(*result, 1));
  EXPECT_FALSE(result->infos.contains("final_obs"));
  EXPECT_FALSE(result->infos.contains("final_info"));
}

TEST_P(AutoresetTest, DisabledLeavesTheResetToTheCaller) {
  ScriptedVector made = make(AutoresetMode::kDisabled);
  made.env->reset(1);
  made.env->step(scripted_actions(2, 0.1F));
  const VectorStepResult& result = made.env->step(scripted_actions(2, 0.2F));
  EXPECT_TRUE(ended(result, 0, truncate()));
  EXPECT_TRUE(row(result.obs, 0).equals(recorded(made, 0)));
  const Array env1_obs = row(result.obs, 1).clone();
  // Stepping again without resetting env 0 throws before any env steps.
  EXPECT_THROW(made.env->step(scripted_actions(2, 0.3F)), ResetNeeded);
  EXPECT_EQ(actions_seen(made, 1), 2U);
  // Reset env 0 alone: its row is the reset observation, env 1's row is kept.
  Array reset_mask = Array::from_vector<bool>({2}, {true, false});
  const VectorResetResult& reset = made.env->reset(std::nullopt, {}, reset_mask);
  EXPECT_TRUE(row(reset.obs, 0).equals(recorded(made, 0)));
  EXPECT_TRUE(row(reset.obs, 1).equals(env1_obs));
  EXPECT_TRUE(mask(reset.infos, "seeded", 0));
  EXPECT_FALSE(mask(reset.infos, "seeded", 1));
  // Both step on; env 1 ends.
  const VectorStepResult& next = made.env->step(scripted_actions(2, 0.3F));
  EXPECT_EQ(reward(next, 0), 0.5);
  EXPECT_TRUE(ended(next, 1, truncate()));
  EXPECT_FALSE(next.infos.contains("final_obs"));
  // A seeded masked reset seeds env i with seed + i, as a full reset does.
  const VectorResetResult& seeded =
      made.env->reset(50, {}, Array::from_vector<bool>({2}, {false, true}));
  testing::ScriptedEnv alone1(testing::box(-10, 10, {3}), testing::box(-1, 1, {1}));
  EXPECT_TRUE(row(seeded.obs, 1).equals(alone1.reset(51).obs.array()));
}

TEST_P(AutoresetTest, ResetMaskIsChecked) {
  ScriptedVector made = make(AutoresetMode::kDisabled);
  made.env->reset(1);
  EXPECT_THROW(made.env->reset(std::nullopt, {}, Array::from_vector<bool>({2}, {false, false})),
               std::invalid_argument);
  EXPECT_THROW(made.env->reset(std::nullopt, {}, Array::from_vector<bool>({3}, {true, true, true})),
               std::invalid_argument);
  EXPECT_THROW(made.env->reset(std::nullopt, {}, Array::from_vector<std::int64_t>({2}, {1, 0})),
               std::invalid_argument);
}

std::string param_name(const ::testing::TestParamInfo<std::tuple<int, bool>>& param_info) {
  const int threads = std::get<0>(param_info.param);
  return (threads == 0 ? std::string("Sync") : "Async" + std::to_string(threads)) +
         (std::get<1>(param_info.param) ? "Truncated" : "Terminated");
}

INSTANTIATE_TEST_SUITE_P(Modes, AutoresetTest,
                         ::testing::Combine(::testing::Values(0, 2), ::testing::Bool()),
                         param_name);

}  // namespace
}  // namespace pixelgym::vector
