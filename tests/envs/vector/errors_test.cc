// Vector env errors: bad construction, calls out of order, bad actions, and an env that throws
// inside a worker (the message names the env; the vector env is usable again after reset()).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "tests/envs/vector/vector_test_util.h"

namespace pixelgym::vector {
namespace {

using ::testing::HasSubstr;
using testing::make_scripted_vector;
using testing::scripted_actions;
using testing::ScriptedVector;

/// Throws std::runtime_error on its `throw_at`-th step (counted over its life).
class ThrowingWrapper final : public Wrapper {
 public:
  ThrowingWrapper(std::unique_ptr<Env> env, int throw_at)
      : Wrapper(std::move(env)), throw_at_(throw_at) {}

 protected:
  std::string type_name() const override { return "ThrowingWrapper"; }
  void do_step(const Value& action, StepResult& out) override {
    if (++steps_ == throw_at_) throw std::runtime_error("the simulation blew up");
    Wrapper::do_step(action, out);
  }

 private:
  int throw_at_;
  int steps_ = 0;
};

std::unique_ptr<Env> scripted_env(int episode_length = 100) {
  return std::make_unique<testing::ScriptedEnv>(testing::box(-10, 10, {3}),
                                                testing::box(-1, 1, {1}), episode_length);
}

// A message-matching EXPECT_THROW.
template <typename Exception, typename Body>
std::string thrown_message(Body&& body) {
  try {
    body();
  } catch (const Exception& e) {
    return e.what();
  }
  ADD_FAILURE() << "nothing of the expected type thrown";
  return "";
}

class VectorErrorsTest : public ::testing::TestWithParam<int> {};  // threads; 0: sync

TEST_P(VectorErrorsTest, AWorkerErrorNamesTheEnvAndAResetRecovers) {
  const int threads = GetParam();
  const EnvFactory factory = [](int i) -> std::unique_ptr<Env> {
    if (i == 2) return std::make_unique<ThrowingWrapper>(scripted_env(), 3);
    return scripted_env();
  };
  auto env = testing::make_vector_env(threads, 4, factory, AutoresetMode::kNextStep);
  env->reset(0);
  env->step(scripted_actions(4, 0.1F));
  env->step(scripted_actions(4, 0.1F));
  const std::string message =
      thrown_message<std::runtime_error>([&] { env->step(scripted_actions(4, 0.1F)); });
  EXPECT_THAT(message, HasSubstr("env 2 (ThrowingWrapper<ScriptedEnv>)"));
  EXPECT_THAT(message, HasSubstr("the simulation blew up"));
  // Until a full reset, steps and masked resets are refused.
  EXPECT_THROW(env->step(scripted_actions(4, 0.1F)), ResetNeeded);
  EXPECT_THROW(env->reset(std::nullopt, {}, Array::from_vector<bool>({4}, {0, 0, 1, 0})),
               ResetNeeded);
  const VectorResetResult& reset = env->reset(7);
  EXPECT_EQ(reset.obs.array().shape(), (Shape{4, 3}));
  const VectorStepResult& step = env->step(scripted_actions(4, 0.1F));
  EXPECT_EQ(step.rewards.data<double>()[2], 1.0);
}

TEST_P(VectorErrorsTest, AnActionOutsideTheSpaceNamesTheEnv) {
  ScriptedVector made =
      make_scripted_vector({5, 5, 5}, false, AutoresetMode::kNextStep, GetParam());
  made.env->reset(0);
  Value actions = Array::from_vector<float>({3, 1}, {0.0F, 5.0F, 0.0F});
  const std::string message =
      thrown_message<std::invalid_argument>([&] { made.env->step(actions); });
  EXPECT_THAT(message, HasSubstr("env 1"));
  EXPECT_THAT(message, HasSubstr("is not in Box"));
  EXPECT_THROW(made.env->step(scripted_actions(3, 0.0F)), ResetNeeded);
  made.env->reset();
  made.env->step(scripted_actions(3, 0.0F));
}

TEST_P(VectorErrorsTest, ActionsOfAnotherLayoutAreRefusedBeforeAnyEnvSteps) {
  ScriptedVector made = make_scripted_vector({5, 5}, false, AutoresetMode::kNextStep, GetParam());
  made.env->reset(0);
  std::string message = thrown_message<std::invalid_argument>([&] {
    made.env->step(Array::from_vector<float>({3, 1}, {0, 0, 0}));
  });
  EXPECT_THAT(message, HasSubstr("Box(-1.0, 1.0, (2, 1), float32)"));
  EXPECT_THAT(message, HasSubstr("(3, 1)"));
  message = thrown_message<std::invalid_argument>([&] {
    made.env->step(Array::from_vector<double>({2, 1}, {0, 0}));
  });
  EXPECT_THAT(message, HasSubstr("dtype float64, expected float32"));
  EXPECT_EQ(made.scripted[0]->actions.size(), 0U);
  // Nothing stepped, nothing broken: the next good step runs.
  made.env->step(scripted_actions(2, 0.0F));
  EXPECT_EQ(made.scripted[1]->actions.size(), 1U);
}

TEST_P(VectorErrorsTest, CallsOutOfOrder) {
  ScriptedVector made = make_scripted_vector({5, 5}, false, AutoresetMode::kNextStep, GetParam());
  EXPECT_THROW(made.env->step(scripted_actions(2, 0.0F)), ResetNeeded);
  made.env->reset(0);
  made.env->close();
  made.env->close();
  EXPECT_THROW(made.env->step(scripted_actions(2, 0.0F)), ResetNeeded);
  EXPECT_THROW(made.env->reset(0), ResetNeeded);
}

TEST_P(VectorErrorsTest, AFactoryErrorNamesTheEnv) {
  const EnvFactory factory = [](int i) -> std::unique_ptr<Env> {
    if (i == 1) throw std::invalid_argument("no such camera");
    return scripted_env();
  };
  const std::string message = thrown_message<std::invalid_argument>(
      [&] { testing::make_vector_env(GetParam(), 3, factory, AutoresetMode::kNextStep); });
  EXPECT_THAT(message, HasSubstr("env 1"));
  EXPECT_THAT(message, HasSubstr("no such camera"));
}

TEST_P(VectorErrorsTest, EnvsWithOtherSpacesAreRefused) {
  const EnvFactory factory = [](int i) -> std::unique_ptr<Env> {
    return std::make_unique<testing::ScriptedEnv>(testing::box(-10, 10, {i == 0 ? 3 : 4}),
                                                  testing::box(-1, 1, {1}));
  };
  const std::string message = thrown_message<std::invalid_argument>(
      [&] { testing::make_vector_env(GetParam(), 2, factory, AutoresetMode::kNextStep); });
  EXPECT_THAT(message, HasSubstr("env 1's spaces differ from env 0's"));
}

std::string threads_name(const ::testing::TestParamInfo<int>& param_info) {
  return param_info.param == 0 ? "Sync" : "Async" + std::to_string(param_info.param);
}

INSTANTIATE_TEST_SUITE_P(Runners, VectorErrorsTest, ::testing::Values(0, 1, 2, 4), threads_name);

TEST(VectorEnvTest, NumEnvsBelowOneIsAnError) {
  const EnvFactory factory = [](int) { return scripted_env(); };
  EXPECT_THAT(thrown_message<std::invalid_argument>([&] { SyncVectorEnv env(0, factory); }),
              HasSubstr("num_envs must be >= 1, got num_envs = 0"));
  EXPECT_THAT(thrown_message<std::invalid_argument>([&] { AsyncVectorEnv env(-1, factory, 2); }),
              HasSubstr("num_envs must be >= 1, got num_envs = -1"));
}

TEST(AsyncVectorEnvTest, MoreThreadsThanEnvsAreClamped) {
  const EnvFactory factory = [](int) { return scripted_env(); };
  EXPECT_EQ(AsyncVectorEnv(3, factory, 8).num_threads(), 3);
  EXPECT_EQ(AsyncVectorEnv(3, factory, 2).num_threads(), 2);
  EXPECT_GE(AsyncVectorEnv(3, factory, 0).num_threads(), 1);
  EXPECT_THROW(AsyncVectorEnv(3, factory, -1), std::invalid_argument);
}

TEST(AsyncVectorEnvTest, StepAsyncAndStepWait) {
  const EnvFactory factory = [](int) { return scripted_env(); };
  AsyncVectorEnv env(3, factory, 2);
  EXPECT_THAT(thrown_message<ResetNeeded>([&] { env.step_wait(); }),
              HasSubstr("step_wait() called without a pending step_async()"));
  env.reset(0);
  EXPECT_THROW(env.step_wait(), ResetNeeded);
  Value actions = scripted_actions(3, 0.5F);
  env.step_async(actions);
  actions.array().data<float>()[0] = 99.0F;  // the vector env copied the actions
  EXPECT_THROW(env.step_async(actions), ResetNeeded);
  EXPECT_THROW(env.reset(0), ResetNeeded);
  const VectorStepResult& result = env.step_wait();
  EXPECT_EQ(result.rewards.shape(), (Shape{3}));
  EXPECT_THROW(env.step_wait(), ResetNeeded);
  // A step left pending is waited for by close() (and the destructor); step_wait() then names the
  // close (it said "without a pending step_async()", issue 42).
  env.step_async(scripted_actions(3, 0.5F));
  env.close();
  EXPECT_THAT(thrown_message<ResetNeeded>([&] { env.step_wait(); }),
              HasSubstr("step_wait() called after close()"));
  EXPECT_THAT(thrown_message<ResetNeeded>([&] { env.step_async(scripted_actions(3, 0.5F)); }),
              HasSubstr("step_async() called after close()"));
}

// Errors on the worker threads of step_async() reach the caller at step_wait(): the lowest
// failing env's, while the other envs still finish their step.
TEST(AsyncVectorEnvTest, StepWaitReportsTheLowestFailingEnvAfterEveryEnvStepped) {
  for (const int threads : {1, 2, 4}) {
    std::vector<testing::ScriptedEnv*> scripted(4, nullptr);
    const EnvFactory factory = [&scripted](int i) -> std::unique_ptr<Env> {
      auto env = std::make_unique<testing::ScriptedEnv>(testing::box(-10, 10, {3}),
                                                        testing::box(-1, 1, {1}), 100);
      scripted[static_cast<std::size_t>(i)] = env.get();
      if (i == 1 || i == 3) return std::make_unique<ThrowingWrapper>(std::move(env), 2);
      return env;
    };
    AsyncVectorEnv env(4, factory, threads);
    env.reset(0);
    env.step_async(scripted_actions(4, 0.1F));
    env.step_wait();
    env.step_async(scripted_actions(4, 0.1F));
    const std::string message = thrown_message<std::runtime_error>([&] { env.step_wait(); });
    EXPECT_THAT(message, HasSubstr("env 1 (ThrowingWrapper<ScriptedEnv>)")) << threads;
    EXPECT_THAT(message, HasSubstr("the simulation blew up")) << threads;
    for (const int i : {0, 2}) {
      EXPECT_EQ(scripted[static_cast<std::size_t>(i)]->actions.size(), 2U)
          << threads << " threads, env " << i;
    }
    EXPECT_THROW(env.step_async(scripted_actions(4, 0.1F)), ResetNeeded);
    env.reset(1);
    env.step_async(scripted_actions(4, 0.1F));
    EXPECT_EQ(env.step_wait().rewards.data<double>()[0], 1.0);
  }
}

TEST(MakeVecTest, BadIdsKwargsAndWrappersAreReportedBeforeBuilding) {
  EXPECT_THROW(make_vec("NoSuchEnv-v0", 2), std::invalid_argument);
  EXPECT_THROW(make_vec("GridWorld-v0", 2, {{"no_such_kwarg", 1}}), std::invalid_argument);
  EXPECT_THROW(make_vec("GridWorld-v0", 2, {}, pixelgym::wrappers::wrapping({"no_such_wrapper"})),
               std::invalid_argument);
  EXPECT_THROW(make_vec("GridWorld-v0", 0), std::invalid_argument);
}

TEST(MakeVecTest, BuildsTheWrappedEnvs) {
  auto env = make_vec(
      "CartPoleSwingup-v0", 2, {{"width", 32}, {"height", 32}, {"obs_mode", "pixels"}},
      pixelgym::wrappers::wrapping({"grayscale", "frame_stack=3"}), {VectorMode::kAsync, 2});
  EXPECT_EQ(env->name(), "AsyncVectorEnv(CartPoleSwingup-v0, num_envs=2)");
  const auto& single = dynamic_cast<const spaces::Dict&>(env->single_observation_space());
  EXPECT_EQ(single.at("pixels").shape(), (Shape{3, 32, 32}));
  const auto& batched = dynamic_cast<const spaces::Dict&>(env->observation_space());
  EXPECT_EQ(batched.at("pixels").shape(), (Shape{2, 3, 32, 32}));
  EXPECT_EQ(env->action_space().to_string(), "Box(-1.0, 1.0, (2, 1), float32)");
  env->reset(0);
  env->step(env->action_space().sample());
}

}  // namespace
}  // namespace pixelgym::vector
