// vector::NormalizeObservation against a direct computation: after every call its statistics
// are the mean and variance of every observation the scripted envs returned (pooled with the
// prior), and every row it returns is that row normalized with them, in each autoreset mode
// (SameStep's final_obs included, Disabled's masked resets included), in SyncVectorEnv and
// AsyncVectorEnv (2 threads). A batch of one env is the per-env wrapper bit for bit.
#include "pixelgym/wrappers/vector/normalize_observation.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/vector/batch_space.h"
#include "pixelgym/wrappers/normalize_observation.h"
#include "tests/envs/vector/vector_test_util.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::vector {
namespace {

using testing::scripted_actions;
using wrappers::RunningStatistics;

constexpr double kEpsilon = 1e-8;

// The Box a test normalizes in a recorded observation: the array itself, or its "state".
const Array& box_in(const Value& observation) {
  return observation.is_dict() ? observation.dict().at("state").array() : observation.array();
}

// Every observation env i returned, oldest first (the scripted env records each).
const std::vector<Value>& returned(const testing::ScriptedVector& made, int i) {
  return made.scripted[static_cast<std::size_t>(i)]->observations;
}

// The statistics of every observation every env returned so far, computed directly: the
// samples pooled with the prior (mean 0, var 1, count 1e-4).
RunningStatistics direct(const testing::ScriptedVector& made, std::size_t size) {
  std::vector<const Array*> samples;
  for (int i = 0; i < static_cast<int>(made.scripted.size()); ++i) {
    for (const Value& observation : returned(made, i)) samples.push_back(&box_in(observation));
  }
  RunningStatistics out = RunningStatistics::initial(size);
  out.count = RunningStatistics::kInitialCount + static_cast<double>(samples.size());
  for (std::size_t e = 0; e < size; ++e) {
    double sum = 0.0;
    for (const Array* sample : samples) sum += sample->element_as_double(static_cast<int>(e));
    const double mean = sum / out.count;
    double squares = RunningStatistics::kInitialCount * (1.0 + mean * mean);
    for (const Array* sample : samples) {
      const double deviation = sample->element_as_double(static_cast<int>(e)) - mean;
      squares += deviation * deviation;
    }
    out.mean[e] = mean;
    out.var[e] = squares / out.count;
  }
  return out;
}

void expect_statistics(const RunningStatistics& got, const RunningStatistics& want,
                       const std::string& where) {
  EXPECT_NEAR(got.count, want.count, 1e-9) << where;
  for (std::size_t e = 0; e < want.mean.size(); ++e) {
    EXPECT_NEAR(got.mean[e], want.mean[e], 1e-9 * (1.0 + std::abs(want.mean[e]))) << where;
    EXPECT_NEAR(got.var[e], want.var[e], 1e-9 * want.var[e]) << where;
  }
}

// Expects `row` (float32) to be `raw` normalized with `statistics`.
void expect_normalized(const Array& row, const Array& raw, const RunningStatistics& statistics,
                       const std::string& where) {
  ASSERT_EQ(row.dtype(), DType::kFloat32) << where;
  ASSERT_EQ(row.size(), raw.size()) << where;
  for (std::int64_t e = 0; e < raw.size(); ++e) {
    const auto k = static_cast<std::size_t>(e);
    const double want =
        (raw.element_as_double(e) - statistics.mean[k]) / std::sqrt(statistics.var[k] + kEpsilon);
    EXPECT_NEAR(row.data<float>()[e], want, 1e-5 * (1.0 + std::abs(want)))
        << where << ", element " << e;
  }
}

// Scripted envs whose observations are float32 (3,) in [1, 5] (mean 3, so that a missing mean
// shows), episodes of `lengths`.
testing::ScriptedVector make_offset_vector(const std::vector<int>& lengths, AutoresetMode mode,
                                           int threads) {
  testing::ScriptedVector made = testing::make_scripted_vector(lengths, false, mode, threads);
  for (testing::ScriptedEnv* env : made.scripted) {
    env->offset = 3.0;
    env->scale = 2.0;
  }
  return made;
}

std::string mode_text(AutoresetMode mode) { return autoreset_mode_name(mode); }

class NormalizeObservationTest : public ::testing::TestWithParam<std::tuple<int, AutoresetMode>> {
 protected:
  int threads() const { return std::get<0>(GetParam()); }
  AutoresetMode mode() const { return std::get<1>(GetParam()); }
};

TEST_P(NormalizeObservationTest, NormalizesWithTheStatisticsOfEveryObservationReturned) {
  const std::vector<int> lengths{2, 3, 5};
  testing::ScriptedVector made = make_offset_vector(lengths, mode(), threads());
  NormalizeObservation env(std::move(made.env));
  const VectorResetResult& reset = env.reset(11);
  RunningStatistics want = direct(made, 3);
  expect_statistics(env.statistics(), want, "reset");
  for (int i = 0; i < 3; ++i) {
    expect_normalized(reset.obs.array().index(i), box_in(returned(made, i).back()), want,
                      "reset, env " + std::to_string(i));
  }
  int final_rows = 0;
  int masked_resets = 0;
  for (int step = 1; step <= 16; ++step) {
    const VectorStepResult& result = env.step(scripted_actions(3, 0.1F));
    const std::string where = mode_text(mode()) + " step " + std::to_string(step);
    want = direct(made, 3);
    expect_statistics(env.statistics(), want, where);
    std::vector<bool> done(3);
    for (int i = 0; i < 3; ++i) {
      done[static_cast<std::size_t>(i)] =
          result.terminated.data<bool>()[i] || result.truncated.data<bool>()[i];
      expect_normalized(result.obs.array().index(i), box_in(returned(made, i).back()), want,
                        where + ", env " + std::to_string(i));
    }
    const bool any_done = done[0] || done[1] || done[2];
    ASSERT_EQ(result.infos.contains("final_obs"), mode() == AutoresetMode::kSameStep && any_done)
        << where;
    if (result.infos.contains("final_obs")) {
      const Value& final_obs = result.infos.at("final_obs");
      for (int i = 0; i < 3; ++i) {
        const Array row = final_obs.array().index(i);
        EXPECT_EQ(result.infos.at("_final_obs").array().data<bool>()[i],
                  done[static_cast<std::size_t>(i)]);
        if (done[static_cast<std::size_t>(i)]) {
          // The episode's last observation: the one before the reset's.
          const auto& all = returned(made, i);
          expect_normalized(row, box_in(all[all.size() - 2]), want,
                            where + ", final_obs of env " + std::to_string(i));
          ++final_rows;
        } else {
          EXPECT_TRUE(row.equals(Array(DType::kFloat32, {3}))) << where;
        }
      }
    }
    if (mode() == AutoresetMode::kDisabled && any_done) {
      // Reset exactly the envs that ended: only their rows change and are merged.
      const Value before = result.obs.clone();
      const Array mask = Array::from_vector<bool>({3}, {done[0], done[1], done[2]});
      const VectorResetResult& partial = env.reset(std::nullopt, {}, mask);
      want = direct(made, 3);
      expect_statistics(env.statistics(), want, where + " masked reset");
      for (int i = 0; i < 3; ++i) {
        if (done[static_cast<std::size_t>(i)]) {
          expect_normalized(partial.obs.array().index(i), box_in(returned(made, i).back()), want,
                            where + " masked reset, env " + std::to_string(i));
        } else {
          EXPECT_TRUE(partial.obs.array().index(i).equals(before.array().index(i))) << where;
        }
      }
      ++masked_resets;
    }
  }
  if (mode() == AutoresetMode::kSameStep) {
    EXPECT_GE(final_rows, 10);
  }
  if (mode() == AutoresetMode::kDisabled) {
    EXPECT_GE(masked_resets, 5);
  }
}

TEST_P(NormalizeObservationTest, FreezingKeepsTheStatistics) {
  testing::ScriptedVector made = make_offset_vector({2, 3}, mode(), threads());
  NormalizeObservation env(std::move(made.env));
  env.reset(3);
  env.step(scripted_actions(2, 0.1F));
  const RunningStatistics frozen = env.statistics();
  env.set_update_statistics(false);
  EXPECT_FALSE(env.update_statistics());
  const VectorStepResult& result = env.step(scripted_actions(2, 0.2F));
  EXPECT_EQ(env.statistics().mean, frozen.mean);
  EXPECT_EQ(env.statistics().var, frozen.var);
  EXPECT_EQ(env.statistics().count, frozen.count);
  expect_normalized(result.obs.array().index(1), box_in(returned(made, 1).back()), frozen,
                    "frozen");
}

TEST(NormalizeObservationSingleTest, OneEnvIsThePerEnvWrapperBitForBit) {
  testing::ScriptedVector made = make_offset_vector({3}, AutoresetMode::kNextStep, 0);
  NormalizeObservation vector(std::move(made.env));
  auto scripted = std::make_unique<testing::ScriptedEnv>(testing::box(-10.0, 10.0, {3}),
                                                         testing::box(-1.0, 1.0, {1}), 3);
  scripted->offset = 3.0;
  scripted->scale = 2.0;
  wrappers::NormalizeObservation single(std::move(scripted));
  EXPECT_TRUE(vector.reset(7).obs.array().index(0).equals(single.reset(7).obs.array()));
  bool ended = false;
  for (int step = 0; step < 12; ++step) {
    const Value action = scripted_actions(1, 0.5F);
    const VectorStepResult& result = vector.step(action);
    // NextStep: the step after a done is the reset.
    Value obs;
    if (ended) {
      obs = single.reset().obs;
      ended = false;
    } else {
      const StepResult stepped = single.step(action.array().index(0));
      obs = stepped.obs;
      ended = stepped.terminated;
    }
    EXPECT_TRUE(result.obs.array().index(0).equals(obs.array())) << "step " << step;
    EXPECT_EQ(vector.statistics().mean, single.statistics().mean) << "step " << step;
    EXPECT_EQ(vector.statistics().var, single.statistics().var) << "step " << step;
    EXPECT_EQ(vector.statistics().count, single.statistics().count) << "step " << step;
  }
}

TEST(NormalizeObservationSingleTest, NormalizesOneDictKeyAndPassesTheOthers) {
  const SpacePtr space = std::make_shared<spaces::Dict>(spaces::Dict::Entries{
      {"pixels", std::make_shared<spaces::Box>(0.0, 255.0, Shape{2, 2, 3}, DType::kUInt8)},
      {"state", testing::box(-10.0, 10.0, {3})},
  });
  testing::ScriptedVector made;
  made.scripted.resize(2);
  const EnvFactory factory = [&](int i) {
    auto env = std::make_unique<testing::ScriptedEnv>(space, testing::box(-1.0, 1.0, {1}), 2);
    env->offset = 3.0;
    made.scripted[static_cast<std::size_t>(i)] = env.get();
    return env;
  };
  NormalizeObservation env(std::make_unique<SyncVectorEnv>(2, factory, AutoresetMode::kSameStep),
                           "state");
  EXPECT_EQ(env.key(), "state");
  const double inf = std::numeric_limits<double>::infinity();
  const auto& single = dynamic_cast<const spaces::Dict&>(env.single_observation_space());
  EXPECT_TRUE(single.at("state").equals(spaces::Box(-inf, inf, {3}, DType::kFloat32)));
  EXPECT_TRUE(single.at("pixels").equals(dynamic_cast<const spaces::Dict&>(*space).at("pixels")));
  EXPECT_TRUE(env.observation_space().equals(*batch_space(single, 2)));
  env.reset(1);
  for (int step = 0; step < 3; ++step) {
    const VectorStepResult& result = env.step(scripted_actions(2, 0.1F));
    const RunningStatistics want = direct(made, 3);
    expect_statistics(env.statistics(), want, "step " + std::to_string(step));
    for (int i = 0; i < 2; ++i) {
      const Value& latest = returned(made, i).back();
      expect_normalized(result.obs.dict().at("state").array().index(i), box_in(latest), want,
                        "state");
      EXPECT_TRUE(result.obs.dict().at("pixels").array().index(i).equals(
          latest.dict().at("pixels").array()));
    }
    if (step == 1) {  // both episodes end: final_obs holds both keys, "state" normalized
      const Value& final_obs = result.infos.at("final_obs");
      const auto& all = returned(made, 0);
      expect_normalized(final_obs.dict().at("state").array().index(0), box_in(all[all.size() - 2]),
                        want, "final state");
      EXPECT_TRUE(final_obs.dict().at("pixels").array().index(0).equals(
          all[all.size() - 2].dict().at("pixels").array()));
    }
  }
}

TEST(NormalizeObservationSingleTest, StatisticsRoundTripAndAreChecked) {
  NormalizeObservation env(make_offset_vector({2, 3}, AutoresetMode::kNextStep, 0).env);
  env.reset(1);
  env.step(scripted_actions(2, 0.1F));
  const RunningStatistics saved =
      RunningStatistics::from_value(env.statistics().to_value(), 3, "test");
  env.step(scripted_actions(2, 0.2F));
  env.set_statistics(saved);
  EXPECT_EQ(env.statistics().mean, saved.mean);
  EXPECT_EQ(env.statistics().count, saved.count);
  RunningStatistics bad = saved;
  bad.var[1] = -1.0;
  testing::expect_invalid([&] { env.set_statistics(bad); },
                          {"NormalizeObservation", "3 elements", "var[1]"});
  testing::expect_invalid([&] { env.set_statistics(RunningStatistics::initial(4)); },
                          {"NormalizeObservation", "3 elements expected"});
  EXPECT_EQ(env.statistics().mean, saved.mean);
}

TEST(NormalizeObservationSingleTest, RefusesBadArguments) {
  const auto scripted = [] {
    return testing::make_scripted_vector({2}, false, AutoresetMode::kNextStep).env;
  };
  testing::expect_invalid([&] { NormalizeObservation env(scripted(), "", 0.0); },
                          {"NormalizeObservation", "epsilon", "got 0"});
  testing::expect_invalid([&] { NormalizeObservation env(scripted(), "pixels"); },
                          {"NormalizeObservation", "pixels"});
}

INSTANTIATE_TEST_SUITE_P(
    SyncAndPool, NormalizeObservationTest,
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
