// Contract tests over every registered env (dm_control's suite_test pattern): adding an env to the
// registry adds it here.
#include <gtest/gtest.h>

#include <cmath>

#include "envs/checker.h"
#include "envs/registry.h"

namespace pixelgym {
namespace {

class RegisteredEnvTest : public ::testing::TestWithParam<std::string> {};

TEST_P(RegisteredEnvTest, PassesCheckEnv) {
  std::unique_ptr<Env> env = make(GetParam());
  const CheckReport report = check_env(*env, {/*seed=*/0, /*num_steps=*/200});
  for (const CheckResult& result : report.failures()) {
    ADD_FAILURE() << GetParam() << ": " << result.name << ": " << result.reason;
  }
}

TEST_P(RegisteredEnvTest, SameSeedAndActionsGiveIdenticalTrajectoriesAcrossInstances) {
  std::unique_ptr<Env> a = make(GetParam());
  std::unique_ptr<Env> b = make(GetParam());
  Rng actions(1);
  Value obs_a = a->reset(123).obs;
  Value obs_b = b->reset(123).obs;
  ASSERT_TRUE(obs_a.equals(obs_b));
  for (int t = 0; t < 300; ++t) {
    const Value action = a->action_space().sample(actions);
    const StepResult sa = a->step(action);
    const StepResult sb = b->step(action);
    ASSERT_TRUE(sa.obs.equals(sb.obs)) << "step " << t;
    ASSERT_EQ(sa.reward, sb.reward) << "step " << t;
    ASSERT_EQ(sa.terminated, sb.terminated);
    ASSERT_EQ(sa.truncated, sb.truncated);
    ASSERT_TRUE(a->render().equals(b->render())) << "step " << t;
    if (sa.terminated || sa.truncated) {
      ASSERT_TRUE(a->reset().obs.equals(b->reset().obs));
    }
  }
}

TEST_P(RegisteredEnvTest, RejectsActionsOfTheWrongKind) {
  std::unique_ptr<Env> env = make(GetParam());
  env->reset(0);
  EXPECT_THROW(env->step(Value(Tuple{})), std::invalid_argument);
  EXPECT_THROW(env->step(Array::scalar<double>(std::nan(""))), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, RegisteredEnvTest, ::testing::ValuesIn(registered_ids()),
                         [](const ::testing::TestParamInfo<std::string>& param_info) {
                           std::string name = param_info.param;
                           for (char& c : name) {
                             if (c == '-') c = '_';
                           }
                           return name;
                         });

}  // namespace
}  // namespace pixelgym
