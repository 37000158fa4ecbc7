// The replay buffer: frame stacks rebuilt from single frames and never across an episode's
// start, n-step returns that stop at `terminated` (no bootstrap) and at `truncated` (bootstrap
// from the episode's last observation), windows not yet complete never sampled, wrap-around at
// capacity, several envs, and the errors of bad input.
#include "examples/trainer/torch_common/replay_buffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <map>
#include <random>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

constexpr std::int64_t kStack = 3;

// Frames are 4 bytes holding a unique int32 id; the vector key holds the id as a float.
ReplayLayout layout() {
  ReplayLayout layout;
  layout.images.push_back({"pixels", kStack, 4});
  layout.vectors.push_back({"state", 1});
  layout.action_size = 1;
  return layout;
}

// One env's episodes as FrameStackObservation(padding=reset) gives them: the stack of the
// latest frames, the first one repeated at an episode's start. Records each observation's
// expected stack by its newest frame's id.
class Episodes {
 public:
  explicit Episodes(ReplayBuffer& buffer, std::int64_t env = 0, int first_id = 0)
      : buffer_(buffer), env_(env), next_id_(first_id) {}

  int start() {
    const int id = next_id_++;
    frames_.assign(kStack, id);
    buffer_.add_first(env_, view());
    return id;
  }
  // Steps with action = reward = the current id; returns the new observation's id.
  int step(bool terminated = false, bool truncated = false) {
    const float action = static_cast<float>(frames_.back());
    const double reward = frames_.back();
    const int id = next_id_++;
    frames_.erase(frames_.begin());
    frames_.push_back(id);
    buffer_.add_step(env_, &action, reward, terminated, truncated, view());
    return id;
  }
  std::map<int, std::vector<int>> stacks;  // by newest id

 private:
  ObservationView view() {
    std::memcpy(bytes_, frames_.data(), sizeof(bytes_));
    state_ = static_cast<float>(frames_.back());
    stacks[frames_.back()] = frames_;
    return ObservationView{{bytes_}, {&state_}};
  }
  ReplayBuffer& buffer_;
  std::int64_t env_;
  int next_id_;
  std::vector<int> frames_;
  std::uint8_t bytes_[kStack * 4] = {};
  float state_ = 0.0f;
};

std::vector<int> stack_of(const std::vector<std::uint8_t>& images, std::int64_t row) {
  std::vector<int> ids(kStack);
  std::memcpy(ids.data(), images.data() + row * kStack * 4, kStack * 4);
  return ids;
}

TEST(ReplayBufferTest, StacksAreRebuiltWithinTheirEpisode) {
  ReplayBuffer buffer(layout(), 1, 1000, 1, 0.99);
  Episodes episodes(buffer);
  episodes.start();                             // id 0
  episodes.step();                              // 1
  episodes.step(true);                          // 2: terminated
  episodes.start();                             // 3
  for (int k = 0; k < 4; ++k) episodes.step();  // 4..7
  std::mt19937_64 rng(1);
  ReplayBatch batch;
  std::set<int> seen;
  for (int draw = 0; draw < 50; ++draw) {
    buffer.sample(16, rng, batch);
    for (std::int64_t row = 0; row < batch.size; ++row) {
      const std::vector<int> obs = stack_of(batch.images[0], row);
      const std::vector<int> next = stack_of(batch.next_images[0], row);
      EXPECT_EQ(obs, episodes.stacks.at(obs.back()));
      EXPECT_EQ(next, episodes.stacks.at(next.back()));
      EXPECT_EQ(batch.vectors[0][row], static_cast<float>(obs.back()));
      EXPECT_EQ(batch.actions[row], static_cast<float>(obs.back()));
      EXPECT_EQ(next.back(), obs.back() + 1);
      seen.insert(obs.back());
    }
  }
  // Every step was drawn (the episodes' last observations 2 and 7 take no action; 7 is also
  // the newest).
  EXPECT_EQ(seen, (std::set<int>{0, 1, 3, 4, 5, 6}));
  // The second episode's first stacks repeat its first frame, never the first episode's frames.
  EXPECT_EQ(episodes.stacks.at(4), (std::vector<int>{3, 3, 4}));
  EXPECT_EQ(episodes.stacks.at(5), (std::vector<int>{3, 4, 5}));
}

