// Same seeds and actions give byte-identical batches — pixels included — from SyncVectorEnv,
// from AsyncVectorEnv on 1, 2 and 4 threads, and from the envs stepped one by one with Env
// (with NextStep's autoreset done by hand), for 1, 3 and 8 envs; and under SameStep (final_obs
// included) and Disabled (the caller's masked resets) for 3 envs. Episodes are cut at 4 steps so
// that autoresets happen inside the 9 steps compared; renders are small to keep this quick.
// The pools alternate step() (worker 0's envs run on the calling thread) with step_async() +
// step_wait() (they run on worker thread 0), and the vector envs run with GL contexts shared per
// thread (their default) and, sync and on 2 threads, with a context per env. Workers 1-3 draw with
// private copies of Mesa (render::MesaCopy), so their frames are compared with copy 0's too.
// ProcessVectorEnv runs with 1, 2 and 3 workers under each autoreset mode, the calling process
// running worker 0 (its default) or every worker a child (a negative count below).
#include <gtest/gtest.h>

#include <cstdlib>
#include <optional>
#include <ostream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/async_vector_env.h"
#include "pixelgym/envs/vector/batch_space.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/render/context.h"
#include "pixelgym/render/mesa_copy.h"
#include "pixelgym/wrappers/wrapper_spec.h"

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

void PrintTo(const Case& c, std::ostream* os) {
  *os << c.id;
  for (const auto& [key, value] : c.kwargs) *os << " " << key << "=" << value.to_string();
  for (const std::string& wrapper : c.wrappers) *os << " --wrap " << wrapper;
}

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

std::string describe(VectorMode mode, int count) {
  switch (mode) {
    case VectorMode::kSync:
      return "sync";
    case VectorMode::kAsync:
      return std::to_string(count) + " threads";
    case VectorMode::kProcess:
      return std::to_string(std::abs(count)) +
             (count < 0 ? " workers, every one a child" : " workers, the caller's included");
  }
  return "";
}

class VectorDeterminismTest : public ::testing::TestWithParam<Case> {};

TEST_P(VectorDeterminismTest, SyncAndPoolsEqualSingleEnvsByteForByte) {
  const Case& c = GetParam();
  for (const int num_envs : {1, 3, 8}) {
    std::vector<Value> actions;
    {
      const auto probe =
          make_vec(c.id, num_envs, c.kwargs, pixelgym::wrappers::wrapping(c.wrappers));
      actions = batched_actions(probe->action_space());
    }
    const Trajectory expected = one_by_one(c, num_envs, actions);
    bool ended = false;
    for (const auto& row : expected) {
      for (const EnvStep& step : row) ended = ended || step.terminated || step.truncated;
    }
    EXPECT_TRUE(ended) << "no episode ended: the autoreset is not exercised";
    // {mode, threads or workers, shared GL contexts}
    const std::tuple<VectorMode, int, bool> runners[] = {
        {VectorMode::kSync, 0, true},    {VectorMode::kAsync, 1, true},
        {VectorMode::kAsync, 2, true},   {VectorMode::kAsync, 4, true},
        {VectorMode::kSync, 0, false},   {VectorMode::kAsync, 2, false},
        {VectorMode::kProcess, 1, true}, {VectorMode::kProcess, 2, true},
        {VectorMode::kProcess, 3, true}, {VectorMode::kProcess, -2, true}};
    for (const auto& [mode, threads, shared] : runners) {
      const std::string runner = std::to_string(num_envs) + " envs, " + describe(mode, threads) +
                                 (shared ? "" : ", a GL context per env");
      VectorOptions options{mode, threads, AutoresetMode::kNextStep, shared};
      options.num_workers = std::abs(threads);
      options.caller_steps_envs = threads >= 0;
      const auto env =
          make_vec(c.id, num_envs, c.kwargs, pixelgym::wrappers::wrapping(c.wrappers), options);
      auto* pool = dynamic_cast<AsyncVectorEnv*>(env.get());
      expect_same(expected, *env, env->reset(kSeed).obs, nullptr, 0, runner);
      for (int t = 0; t < kSteps; ++t) {
        const Value& actions_t = actions[static_cast<std::size_t>(t)];
        if (pool != nullptr && t % 2 == 1) {
          pool->step_async(actions_t);
          const VectorStepResult& step = pool->step_wait();
          expect_same(expected, *env, step.obs, &step, t + 1, runner + ", step_async");
        } else {
          const VectorStepResult& step = env->step(actions_t);
          expect_same(expected, *env, step.obs, &step, t + 1, runner);
        }
      }
    }
  }
  // With OSMesa, the pools of 2 and 4 threads drew with private copies 1-3 (each test runs in a
  // process of its own): the frames compared above came from them. (EGL has no copies.)
  if (!render::gl_backend_built(render::GlBackend::kOSMesa) ||
      render::requested_gl_backend(render::GlBackend::kAuto) == render::GlBackend::kEgl) {
    return;
  }
  for (const int copy : {1, 2, 3}) {
    EXPECT_TRUE(render::MesaCopy::loaded(copy)) << copy << ": " << render::MesaCopy::why_not(copy);
  }
}

