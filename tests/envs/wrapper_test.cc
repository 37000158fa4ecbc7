#include "pixelgym/envs/wrapper.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "tests/envs/probe_env.h"

namespace pixelgym {
namespace {

using testing::action;
using testing::ProbeEnv;

// Doubles observations and declares the doubled bounds.
class DoubleObservation final : public ObservationWrapper {
 public:
  explicit DoubleObservation(std::unique_ptr<Env> env) : ObservationWrapper(std::move(env)) {
    set_observation_space(std::make_shared<spaces::Box>(-20.0, 20.0, Shape{2}));
  }

 protected:
  std::string type_name() const override { return "DoubleObservation"; }
  void observation(const Value& obs, Value& out) override {
    for (int i = 0; i < 2; ++i) out.array().data<float>()[i] = 2.0F * obs.array().data<float>()[i];
  }
};

// Takes actions in [-10, 10] and scales them into the inner env's [-1, 1].
class ScaleAction final : public ActionWrapper {
 public:
  explicit ScaleAction(std::unique_ptr<Env> env) : ActionWrapper(std::move(env)) {
    set_action_space(std::make_shared<spaces::Box>(-10.0, 10.0, Shape{1}));
  }

 protected:
  void action(const Value& a, Value& out) override {
    out.array().data<float>()[0] = a.array().data<float>()[0] / 10.0F;
  }
};

class NegateReward final : public RewardWrapper {
 public:
  using RewardWrapper::RewardWrapper;

 protected:
  double reward(double r) override { return -r; }
};

TEST(WrapperTest, ForwardsProtocolAndUnwraps) {
  auto inner = std::make_unique<ProbeEnv>();
  ProbeEnv* probe = inner.get();
  DoubleObservation env(std::move(inner));
  EXPECT_EQ(&env.unwrapped(), probe);
  EXPECT_EQ(&env.env(), probe);
  EXPECT_EQ(env.name(), "DoubleObservation<ProbeEnv>");
  EXPECT_TRUE(env.action_space().equals(probe->action_space()));
  EXPECT_EQ(env.metadata().render_fps, 30.0);
}

TEST(WrapperTest, ObservationWrapperTransformsResetAndStep) {
  DoubleObservation env(std::make_unique<ProbeEnv>());
  const Value obs = env.reset(3).obs;
  const auto& probe = static_cast<const ProbeEnv&>(env.unwrapped());
  EXPECT_FLOAT_EQ(obs.array().data<float>()[0], 2.0F * static_cast<float>(probe.x()));
  EXPECT_TRUE(env.observation_space().contains(obs));
  EXPECT_FALSE(env.env().observation_space().equals(env.observation_space()));
  const Value stepped = env.step(action(1.0F)).obs;
  EXPECT_FLOAT_EQ(stepped.array().data<float>()[1], 0.02F);
}

TEST(WrapperTest, SeedReachesTheInnerEnv) {
  DoubleObservation a(std::make_unique<ProbeEnv>());
  ProbeEnv b;
  a.reset(99);
  b.reset(99);
  EXPECT_EQ(static_cast<ProbeEnv&>(a.unwrapped()).x(), b.x());
}

TEST(WrapperTest, ActionWrapperValidatesItsOwnSpaceThenTransforms) {
  ScaleAction env(std::make_unique<ProbeEnv>());
  env.reset(0);
  const double x0 = static_cast<ProbeEnv&>(env.unwrapped()).x();
  env.step(action(5.0F));  // outside the inner space, inside the wrapper's
  EXPECT_NEAR(static_cast<ProbeEnv&>(env.unwrapped()).x(), x0 + 0.05, 1e-6);
  EXPECT_THROW(env.step(action(11.0F)), std::invalid_argument);
}

TEST(WrapperTest, RewardWrapperTransformsReward) {
  NegateReward env(std::make_unique<ProbeEnv>());
  env.reset(0);
  const StepResult result = env.step(action(0.0F));
  EXPECT_EQ(result.reward, std::abs(static_cast<ProbeEnv&>(env.unwrapped()).x()));
}

TEST(WrapperTest, OrderIsEnforcedAtTheWrapperAndCloseReachesInner) {
  auto inner = std::make_unique<ProbeEnv>();
  ProbeEnv* probe = inner.get();
  NegateReward env(std::move(inner));
  EXPECT_THROW(env.step(action(0.0F)), ResetNeeded);
  env.close();
  env.close();
  EXPECT_EQ(probe->close_calls(), 1);
}

TEST(WrapperTest, NullEnvIsRejected) { EXPECT_THROW(NegateReward(nullptr), std::invalid_argument); }

TEST(WrapperTest, ObservationWrapperWritesIntoTheCallersBufferThroughItsOwn) {
  DoubleObservation env(std::make_unique<ProbeEnv>());
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  const void* reset_memory = reset.obs.array().raw_data();
  env.reset_into(reset, 3);
  EXPECT_EQ(reset.obs.array().raw_data(), reset_memory);
  EXPECT_TRUE(reset.obs.equals(env.reset(3).obs));

  env.reset(3);
  StepResult step;
  step.obs = env.observation_space().zeros();
  const void* step_memory = step.obs.array().raw_data();
  env.step_into(action(0.5F), step);
  EXPECT_EQ(step.obs.array().raw_data(), step_memory);
  const double x = static_cast<ProbeEnv&>(env.unwrapped()).x();
  EXPECT_FLOAT_EQ(step.obs.array().data<float>()[0], static_cast<float>(2.0 * x));
}

TEST(WrapperTest, TheCallerKeepsItsBufferWhenTheInnerEnvThrows) {
  DoubleObservation env(std::make_unique<ProbeEnv>());
  env.reset(0);
  StepResult step;
  step.obs = env.observation_space().zeros();
  const void* memory = step.obs.array().raw_data();
  env.env().close();  // the inner env now refuses to step; the wrapper still accepts the call
  EXPECT_THROW(env.step_into(action(0.0F), step), ResetNeeded);
  ASSERT_TRUE(step.obs.is_array());
  EXPECT_EQ(step.obs.array().raw_data(), memory);
  EXPECT_EQ(step.obs.array().shape(), (Shape{2}));
}

TEST(WrapperTest, ActionWrapperStepsTheInnerEnvThroughItsOwnActionBuffer) {
  ScaleAction env(std::make_unique<ProbeEnv>());
  env.reset(0);
  const double x0 = static_cast<ProbeEnv&>(env.unwrapped()).x();
  StepResult step;
  step.obs = env.observation_space().zeros();
  env.step_into(action(5.0F), step);
  env.step_into(action(-5.0F), step);
  env.step_into(action(5.0F), step);
  EXPECT_NEAR(static_cast<ProbeEnv&>(env.unwrapped()).x(), x0 + 0.05, 1e-6);
}

// Hands out buffers of its own (as FrameStackObservation does) and records which call asked.
class OwnBuffer final : public Wrapper {
 public:
  using Wrapper::Wrapper;
  Value observation_buffer(BufferFor call) override {
    calls.push_back(call);
    return buffer;
  }
  Array buffer{DType::kFloat32, {2}};
  std::vector<BufferFor> calls;
};

// Declares a space of its own (the same bounds, another Space object) and writes nothing.
class OwnSpace final : public Wrapper {
 public:
  using Wrapper::Wrapper;
  const Space& observation_space() const override { return space_; }

