// EnvLoop and env_digest: the action log, its replay back to the same place, and the digest that
// checkpoints keep (its bytes must not change: older checkpoints compare against it).
#include "pixelgym/trainer/env_loop.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/tasks/grid_world.h"
#include "pixelgym/trainer/communicator.h"
#include "tests/examples/trainer/run/grid_envs.h"

namespace pixelgym::trainer {
namespace {

using test_envs::grid_envs;

// Env i's action at batch t: down or right, in a pattern that differs between envs.
void fill_actions(Value& actions, std::int64_t t) {
  Array& batch = actions.array();
  for (std::int64_t i = 0; i < batch.shape()[0]; ++i) {
    batch.data<std::int64_t>()[i] = (t + i) % 3 == 0 ? GridWorld::kRight : GridWorld::kDown;
  }
}

TEST(EnvDigestTest, HashesTheDictsArraysInKeyOrderThenTheEpisodes) {
  const Array b = Array::from_vector<float>({2}, {1.0f, 2.0f});
  const Array a = Array::from_vector<std::uint8_t>({3}, {7, 8, 9});
  // Inserted "b" first: the digest takes "a" first, as a std::map of tensors did.
  const Value observations = ValueDict{{"b", Value(b)}, {"a", Value(a)}};
  const std::vector<double> returns{0.5, -1.0};
  const std::vector<std::int64_t> lengths{3, 4};
  std::uint64_t expected = fnv1a(nullptr, 0);
  expected = fnv1a("a", 1, expected);
  expected = fnv1a(a.raw_data(), a.nbytes(), expected);
  expected = fnv1a("b", 1, expected);
  expected = fnv1a(b.raw_data(), b.nbytes(), expected);
  expected = fnv1a(returns.data(), returns.size() * sizeof(double), expected);
  expected = fnv1a(lengths.data(), lengths.size() * sizeof(std::int64_t), expected);
  EXPECT_EQ(env_digest(observations, returns, lengths), expected);

  std::uint64_t bare = fnv1a(nullptr, 0);
  bare = fnv1a(a.raw_data(), a.nbytes(), bare);  // the key "" adds no bytes
  bare = fnv1a(returns.data(), returns.size() * sizeof(double), bare);
  bare = fnv1a(lengths.data(), lengths.size() * sizeof(std::int64_t), bare);
  EXPECT_EQ(env_digest(Value(a), returns, lengths), bare);
}

TEST(EnvDigestTest, RefusesATupleByName) {
  const Value tuple = ValueTuple{Value(Array::scalar<float>(1.0f))};
  try {
    env_digest(tuple, {}, {});
    FAIL() << "a Tuple was hashed";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("Tuple"), std::string::npos) << error.what();
  }
}

TEST(EnvLoopTest, ReplayingTheLogBringsTheEnvsBackToTheSamePlace) {
  auto envs = grid_envs(2);
  EnvLoop loop(*envs, 11, "test_episode");
  EXPECT_EQ(loop.digest(), 0u);
  loop.reset();
  Value actions = loop.zero_actions();
  std::vector<std::uint64_t> digests;
  std::int64_t ended = 0;
  for (std::int64_t t = 0; t < 70; ++t) {  // GridWorld truncates at 50 steps: episodes end
    fill_actions(actions, t);
    ended += static_cast<std::int64_t>(loop.ended_returns(loop.step(actions)).size());
    digests.push_back(loop.digest());
  }
  EXPECT_GT(ended, 0);
  EXPECT_EQ(loop.batches(), 70);
  EXPECT_TRUE(loop.action_log_covers(140));
  EXPECT_FALSE(loop.action_log_covers(138));

  auto other = grid_envs(2);
  EnvLoop replayed(*other, 11, "test_episode");
  int resets = 0;
  std::int64_t steps = 0;
  replayed.replay(
      loop.action_log(), 140, [&resets](const Value&) { ++resets; },
      [&](const Value& logged, const vector::VectorStepResult&) {
        Value expected = loop.zero_actions();
        fill_actions(expected, steps);
        EXPECT_EQ(logged.array().data<std::int64_t>()[0], expected.array().data<std::int64_t>()[0]);
        EXPECT_EQ(replayed.digest(), digests[static_cast<std::size_t>(steps)]) << "batch " << steps;
        ++steps;
      });
  EXPECT_EQ(resets, 1);
  EXPECT_EQ(steps, 70);
  EXPECT_EQ(replayed.digest(), loop.digest());
  EXPECT_EQ(replayed.action_log(), loop.action_log());

  // The digest follows the envs (places and episode lengths repeat across episodes).
  EXPECT_GT(std::set<std::uint64_t>(digests.begin(), digests.end()).size(), 20u);
}

TEST(EnvLoopTest, RefusesALogOfAnotherLengthNamingBoth) {
  auto envs = grid_envs(2);
  EnvLoop loop(*envs, 0, "test_episode");
  const std::string log(3 * 16 + 1, '\0');  // 3 batches of two int64 actions, and a byte
  try {
    loop.replay(
        log, 6, [](const Value&) {}, [](const Value&, const vector::VectorStepResult&) {});
    FAIL() << "a log of a wrong length was replayed";
  } catch (const std::invalid_argument& error) {
    const std::string what = error.what();
    EXPECT_NE(what.find("3 batches of 16 bytes"), std::string::npos) << what;
    EXPECT_NE(what.find("got 49 bytes"), std::string::npos) << what;
  }
}

TEST(EnvLoopTest, StepBeforeResetAndReplayAfterResetAreErrors) {
  auto envs = grid_envs(1);
  EnvLoop loop(*envs, 0, "test_episode");
  Value actions = loop.zero_actions();
  EXPECT_THROW(loop.step(actions), std::logic_error);
  loop.reset();
  EXPECT_THROW(
      loop.replay(
          "", 0, [](const Value&) {}, [](const Value&, const vector::VectorStepResult&) {}),
      std::logic_error);
}

}  // namespace
}  // namespace pixelgym::trainer