TEST(ReplayBufferTest, NStepReturnsStopAtTerminationAndBootstrapAfterTruncation) {
  const double gamma = 0.5;
  ReplayBuffer buffer(layout(), 1, 1000, 3, gamma);
  Episodes episodes(buffer);
  // Episode A: observations 0..4, rewards 0, 1, 2, 3 (reward = the id acted from), truncated.
  episodes.start();
  for (int k = 0; k < 3; ++k) episodes.step();
  episodes.step(false, true);
  // Episode B: observations 5..7, rewards 5, 6, terminated.
  episodes.start();
  episodes.step();
  episodes.step(true, false);
  episodes.start();  // 8: an episode in progress, nothing to sample from yet
  struct Expected {
    float reward;
    float discount;
    int next;
  };
  const std::map<int, Expected> expected = {
      {0, {0 + 0.5f * 1 + 0.25f * 2, 0.125f, 3}},  // a full window
      {1, {1 + 0.5f * 2 + 0.25f * 3, 0.125f, 4}},  // ends on the truncated step: bootstraps
      {2, {2 + 0.5f * 3, 0.25f, 4}},               // truncated after 2 steps: gamma^2 from obs 4
      {3, {3, 0.5f, 4}},
      {5, {5 + 0.5f * 6, 0.0f, 7}},  // terminated: nothing to bootstrap from
      {6, {6, 0.0f, 7}},
  };
  std::mt19937_64 rng(2);
  ReplayBatch batch;
  std::set<int> seen;
  for (int draw = 0; draw < 50; ++draw) {
    buffer.sample(8, rng, batch);
    for (std::int64_t row = 0; row < batch.size; ++row) {
      const int id = stack_of(batch.images[0], row).back();
      ASSERT_EQ(expected.count(id), 1U) << "sampled observation " << id;
      const Expected& want = expected.at(id);
      EXPECT_FLOAT_EQ(batch.rewards[row], want.reward) << id;
      EXPECT_FLOAT_EQ(batch.discounts[row], want.discount) << id;
      EXPECT_EQ(stack_of(batch.next_images[0], row).back(), want.next) << id;
      EXPECT_EQ(batch.next_vectors[0][row], static_cast<float>(want.next)) << id;
      seen.insert(id);
    }
  }
  EXPECT_EQ(seen.size(), expected.size());
}

TEST(ReplayBufferTest, AWindowIsSampledOnlyOnceItsStepsAreKnown) {
  ReplayBuffer buffer(layout(), 1, 1000, 3, 0.99);
  Episodes episodes(buffer);
  episodes.start();
  EXPECT_FALSE(buffer.can_sample());
  episodes.step();
  episodes.step();
  EXPECT_FALSE(buffer.can_sample());  // obs 0 needs 3 steps
  std::mt19937_64 rng(3);
  ReplayBatch batch;
  EXPECT_THROW(buffer.sample(4, rng, batch), std::logic_error);
  episodes.step();
  ASSERT_TRUE(buffer.can_sample());
  buffer.sample(16, rng, batch);
  for (std::int64_t row = 0; row < batch.size; ++row) {
    EXPECT_EQ(stack_of(batch.images[0], row).back(), 0);  // the only complete window
  }
  // An episode ending completes the shorter windows at once.
  episodes.step(false, true);
  buffer.sample(64, rng, batch);
  std::set<int> seen;
  for (std::int64_t row = 0; row < batch.size; ++row) {
    seen.insert(stack_of(batch.images[0], row).back());
  }
  EXPECT_EQ(seen, (std::set<int>{0, 1, 2, 3}));
}

