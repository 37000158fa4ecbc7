// vector::RecordEpisodeStatistics against the scripted episodes: env i's episodes last lengths[i]
// steps with rewards 0.5, 0.25, 0.125, ... by step, so every episode it reports must have that
// length and that return, at the steps each autoreset mode ends episodes on, and no other. In
// SyncVectorEnv and AsyncVectorEnv (2 threads), for terminated and for truncated episodes.
#include "pixelgym/wrappers/vector/record_episode_statistics.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "pixelgym/wrappers/record_episode_statistics.h"
#include "tests/envs/vector/vector_test_util.h"

namespace pixelgym::vector {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using testing::scripted_actions;

// The return of a scripted episode of `length` steps.
double scripted_return(int length) {
  const std::vector<double> rewards{0.5, 0.25, 0.125, 0.0625, 0.03125};
  double sum = 0.0;
  for (int t = 0; t < length; ++t) sum += rewards[static_cast<std::size_t>(t) % rewards.size()];
  return sum;
}

// What one step reported: per env, whether an episode ended and its "r", "l", "t".
struct Reported {
  std::vector<bool> mask;
  std::vector<double> r;
  std::vector<std::int64_t> l;
  std::vector<double> t;
};

// Reads infos[key] / infos["_" + key]; nullopt when absent (checking both go together). The
// vector wrapper's Dict has exactly "r", "l", "t"; `per_env`: the per-env wrapper's, batched by
// the vector env, also has their masks ("_r", ...).
std::optional<Reported> reported(const Info& infos, int n, const std::string& key = "episode",
                                 bool per_env = false) {
  EXPECT_EQ(infos.contains(key), infos.contains("_" + key));
  if (!infos.contains(key)) return std::nullopt;
  const ValueDict& stats = infos.at(key).dict();
  if (per_env) {
    EXPECT_THAT(stats.keys(), ElementsAre("r", "_r", "l", "_l", "t", "_t"));
  } else {
    EXPECT_THAT(stats.keys(), ElementsAre("r", "l", "t"));
  }
  const Array& mask = infos.at("_" + key).array();
  EXPECT_EQ(mask.dtype(), DType::kBool);
  EXPECT_EQ(stats.at("r").array().dtype(), DType::kFloat64);
  EXPECT_EQ(stats.at("l").array().dtype(), DType::kInt64);
  EXPECT_EQ(stats.at("t").array().dtype(), DType::kFloat64);
  Reported out;
  for (int i = 0; i < n; ++i) {
    out.mask.push_back(mask.data<bool>()[i]);
    out.r.push_back(stats.at("r").array().data<double>()[i]);
    out.l.push_back(stats.at("l").array().data<std::int64_t>()[i]);
    out.t.push_back(stats.at("t").array().data<double>()[i]);
  }
  return out;
}

class RecordEpisodeStatisticsTest : public ::testing::TestWithParam<std::tuple<int, bool>> {
 protected:
  int threads() const { return std::get<0>(GetParam()); }
  bool truncate() const { return std::get<1>(GetParam()); }
  std::unique_ptr<RecordEpisodeStatistics> make(const std::vector<int>& lengths, AutoresetMode mode,
                                                std::int64_t buffer_length = 100) {
    testing::ScriptedVector made =
        testing::make_scripted_vector(lengths, truncate(), mode, threads());
    return std::make_unique<RecordEpisodeStatistics>(std::move(made.env), buffer_length);
  }
};

TEST_P(RecordEpisodeStatisticsTest, NextStepStepByStep) {
  const auto env = make({2, 3}, AutoresetMode::kNextStep);
  env->reset(1);
  // Step 1: nothing ends.
  EXPECT_FALSE(reported(env->step(scripted_actions(2, 0.1F)).infos, 2));
  EXPECT_THAT(env->episode_lengths(), ElementsAre(1, 1));
  // Step 2: env 0's episode ends after 2 steps.
  const auto start = std::chrono::steady_clock::now();
  const VectorStepResult& second = env->step(scripted_actions(2, 0.2F));
  std::optional<Reported> got = reported(second.infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(true, false));
  EXPECT_THAT(got->r, ElementsAre(0.75, 0.0));
  EXPECT_THAT(got->l, ElementsAre(2, 0));
  EXPECT_GT(got->t[0], 0.0);
  EXPECT_EQ(got->t[1], 0.0);
  EXPECT_TRUE(second.infos.contains("t"));  // the inner env's infos are kept
  // Step 3: env 0's reset step (no episode step); env 1's episode ends after 3 steps.
  got = reported(env->step(scripted_actions(2, 0.3F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(false, true));
  EXPECT_THAT(got->r, ElementsAre(0.0, 0.875));
  EXPECT_THAT(got->l, ElementsAre(0, 3));
  EXPECT_THAT(env->episode_lengths(), ElementsAre(0, 3));
  // Step 4: env 0's first step of its second episode; env 1's reset step.
  EXPECT_FALSE(reported(env->step(scripted_actions(2, 0.4F)).infos, 2));
  EXPECT_THAT(env->episode_lengths(), ElementsAre(1, 0));
  EXPECT_THAT(env->episode_returns(), ElementsAre(0.5, 0.0));
  // Step 5: env 0's second episode ends, again after 2 steps.
  got = reported(env->step(scripted_actions(2, 0.5F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(true, false));
  EXPECT_THAT(got->l, ElementsAre(2, 0));
  EXPECT_LT(got->t[0],
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  EXPECT_EQ(env->episode_count(), 3);
  EXPECT_THAT(env->length_queue(), ElementsAre(2, 3, 2));
  EXPECT_THAT(env->return_queue(), ElementsAre(0.75, 0.875, 0.75));
  EXPECT_EQ(env->time_queue().size(), 3U);
}

TEST_P(RecordEpisodeStatisticsTest, SameStepStepByStep) {
  const auto env = make({2, 3}, AutoresetMode::kSameStep);
  env->reset(1);
  EXPECT_FALSE(reported(env->step(scripted_actions(2, 0.1F)).infos, 2));
  // Step 2: env 0 ends (and is reset in the same step).
  std::optional<Reported> got = reported(env->step(scripted_actions(2, 0.2F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(true, false));
  EXPECT_THAT(got->l, ElementsAre(2, 0));
  EXPECT_THAT(env->episode_lengths(), ElementsAre(0, 2));
  // Step 3: env 0's first step of its second episode; env 1 ends.
  got = reported(env->step(scripted_actions(2, 0.3F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(false, true));
  EXPECT_THAT(got->r, ElementsAre(0.0, 0.875));
  EXPECT_THAT(got->l, ElementsAre(0, 3));
  // Step 4: env 0's second episode ends after its 2 steps.
  got = reported(env->step(scripted_actions(2, 0.4F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(true, false));
  EXPECT_THAT(got->r, ElementsAre(0.75, 0.0));
  EXPECT_THAT(got->l, ElementsAre(2, 0));
}

// Over many steps every reported episode is a scripted one, reported at the steps the mode ends
// episodes on: NextStep, the k-th episode of length L ends at step k (L + 1) - 1 (each reset takes
// a step); SameStep at step k L.
TEST_P(RecordEpisodeStatisticsTest, EveryEpisodeOfALongRunIsReportedAsScripted) {
  const std::vector<int> lengths{2, 3, 5};
  for (const AutoresetMode mode : {AutoresetMode::kNextStep, AutoresetMode::kSameStep}) {
    const auto env = make(lengths, mode, 1000);
    env->reset(3);
    std::vector<double> returns;
    std::vector<std::int64_t> episode_lengths;
    for (int step = 1; step <= 40; ++step) {
      const std::optional<Reported> got = reported(env->step(scripted_actions(3, 0.1F)).infos, 3);
      for (int i = 0; i < 3; ++i) {
        const int length = lengths[static_cast<std::size_t>(i)];
        const int period = mode == AutoresetMode::kNextStep ? length + 1 : length;
        const bool ends =
            mode == AutoresetMode::kNextStep ? (step + 1) % period == 0 : step % period == 0;
        const bool was_reported = got && got->mask[static_cast<std::size_t>(i)];
        EXPECT_EQ(was_reported, ends)
            << autoreset_mode_name(mode) << " step " << step << " env " << i;
        if (!was_reported) continue;
        EXPECT_EQ(got->l[static_cast<std::size_t>(i)], length);
        EXPECT_DOUBLE_EQ(got->r[static_cast<std::size_t>(i)], scripted_return(length));
        returns.push_back(scripted_return(length));
        episode_lengths.push_back(length);
      }
    }
    EXPECT_EQ(env->episode_count(), static_cast<std::int64_t>(episode_lengths.size()));
    EXPECT_EQ(env->length_queue(), episode_lengths);
    EXPECT_EQ(env->return_queue(), returns);
  }
}

TEST_P(RecordEpisodeStatisticsTest, DisabledRestartsOnlyTheMaskedEnvsCounters) {
  const auto env = make({2, 3}, AutoresetMode::kDisabled);
  env->reset(1);
  env->step(scripted_actions(2, 0.1F));
  std::optional<Reported> got = reported(env->step(scripted_actions(2, 0.2F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->l, ElementsAre(2, 0));
  EXPECT_THROW(env->step(scripted_actions(2, 0.3F)), ResetNeeded);
  // Env 0 restarts; env 1 keeps counting and ends its 3-step episode at the next step.
  env->reset(std::nullopt, {}, Array::from_vector<bool>({2}, {true, false}));
  EXPECT_THAT(env->episode_lengths(), ElementsAre(0, 2));
  got = reported(env->step(scripted_actions(2, 0.3F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(false, true));
  EXPECT_THAT(got->l, ElementsAre(0, 3));
  EXPECT_THAT(got->r, ElementsAre(0.0, 0.875));
  env->reset(std::nullopt, {}, Array::from_vector<bool>({2}, {false, true}));
  got = reported(env->step(scripted_actions(2, 0.4F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->mask, ElementsAre(true, false));
  EXPECT_THAT(got->l, ElementsAre(2, 0));
  EXPECT_THAT(env->length_queue(), ElementsAre(2, 3, 2));
  // A full reset mid-episode restarts every env's counters.
  env->reset(std::nullopt, {}, Array::from_vector<bool>({2}, {true, false}));
  env->step(scripted_actions(2, 0.5F));
  env->reset();
  EXPECT_THAT(env->episode_lengths(), ElementsAre(0, 0));
  env->step(scripted_actions(2, 0.6F));
  got = reported(env->step(scripted_actions(2, 0.7F)).infos, 2);
  ASSERT_TRUE(got);
  EXPECT_THAT(got->l, ElementsAre(2, 0));
}

TEST_P(RecordEpisodeStatisticsTest, KeepsTheLastBufferLengthEpisodesInEnvOrder) {
  // SameStep, lengths 2 and 4: episodes end at steps 2 (env 0), 4 (0, 1), 6 (0), 8 (0, 1).
  const auto env = make({2, 4}, AutoresetMode::kSameStep, 3);
  env->reset(1);
  for (int step = 0; step < 8; ++step) env->step(scripted_actions(2, 0.1F));
  EXPECT_EQ(env->episode_count(), 6);
  EXPECT_THAT(env->length_queue(), ElementsAre(2, 2, 4));
  EXPECT_THAT(env->return_queue(), ElementsAre(0.75, 0.75, scripted_return(4)));
  EXPECT_EQ(env->time_queue().size(), 3U);
}

TEST_P(RecordEpisodeStatisticsTest, InfosKeptFromAnEarlierStepStayUnchanged) {
  const auto env = make({2, 2}, AutoresetMode::kSameStep);
  env->reset(1);
  env->step(scripted_actions(2, 0.1F));
  const Value kept = env->step(scripted_actions(2, 0.2F)).infos.at("episode");
  const double time = kept.dict().at("t").array().data<double>()[0];
  env->step(scripted_actions(2, 0.3F));
  env->step(scripted_actions(2, 0.4F));
  EXPECT_EQ(kept.dict().at("l").array().data<std::int64_t>()[0], 2);
  EXPECT_EQ(kept.dict().at("t").array().data<double>()[0], time);
}

TEST_P(RecordEpisodeStatisticsTest, RefusesInfosThatHoldItsKeyAlready) {
  // A per-env RecordEpisodeStatistics inside puts "episode" in the infos.
  const vector::EnvFactory factory = [this](int /*i*/) {
    auto scripted = std::make_unique<testing::ScriptedEnv>(
        testing::box(-1.0, 1.0, {3}), testing::box(-1.0, 1.0, {1}), 2, truncate());
    return std::make_unique<wrappers::RecordEpisodeStatistics>(std::move(scripted));
  };
  RecordEpisodeStatistics same_key(
      testing::make_vector_env(threads(), 2, factory, AutoresetMode::kNextStep));
  same_key.reset(1);
  same_key.step(scripted_actions(2, 0.1F));
  try {
    same_key.step(scripted_actions(2, 0.2F));
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("\"episode\""));
    EXPECT_THAT(error.what(), HasSubstr("stats_key"));
  }
  RecordEpisodeStatistics other_key(
      testing::make_vector_env(threads(), 2, factory, AutoresetMode::kNextStep), 10, "batch");
  other_key.reset(1);
  other_key.step(scripted_actions(2, 0.1F));
  const VectorStepResult& result = other_key.step(scripted_actions(2, 0.2F));
  const std::optional<Reported> ours = reported(result.infos, 2, "batch");
  const std::optional<Reported> theirs = reported(result.infos, 2, "episode", true);
  ASSERT_TRUE(ours && theirs);
  EXPECT_EQ(ours->l, theirs->l);
  EXPECT_EQ(ours->r, theirs->r);
}

TEST(RecordEpisodeStatisticsErrorsTest, RefusesBadArguments) {
  const auto scripted = [] {
    return testing::make_scripted_vector({2}, false, AutoresetMode::kNextStep).env;
  };
  EXPECT_THROW(RecordEpisodeStatistics(scripted(), 0), std::invalid_argument);
  EXPECT_THROW(RecordEpisodeStatistics(scripted(), 10, ""), std::invalid_argument);
  EXPECT_EQ(RecordEpisodeStatistics(scripted()).name(),
            "RecordEpisodeStatistics<SyncVectorEnv(num_envs=1)>");
}

INSTANTIATE_TEST_SUITE_P(SyncAndPool, RecordEpisodeStatisticsTest,
                         ::testing::Combine(::testing::Values(0, 2), ::testing::Bool()),
                         [](const ::testing::TestParamInfo<std::tuple<int, bool>>& param_info) {
                           const int threads = std::get<0>(param_info.param);
                           return (threads == 0 ? std::string("Sync")
                                                : "Threads" + std::to_string(threads)) +
                                  (std::get<1>(param_info.param) ? "Truncated" : "Terminated");
                         });

}  // namespace
}  // namespace pixelgym::vector
