// NormalizeObservation: running statistics against a direct computation, output, freeze,
// checkpoint round trip, Dict keys, errors. Also RunningStatistics' checkpoint form.
#include "pixelgym/wrappers/normalize_observation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <vector>

#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "tests/wrappers/scripted_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::box;
using testing::ScriptedEnv;

constexpr double kInf = std::numeric_limits<double>::infinity();

SpacePtr dict_space() {
  return std::make_shared<spaces::Dict>(
      spaces::Dict::Entries{{"pixels", box(0.0, 255.0, {2, 2, 3}, DType::kUInt8)},
                            {"joints", box(-10.0, 10.0, {3}, DType::kFloat64)},
                            {"mode", std::make_shared<spaces::Discrete>(3)}});
}

// Runs `steps` steps (resetting at episode ends) and returns the observations returned.
std::vector<Value> run(Env& env, int steps) {
  std::vector<Value> seen;
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  env.reset_into(reset, 1);
  seen.push_back(reset.obs.clone());
  StepResult step;
  step.obs = env.observation_space().zeros();
  for (int i = 0; i < steps; ++i) {
    env.step_into(env.action_space().zeros(), step);
    seen.push_back(step.obs.clone());
    if (step.terminated || step.truncated) {
      env.reset_into(reset);
      seen.push_back(reset.obs.clone());
    }
  }
  return seen;
}

// The statistics of `samples` (element `i` of each by `get`) pooled with the prior mean 0,
// var 1, count 1e-4, computed directly from sums: what RunningStatistics must match.
template <typename Get>
void expect_statistics(const RunningStatistics& statistics, std::size_t elements, std::size_t count,
                       const Get& get) {
  const double prior = RunningStatistics::kInitialCount;
  ASSERT_EQ(statistics.mean.size(), elements);
  EXPECT_NEAR(statistics.count, prior + static_cast<double>(count), 1e-9);
  for (std::size_t i = 0; i < elements; ++i) {
    double sum = 0.0;
    for (std::size_t k = 0; k < count; ++k) sum += get(k, i);
    const double sample_mean = sum / static_cast<double>(count);
    double squares = 0.0;
    for (std::size_t k = 0; k < count; ++k) {
      squares += (get(k, i) - sample_mean) * (get(k, i) - sample_mean);
    }
    const double n = static_cast<double>(count);
    const double total = n + prior;
    const double mean = sum / total;
    const double var =
        (squares + prior * 1.0 + sample_mean * sample_mean * prior * n / total) / total;
    EXPECT_NEAR(statistics.mean[i], mean, 1e-9 * (1.0 + std::abs(mean))) << "element " << i;
    EXPECT_NEAR(statistics.var[i], var, 1e-9 * (1.0 + var)) << "element " << i;
    // And close to the plain sample statistics.
    EXPECT_NEAR(statistics.mean[i], sample_mean, 1e-3 * (1.0 + std::abs(sample_mean)));
    EXPECT_NEAR(statistics.var[i], squares / n, 1e-3 * (1.0 + squares / n));
  }
}

TEST(NormalizeObservationTest, BareBoxSpace) {
  NormalizeObservation env(
      std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {2, 3}), box(-1.0, 1.0, {1})));
  EXPECT_TRUE(env.observation_space().equals(spaces::Box(-kInf, kInf, {2, 3}, DType::kFloat32)));
  EXPECT_EQ(env.statistics().mean, std::vector<double>(6, 0.0));
  EXPECT_EQ(env.statistics().var, std::vector<double>(6, 1.0));
  EXPECT_EQ(env.statistics().count, 1e-4);
  EXPECT_TRUE(env.update_statistics());
  EXPECT_EQ(env.name(), "NormalizeObservation<ScriptedEnv>");
}