TEST(ReplayBufferTest, WrapsAroundAtCapacityKeepingTheNewestSteps) {
  const std::int64_t capacity = 20;
  ReplayBuffer buffer(layout(), 1, capacity, 2, 0.9);
  Episodes episodes(buffer);
  int newest = episodes.start();
  for (int t = 0; t < 60; ++t) {
    newest = episodes.step(false, t % 7 == 6);
    if (t % 7 == 6) newest = episodes.start();
  }
  EXPECT_EQ(buffer.slots_used(), capacity);
  EXPECT_EQ(buffer.steps_added(), 60);
  std::mt19937_64 rng(4);
  ReplayBatch batch;
  for (int draw = 0; draw < 40; ++draw) {
    buffer.sample(16, rng, batch);
    for (std::int64_t row = 0; row < batch.size; ++row) {
      const std::vector<int> obs = stack_of(batch.images[0], row);
      // Ids grow one per slot: only the newest `capacity` slots remain, and no stack holds a
      // frame of a slot already overwritten.
      EXPECT_GT(obs.front(), newest - capacity) << "stale frame in a stack";
      EXPECT_EQ(obs, episodes.stacks.at(obs.back()));
      EXPECT_EQ(stack_of(batch.next_images[0], row),
                episodes.stacks.at(stack_of(batch.next_images[0], row).back()));
    }
  }
}

TEST(ReplayBufferTest, EnvsKeepTheirOwnEpisodes) {
  ReplayBuffer buffer(layout(), 2, 200, 1, 0.99);
  Episodes a(buffer, 0, 0);
  Episodes b(buffer, 1, 1000);
  a.start();
  b.start();
  for (int t = 0; t < 10; ++t) {
    a.step();
    b.step(t == 4);
    if (t == 4) b.start();
  }
  std::mt19937_64 rng(5);
  ReplayBatch batch;
  std::set<bool> envs;
  buffer.sample(64, rng, batch);
  for (std::int64_t row = 0; row < batch.size; ++row) {
    const std::vector<int> obs = stack_of(batch.images[0], row);
    const bool second = obs.back() >= 1000;
    envs.insert(second);
    EXPECT_EQ(obs, (second ? b : a).stacks.at(obs.back()));
  }
  EXPECT_EQ(envs.size(), 2U);
}

TEST(ReplayBufferTest, RefusesAStackItCannotRebuildAndBadSettings) {
  ReplayBuffer buffer(layout(), 1, 100, 1, 0.99);
  std::vector<int> frames = {7, 7, 7};
  float state = 0.0f;
  buffer.add_first(0, ObservationView{{reinterpret_cast<std::uint8_t*>(frames.data())}, {&state}});
  // The next stack should be (7, 7, 8); zero padding, or a frame from elsewhere, is refused.
  frames = {0, 7, 8};
  const float action = 0.0f;
  try {
    buffer.add_step(0, &action, 0.0, false, false,
                    ObservationView{{reinterpret_cast<std::uint8_t*>(frames.data())}, {&state}});
    FAIL() << "a stack that is not the episode's was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("\"pixels\""), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("padding=reset"), std::string::npos) << error.what();
  }
  EXPECT_THROW(buffer.add_step(1, &action, 0.0, false, false, {}), std::out_of_range);

  ReplayBuffer ended(layout(), 1, 100, 1, 0.99);
  frames = {1, 1, 1};
  const ObservationView first{{reinterpret_cast<std::uint8_t*>(frames.data())}, {&state}};
  ended.add_first(0, first);
  frames = {1, 1, 2};
  ended.add_step(0, &action, 0.0, true, false, first);
  EXPECT_THROW(ended.add_step(0, &action, 0.0, false, false, first), std::logic_error);

  const auto refused = [](auto make, const std::string& word) {
    try {
      make();
      ADD_FAILURE() << "accepted; expected an error naming " << word;
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
    }
  };
  refused([] { ReplayBuffer(layout(), 0, 100, 1, 0.9); }, "num_envs");
  refused([] { ReplayBuffer(layout(), 1, 100, 0, 0.9); }, "n_step");
  refused([] { ReplayBuffer(layout(), 1, 100, 1, 1.5); }, "gamma");
  refused([] { ReplayBuffer(layout(), 4, 20, 3, 0.9); }, "capacity");
}

}  // namespace
}  // namespace pixelgym::trainer
