// Frame stacking in a vector env restarts for exactly the envs that reset, under every autoreset
// mode: the per-env FrameStackObservation given as `{"frame_stack=3"}` (make_vec's wrappers, here
// through the same wrappers::apply_wrappers), in SyncVectorEnv and AsyncVectorEnv (2 threads).
// Each env's frame is (env, episode, step, 7), so the test knows which frames every stacked row
// must hold; each row is also compared byte for byte with a single env, wrapped the same way and
// stepped (or reset) one call at a time as the mode says. This is why there is no vector-level
// frame stack wrapper (see envs/vector/vector_wrapper.h).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "tests/envs/vector/vector_test_util.h"

namespace pixelgym::vector {
namespace {

constexpr int kStack = 3;

/// Observations: a uint8 (2, 2) image holding (index, episode, step, 7): episode counts resets
/// from 0, step counts the episode's steps from 0. Episodes end (terminated) after `length` steps.
class CounterEnv final : public Env {
 public:
  CounterEnv(int index, int length) : index_(index), length_(length) {}

  const Space& observation_space() const override { return observation_space_; }
  const Space& action_space() const override { return action_space_; }
  const Metadata& metadata() const override { return metadata_; }

 protected:
  std::string type_name() const override { return "CounterEnv"; }
  void do_reset(std::optional<std::uint64_t> /*seed*/, const Options& /*options*/,
                ResetResult& out) override {
    ++episode_;
    t_ = 0;
    write(out.obs);
  }
  void do_step(const Value& /*action*/, StepResult& out) override {
    ++t_;
    write(out.obs);
    out.terminated = t_ >= length_;
  }
  Array do_render() override { return Array(DType::kUInt8, {2, 2, 3}); }

 private:
  void write(Value& obs) const {
    auto* pixels = obs.array().data<std::uint8_t>();
    pixels[0] = static_cast<std::uint8_t>(index_);
    pixels[1] = static_cast<std::uint8_t>(episode_);
    pixels[2] = static_cast<std::uint8_t>(t_);
    pixels[3] = 7;
  }