TEST(NormalizeObservationTest, StatisticsMatchADirectComputationAndOutputUsesThem) {
  auto inner = std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {3}), box(-1.0, 1.0, {1}), 7);
  inner->offset = 3.0;
  inner->scale = 2.0;
  ScriptedEnv* probe = inner.get();
  NormalizeObservation env(std::move(inner));
  const std::vector<Value> seen = run(env, 40);
  const std::vector<Value>& raw = probe->observations;  // resets included, as Gymnasium
  ASSERT_EQ(raw.size(), seen.size());
  expect_statistics(env.statistics(), 3, raw.size(), [&](std::size_t k, std::size_t i) {
    return static_cast<double>(raw[k].array().data<float>()[i]);
  });
  // The last output is normalized with the final statistics.
  const RunningStatistics& s = env.statistics();
  for (std::size_t i = 0; i < 3; ++i) {
    const double x = raw.back().array().data<float>()[i];
    EXPECT_FLOAT_EQ(seen.back().array().data<float>()[i],
                    static_cast<float>((x - s.mean[i]) / std::sqrt(s.var[i] + 1e-8)));
  }
  // Normalized by statistics near the true ones (mean 3, var 4/3): about zero mean, unit var.
  EXPECT_NEAR(s.mean[0], 3.0, 0.5);
  EXPECT_NEAR(s.var[0], 4.0 / 3.0, 0.6);
}

TEST(NormalizeObservationTest, DictKeyOfIntegersLeavesTheOtherKeys) {
  auto inner = std::make_unique<ScriptedEnv>(dict_space(), box(-1.0, 1.0, {1}));
  ScriptedEnv* probe = inner.get();
  NormalizeObservation env(std::move(inner), "pixels", 1e-3);
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(-kInf, kInf, {2, 2, 3}, DType::kFloat32)));
  EXPECT_TRUE(dict.at("joints").equals(*box(-10.0, 10.0, {3}, DType::kFloat64)));
  EXPECT_EQ(dict.index("pixels"), 0U);
  const std::vector<Value> seen = run(env, 12);
  const std::vector<Value>& raw = probe->observations;
  expect_statistics(env.statistics(), 12, raw.size(), [&](std::size_t k, std::size_t i) {
    return static_cast<double>(raw[k].dict().at("pixels").array().data<std::uint8_t>()[i]);
  });
  EXPECT_TRUE(seen.back().dict().at("joints").equals(raw.back().dict().at("joints")));
  EXPECT_TRUE(seen.back().dict().at("mode").equals(raw.back().dict().at("mode")));
  const double x = raw.back().dict().at("pixels").array().data<std::uint8_t>()[5];
  const RunningStatistics& s = env.statistics();
  EXPECT_FLOAT_EQ(seen.back().dict().at("pixels").array().data<float>()[5],
                  static_cast<float>((x - s.mean[5]) / std::sqrt(s.var[5] + 1e-3)));
}

TEST(NormalizeObservationTest, FrozenStatisticsStayAndStillNormalize) {
  auto inner = std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {2}), box(-1.0, 1.0, {1}));
  inner->offset = -4.0;
  ScriptedEnv* probe = inner.get();
  NormalizeObservation env(std::move(inner));
  run(env, 20);
  const RunningStatistics before = env.statistics();
  env.set_update_statistics(false);
  EXPECT_FALSE(env.update_statistics());
  const std::vector<Value> seen = run(env, 20);
  EXPECT_EQ(env.statistics().mean, before.mean);
  EXPECT_EQ(env.statistics().var, before.var);
  EXPECT_EQ(env.statistics().count, before.count);
  const double x = probe->observations.back().array().data<float>()[1];
  EXPECT_FLOAT_EQ(seen.back().array().data<float>()[1],
                  static_cast<float>((x - before.mean[1]) / std::sqrt(before.var[1] + 1e-8)));
  env.set_update_statistics(true);
  run(env, 1);
  EXPECT_GT(env.statistics().count, before.count);
}

TEST(NormalizeObservationTest, StatisticsRoundTripThroughTheCheckpointForm) {
  NormalizeObservation env(
      std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {3}), box(-1.0, 1.0, {1})));
  run(env, 15);
  const Value checkpoint = env.statistics().to_value();
  EXPECT_EQ(checkpoint.dict().at("mean").array().dtype(), DType::kFloat64);
  EXPECT_EQ(checkpoint.dict().at("mean").array().shape(), (Shape{3}));
  EXPECT_EQ(checkpoint.dict().at("count").array().shape(), (Shape{}));

  NormalizeObservation fresh(
      std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {3}), box(-1.0, 1.0, {1})));
  fresh.set_statistics(RunningStatistics::from_value(checkpoint, 3, "test"));
  EXPECT_EQ(fresh.statistics().mean, env.statistics().mean);  // exact
  EXPECT_EQ(fresh.statistics().var, env.statistics().var);
  EXPECT_EQ(fresh.statistics().count, env.statistics().count);
  // Both now normalize the same observation the same way.
  fresh.set_update_statistics(false);
  env.set_update_statistics(false);
  EXPECT_TRUE(testing::reset_and_step(fresh).equals(testing::reset_and_step(env)));
}

