// VectorWrapper forwards every call to the vector env it wraps (or to the wrapper it wraps):
// the same results, spaces, metadata and errors, in SyncVectorEnv and AsyncVectorEnv (2 threads).
#include "pixelgym/envs/vector/vector_wrapper.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "tests/envs/vector/vector_test_util.h"

namespace pixelgym::vector {
namespace {

using ::testing::HasSubstr;
using testing::make_scripted_vector;
using testing::scripted_actions;

class VectorWrapperTest : public ::testing::TestWithParam<int> {
 protected:
  int threads() const { return GetParam(); }
};

TEST_P(VectorWrapperTest, ForwardsSpacesMetadataAndNames) {
  testing::ScriptedVector made =
      make_scripted_vector({2, 3, 4}, false, AutoresetMode::kSameStep, threads());
  const VectorEnv* inner = made.env.get();
  auto once = std::make_unique<VectorWrapper>(std::move(made.env));
  const VectorWrapper* once_view = once.get();
  const VectorWrapper twice(std::move(once));
  EXPECT_EQ(twice.num_envs(), 3);
  EXPECT_TRUE(twice.single_observation_space().equals(inner->single_observation_space()));
  EXPECT_TRUE(twice.single_action_space().equals(inner->single_action_space()));
  EXPECT_TRUE(twice.observation_space().equals(inner->observation_space()));
  EXPECT_TRUE(twice.action_space().equals(inner->action_space()));
  EXPECT_EQ(twice.autoreset_mode(), AutoresetMode::kSameStep);
  EXPECT_EQ(&twice.metadata(), &inner->metadata());
  EXPECT_EQ(&twice.unwrapped(), inner);
  EXPECT_EQ(&twice.inner(), once_view);
  EXPECT_EQ(&once_view->inner(), inner);
  EXPECT_EQ(&twice.env(2), &inner->env(2));
  EXPECT_THROW(twice.env(3), std::out_of_range);
  EXPECT_EQ(twice.name(), "VectorWrapper<VectorWrapper<" + inner->name() + ">>");
}

TEST_P(VectorWrapperTest, ReturnsTheInnerResults) {
  testing::ScriptedVector made =
      make_scripted_vector({2, 3}, true, AutoresetMode::kDisabled, threads());
  const VectorEnv* inner = made.env.get();
  VectorWrapper wrapper(std::make_unique<VectorWrapper>(std::move(made.env)));
  const VectorResetResult& reset = wrapper.reset(5);
  EXPECT_TRUE(reset.obs.array().index(1).equals(made.scripted[1]->observations.back().array()));
  const VectorStepResult& step = wrapper.step(scripted_actions(2, 0.1F));
  EXPECT_EQ(step.rewards.data<double>()[0], 0.5);
  const VectorStepResult& done = wrapper.step(scripted_actions(2, 0.2F));
  EXPECT_TRUE(done.truncated.data<bool>()[0]);
  EXPECT_EQ(done.infos.at("t").array().data<std::int64_t>()[1], 2);
  // Disabled: the inner env's refusal comes through; the masked reset goes through.
  EXPECT_THROW(wrapper.step(scripted_actions(2, 0.3F)), ResetNeeded);
  const Array mask = Array::from_vector<bool>({2}, {true, false});
  const VectorResetResult& partial = wrapper.reset(std::nullopt, {}, mask);
  EXPECT_TRUE(partial.infos.at("_seeded").array().data<bool>()[0]);
  EXPECT_FALSE(partial.infos.at("_seeded").array().data<bool>()[1]);
  EXPECT_EQ(made.scripted[0]->t, 0);
  EXPECT_EQ(made.scripted[1]->t, 2);
  EXPECT_THROW(wrapper.reset(std::nullopt, {}, Array(DType::kBool, {2})), std::invalid_argument);
  // Bad actions: the inner env's message.
  try {
    wrapper.step(Array(DType::kFloat32, {3, 1}));
    ADD_FAILURE() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr(inner->name()));
  }
  wrapper.close();
  EXPECT_TRUE(wrapper.closed());
  EXPECT_TRUE(inner->closed());
  EXPECT_THROW(wrapper.step(scripted_actions(2, 0.3F)), ResetNeeded);
}

TEST_P(VectorWrapperTest, ResultsAreTheInnerBuffers) {
  testing::ScriptedVector made =
      make_scripted_vector({2, 3}, false, AutoresetMode::kNextStep, threads());
  VectorEnv& inner = *made.env;
  VectorWrapper wrapper(std::move(made.env));
  EXPECT_EQ(&wrapper.reset(1), &inner.reset(1));
  EXPECT_EQ(&wrapper.step(scripted_actions(2, 0.1F)), &inner.step(scripted_actions(2, 0.1F)));
}

TEST(VectorWrapperErrorsTest, RefusesANullEnv) {
  EXPECT_THROW(VectorWrapper wrapper(std::unique_ptr<VectorEnv>{}), std::invalid_argument);
  EXPECT_THROW(VectorWrapper wrapper(std::unique_ptr<VectorWrapper>{}), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(SyncAndPool, VectorWrapperTest, ::testing::Values(0, 2),
                         [](const ::testing::TestParamInfo<int>& param_info) {
                           return param_info.param == 0
                                      ? std::string("Sync")
                                      : "Threads" + std::to_string(param_info.param);
                         });

}  // namespace
}  // namespace pixelgym::vector