  int index_;
  int length_;
  int episode_ = -1;
  int t_ = 0;
  spaces::Box observation_space_{0.0, 255.0, {2, 2}, DType::kUInt8};
  spaces::Box action_space_{-1.0, 1.0, {1}};
  Metadata metadata_;
};

std::unique_ptr<Env> make_stacked(int index, int length) {
  return wrappers::apply_wrappers(std::make_unique<CounterEnv>(index, length),
                                  {"frame_stack=" + std::to_string(kStack)});
}

// The stacked observation of env `index` at step `t` of episode `episode`: frames t - 2, t - 1, t
// (the reset frame repeated before the episode has 3).
Array stack_of(int index, int episode, int t) {
  Array stacked(DType::kUInt8, {kStack, 2, 2});
  for (int k = 0; k < kStack; ++k) {
    const int frame_t = std::max(0, t - (kStack - 1 - k));
    auto* frame = stacked.index(k).data<std::uint8_t>();
    frame[0] = static_cast<std::uint8_t>(index);
    frame[1] = static_cast<std::uint8_t>(episode);
    frame[2] = static_cast<std::uint8_t>(frame_t);
    frame[3] = 7;
  }
  return stacked;
}

// Where each env is: its episode, its step in it, and (NextStep) whether its last step ended it.
struct Position {
  int episode = 0;
  int t = 0;
  bool ended = false;
};

class FrameStackTest : public ::testing::TestWithParam<std::tuple<int, AutoresetMode>> {
 protected:
  int threads() const { return std::get<0>(GetParam()); }
  AutoresetMode mode() const { return std::get<1>(GetParam()); }
};

TEST_P(FrameStackTest, EachEnvsStackRestartsExactlyWhenThatEnvResets) {
  const std::vector<int> lengths{2, 3, 4};
  const int n = 3;
  const auto env = testing::make_vector_env(
      threads(), n, [&](int i) { return make_stacked(i, lengths[static_cast<std::size_t>(i)]); },
      mode());
  std::vector<std::unique_ptr<Env>> singles;
  for (int i = 0; i < n; ++i)
    singles.push_back(make_stacked(i, lengths[static_cast<std::size_t>(i)]));
  EXPECT_EQ(env->single_observation_space().to_string(),
            singles[0]->observation_space().to_string());

  std::vector<Position> at(n);
  const VectorResetResult& reset = env->reset(0);
  for (int i = 0; i < n; ++i) {
    EXPECT_TRUE(reset.obs.array().index(i).equals(stack_of(i, 0, 0)));
    const ResetResult single = singles[static_cast<std::size_t>(i)]->reset(i);
    EXPECT_TRUE(reset.obs.array().index(i).equals(single.obs.array()));
  }
  int restarts = 0;
  int finals = 0;
  const Value actions = testing::scripted_actions(n, 0.1F);
  for (int step = 1; step <= 14; ++step) {
    const VectorStepResult& result = env->step(actions);
    std::vector<bool> done(n);
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const std::string where = std::string(autoreset_mode_name(mode())) + " step " +
                                std::to_string(step) + ", env " + std::to_string(i);
      Env& single = *singles[k];
      Position& p = at[k];
      Value single_obs;
      Value single_final;
      if (mode() == AutoresetMode::kNextStep && p.ended) {
        // This step is env i's reset: its stack restarts from the reset frame.
        p = Position{p.episode + 1, 0, false};
        single_obs = single.reset().obs;
        ++restarts;
      } else {
        ++p.t;
        const StepResult stepped = single.step(actions.array().index(i));
        single_obs = stepped.obs;
        done[k] = stepped.terminated;
        p.ended = stepped.terminated;
        EXPECT_EQ(p.ended, p.t == lengths[k]) << where;
        if (done[k] && mode() == AutoresetMode::kSameStep) {
          // The terminal stack goes to final_obs; the row is the restarted stack.
          single_final = single_obs;
          EXPECT_TRUE(single_final.array().equals(stack_of(i, p.episode, p.t))) << where;
          p = Position{p.episode + 1, 0, false};
          single_obs = single.reset().obs;
          ++restarts;
        }
      }
      EXPECT_EQ(result.terminated.data<bool>()[i], done[k]) << where;
      const Array row = result.obs.array().index(i);
      EXPECT_TRUE(row.equals(stack_of(i, p.episode, p.t))) << where << ": " << row.to_string();
      EXPECT_TRUE(row.equals(single_obs.array())) << where;
      if (mode() == AutoresetMode::kSameStep) {
        const bool has_final = result.infos.contains("final_obs") &&
                               result.infos.at("_final_obs").array().data<bool>()[i];
        EXPECT_EQ(has_final, done[k]) << where;
        if (has_final) {
          EXPECT_TRUE(result.infos.at("final_obs").array().index(i).equals(single_final.array()))
              << where;
          ++finals;
        }
      }
    }
    if (mode() != AutoresetMode::kDisabled) continue;
    // Disabled: reset the envs that ended, and env 2 mid-episode every fifth step; the other
    // rows keep their stacks, and go on stacking at the next step.
    std::vector<bool> mask = done;
    if (step % 5 == 0 && !mask[2]) mask[2] = true;
    if (!(mask[0] || mask[1] || mask[2])) continue;
    const Value before = result.obs.clone();
    const VectorResetResult& partial =
        env->reset(std::nullopt, {}, Array::from_vector<bool>({n}, {mask[0], mask[1], mask[2]}));
    for (int i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const Array row = partial.obs.array().index(i);
      if (mask[k]) {
        at[k] = Position{at[k].episode + 1, 0, false};
        EXPECT_TRUE(row.equals(stack_of(i, at[k].episode, 0))) << "masked reset, env " << i;
        EXPECT_TRUE(row.equals(singles[k]->reset().obs.array())) << "masked reset, env " << i;
        ++restarts;
      } else {
        EXPECT_TRUE(row.equals(before.array().index(i))) << "masked reset, env " << i;
      }
    }
  }
  EXPECT_GE(restarts, 9);
  if (mode() == AutoresetMode::kSameStep) {
    EXPECT_GE(finals, 9);
  }
}

INSTANTIATE_TEST_SUITE_P(
    SyncAndPool, FrameStackTest,
    ::testing::Combine(::testing::Values(0, 2),
                       ::testing::Values(AutoresetMode::kNextStep, AutoresetMode::kSameStep,
                                         AutoresetMode::kDisabled)),
    [](const ::testing::TestParamInfo<std::tuple<int, AutoresetMode>>& param_info) {
      const int threads = std::get<0>(param_info.param);
      return (threads == 0 ? std::string("Sync") : "Threads" + std::to_string(threads)) +
             autoreset_mode_name(std::get<1>(param_info.param));
    });

}  // namespace
}  // namespace pixelgym::vector