 private:
  spaces::Box space_{-10.0, 10.0, {2}};
};

TEST(WrapperTest, ResetAndStepTakeTheBufferHooksBuffer) {
  OwnBuffer env(std::make_unique<ProbeEnv>());
  const Value reset = env.reset(0).obs;
  const Value step = env.step(action(0.5F)).obs;
  EXPECT_TRUE(reset.shares_memory(env.buffer));
  EXPECT_TRUE(step.shares_memory(env.buffer));
  EXPECT_EQ(env.calls, (std::vector<BufferFor>{BufferFor::kReset, BufferFor::kStep}));
}

TEST(WrapperTest, TheBufferHookIsForwardedOnlyByWrappersThatKeepTheSpace) {
  const Value plain = ProbeEnv().observation_buffer(BufferFor::kStep);
  EXPECT_EQ(plain.array().shape(), (Shape{2}));
  EXPECT_EQ(plain.array().data<float>()[0], 0.0F);

  auto own = std::make_unique<OwnBuffer>(std::make_unique<ProbeEnv>());
  const Array buffer = own->buffer;
  NegateReward reward(std::move(own));  // the same space: forwarded
  EXPECT_TRUE(reward.observation_buffer(BufferFor::kReset).shares_memory(buffer));
  reward.reset(0);
  EXPECT_TRUE(reward.step(action(0.5F)).obs.shares_memory(buffer));

  DoubleObservation doubled(std::make_unique<OwnBuffer>(std::make_unique<ProbeEnv>()));
  EXPECT_FALSE(doubled.observation_buffer(BufferFor::kStep)
                   .shares_memory(static_cast<OwnBuffer&>(doubled.env()).buffer));
  OwnSpace other(std::make_unique<OwnBuffer>(std::make_unique<ProbeEnv>()));
  EXPECT_FALSE(other.observation_buffer(BufferFor::kStep)
                   .shares_memory(static_cast<OwnBuffer&>(other.env()).buffer));
}

}  // namespace
}  // namespace pixelgym