TEST(NormalizeObservationTest, RefusesBadStatistics) {
  NormalizeObservation env(
      std::make_unique<ScriptedEnv>(box(-10.0, 10.0, {2}), box(-1.0, 1.0, {1})));
  RunningStatistics wrong_size = RunningStatistics::initial(3);
  testing::expect_invalid([&] { env.set_statistics(wrong_size); },
                          {"NormalizeObservation", "2 elements", "mean has 3 entries"});
  RunningStatistics negative = RunningStatistics::initial(2);
  negative.var[1] = -1.0;
  testing::expect_invalid([&] { env.set_statistics(negative); }, {"var[1] is -1", ">= 0"});
  RunningStatistics nan = RunningStatistics::initial(2);
  nan.mean[0] = std::nan("");
  testing::expect_invalid([&] { env.set_statistics(nan); }, {"mean[0] is nan", "finite"});
  RunningStatistics zero_count = RunningStatistics::initial(2);
  zero_count.count = 0.0;
  testing::expect_invalid([&] { env.set_statistics(zero_count); }, {"count is 0", "> 0"});
  EXPECT_EQ(env.statistics().var, std::vector<double>(2, 1.0));  // unchanged

  testing::expect_invalid([] { RunningStatistics::from_value(Array::scalar(1.0), 2, "ctx"); },
                          {"ctx", "Dict", "array"});
  Value value = RunningStatistics::initial(2).to_value();
  value.dict().insert("mean", Array::from_vector<float>({2}, {0.0F, 0.0F}));
  testing::expect_invalid([&] { RunningStatistics::from_value(value, 2, "ctx"); },
                          {"ctx", "\"mean\" must be float64 (2,)", "float32 (2,)"});
  testing::expect_invalid(
      [] { RunningStatistics::from_value(RunningStatistics::initial(2).to_value(), 4, "ctx"); },
      {"ctx", "float64 (4,)"});
  Value negative_value = negative.to_value();
  testing::expect_invalid([&] { RunningStatistics::from_value(negative_value, 2, "ctx"); },
                          {"ctx", "var[1] is -1"});
}

TEST(NormalizeObservationTest, RefusesNonBoxKeysAndBadArguments) {
  const auto dict_env = [] {
    return std::make_unique<ScriptedEnv>(dict_space(), box(-1.0, 1.0, {1}));
  };
  testing::expect_invalid([&] { NormalizeObservation env(dict_env(), "mode"); },
                          {"NormalizeObservation", "\"mode\" must be a Box", "Discrete(3)",
                           "Box keys: \"pixels\", \"joints\""});
  testing::expect_invalid([&] { NormalizeObservation env(dict_env(), "velocity"); },
                          {"NormalizeObservation", "\"velocity\" is not in"});
  testing::expect_invalid([&] { NormalizeObservation env(dict_env()); },
                          {"NormalizeObservation", "a key is needed"});
  testing::expect_invalid(
      [] {
        NormalizeObservation env(
            std::make_unique<ScriptedEnv>(box(0.0, 1.0, {2}), box(-1.0, 1.0, {1})), "pixels");
      },
      {"NormalizeObservation", "bare Box"});
  testing::expect_invalid(
      [] {
        NormalizeObservation env(std::make_unique<ScriptedEnv>(
            std::make_shared<spaces::Discrete>(4), box(-1.0, 1.0, {1})));
      },
      {"NormalizeObservation", "must be a Box or a Dict", "Discrete(4)"});
  testing::expect_invalid(
      [] {
        NormalizeObservation env(
            std::make_unique<ScriptedEnv>(box(0.0, 1.0, {2}), box(-1.0, 1.0, {1})), "", 0.0);
      },
      {"NormalizeObservation", "epsilon must be finite and > 0, got 0"});
}

}  // namespace
}  // namespace pixelgym::wrappers