// The envs one by one under SameStep's rule: a step that ends an episode comes back with the
// next episode's first observation (an unseeded reset), `final` holding the last one.
struct SameStepEnvStep {
  EnvStep step;
  std::optional<Value> final;  // none when the step ended no episode
};
std::vector<std::vector<SameStepEnvStep>> one_by_one_same_step(const Case& c, int num_envs,
                                                               const std::vector<Value>& actions) {
  std::vector<std::vector<SameStepEnvStep>> trajectory(kSteps + 1);
  for (int i = 0; i < num_envs; ++i) {
    std::unique_ptr<Env> env = wrappers::apply_wrappers(make(c.id, c.kwargs), c.wrappers);
    trajectory[0].push_back({{env->reset(kSeed + static_cast<std::uint64_t>(i)).obs.clone()}, {}});
    for (int t = 0; t < kSteps; ++t) {
      const StepResult result = env->step(batch_slot(actions[static_cast<std::size_t>(t)], i));
      SameStepEnvStep step{{result.obs.clone(), result.reward, result.terminated, result.truncated},
                           {}};
      if (result.terminated || result.truncated) {
        step.final = std::move(step.step.obs);
        step.step.obs = env->reset().obs.clone();
      }
      trajectory[static_cast<std::size_t>(t) + 1].push_back(std::move(step));
    }
  }
  return trajectory;
}

// SameStep and Disabled, on the same envs: the vector envs' batches, final observations and
// masked resets equal the envs stepped one by one, byte for byte, sync and on 1, 2 and 4 threads.
TEST_P(VectorDeterminismTest, SameStepAndDisabledEqualSingleEnvsByteForByte) {
  const Case& c = GetParam();
  const int num_envs = 3;
  std::vector<Value> actions;
  {
    const auto probe = make_vec(c.id, num_envs, c.kwargs, pixelgym::wrappers::wrapping(c.wrappers));
    actions = batched_actions(probe->action_space());
  }
  const auto expected = one_by_one_same_step(c, num_envs, actions);
  const std::pair<VectorMode, int> runners[] = {
      {VectorMode::kSync, 0},  {VectorMode::kAsync, 1},   {VectorMode::kAsync, 2},
      {VectorMode::kAsync, 4}, {VectorMode::kProcess, 2}, {VectorMode::kProcess, 3}};
  for (const AutoresetMode autoreset : {AutoresetMode::kSameStep, AutoresetMode::kDisabled}) {
    for (const auto& [mode, threads] : runners) {
      const std::string runner =
          std::string(autoreset == AutoresetMode::kSameStep ? "SameStep, " : "Disabled, ") +
          describe(mode, threads);
      VectorOptions options{mode, threads, autoreset};
      options.num_workers = std::abs(threads);
      options.caller_steps_envs = threads >= 0;
      const auto env =
          make_vec(c.id, num_envs, c.kwargs, pixelgym::wrappers::wrapping(c.wrappers), options);
      const Value& first = env->reset(kSeed).obs;
      for (int i = 0; i < num_envs; ++i) {
        EXPECT_TRUE(batch_slot(first, i).equals(expected[0][static_cast<std::size_t>(i)].step.obs))
            << runner << ", the reset, env " << i;
      }
      int finals = 0;
      for (int t = 0; t < kSteps; ++t) {
        const VectorStepResult& step = env->step(actions[static_cast<std::size_t>(t)]);
        Array reset_mask(DType::kBool, {num_envs});
        bool any_done = false;
        for (int i = 0; i < num_envs; ++i) {
          const SameStepEnvStep& want =
              expected[static_cast<std::size_t>(t) + 1][static_cast<std::size_t>(i)];
          const std::string where =
              runner + ", step " + std::to_string(t + 1) + ", env " + std::to_string(i);
          EXPECT_EQ(step.rewards.data<double>()[i], want.step.reward) << where;
          EXPECT_EQ(step.terminated.data<bool>()[i], want.step.terminated) << where;
          EXPECT_EQ(step.truncated.data<bool>()[i], want.step.truncated) << where;
          const bool done = want.final.has_value();
          if (autoreset == AutoresetMode::kDisabled) {
            // The step returns the last observation; the caller resets by mask below.
            EXPECT_TRUE(batch_slot(step.obs, i).equals(done ? *want.final : want.step.obs))
                << where;
            reset_mask.data<bool>()[i] = done;
            any_done = any_done || done;
            continue;
          }
          EXPECT_TRUE(batch_slot(step.obs, i).equals(want.step.obs)) << where;
          const bool has_final = step.infos.contains("_final_obs") &&
                                 step.infos.at("_final_obs").array().data<bool>()[i];
          EXPECT_EQ(has_final, done) << where;
          if (done && has_final) {
            EXPECT_TRUE(batch_slot(step.infos.at("final_obs"), i).equals(*want.final)) << where;
            ++finals;
          }
        }
        if (any_done) {
          const Value& reset = env->reset(std::nullopt, {}, reset_mask).obs;
          for (int i = 0; i < num_envs; ++i) {
            if (!reset_mask.data<bool>()[i]) continue;
            EXPECT_TRUE(batch_slot(reset, i).equals(
                expected[static_cast<std::size_t>(t) + 1][static_cast<std::size_t>(i)].step.obs))
                << runner << ", the masked reset after step " << t + 1 << ", env " << i;
            ++finals;
          }
        }
      }
      EXPECT_GT(finals, 0) << runner << ": no episode ended, the autoreset is not exercised";
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
