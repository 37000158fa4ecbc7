// PpoConfig's JSON form, RolloutStorage as the Trainer fills it (truncation bootstrapping from
// infos["final_obs"], episode boundaries), and the Trainer: it learns a bandit (Discrete and
// Box), its first minibatch starts at ratio 1 (with and without augmentation), it is
// deterministic under a seed, and its generator states resume its randomness.
#include "examples/trainer/ppo/ppo.h"

#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/env.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/vector/sync_vector_env.h"
#include "pixelgym/wrappers/vector/normalize_reward.h"
#include "pixelgym/wrappers/vector/record_episode_statistics.h"
#include "tests/wrappers/scripted_env.h"

namespace pixelgym::ppo {
namespace {

using vector::AutoresetMode;
using vector::SyncVectorEnv;

// One-step episodes with a constant observation [0.5]. Discrete(2): reward 1 for action 1, 0
// for action 0. Box [-1, 1]: reward -(a - 0.5)^2.
class BanditEnv final : public Env {
 public:
  explicit BanditEnv(bool continuous)
      : continuous_(continuous),
        observation_space_(std::make_shared<spaces::Box>(-1.0, 1.0, Shape{1})),
        action_space_(continuous ? SpacePtr(std::make_shared<spaces::Box>(-1.0, 1.0, Shape{1}))
                                 : SpacePtr(std::make_shared<spaces::Discrete>(2))) {
    metadata_.render_fps = 30.0;
  }
  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return metadata_; }

 protected:
  void do_reset(std::optional<std::uint64_t> /*seed*/, const Options& /*options*/,
                ResetResult& out) override {
    out.obs.array().data<float>()[0] = 0.5f;
  }
  void do_step(const Value& action, StepResult& out) override {
    if (continuous_) {
      const double a = action.array().data<float>()[0];
      out.reward = -(a - 0.5) * (a - 0.5);
    } else {
      out.reward = action.array().item<std::int64_t>() == 1 ? 1.0 : 0.0;
    }
    out.obs.array().data<float>()[0] = 0.5f;
    out.terminated = true;
  }
  Array do_render() override { return Array(DType::kUInt8, {4, 4, 3}); }

 private:
  bool continuous_;
  SpacePtr observation_space_;
  SpacePtr action_space_;
  Metadata metadata_;
};

// Observation [t / 10] at step t of an episode of `length` steps, reward 1, ended by truncation
// or termination.
class CounterEnv final : public Env {
 public:
  CounterEnv(int length, bool truncate) : length_(length), truncate_(truncate) {
    metadata_.render_fps = 30.0;
  }
  const Space& observation_space() const override { return observation_space_; }
  const Space& action_space() const override { return action_space_; }
  const Metadata& metadata() const override { return metadata_; }

 protected:
  void do_reset(std::optional<std::uint64_t> /*seed*/, const Options& /*options*/,
                ResetResult& out) override {
    t_ = 0;
    out.obs.array().data<float>()[0] = 0.0f;
  }
  void do_step(const Value& /*action*/, StepResult& out) override {
    ++t_;
    out.obs.array().data<float>()[0] = static_cast<float>(t_) / 10.0f;
    out.reward = 1.0;
    out.terminated = t_ >= length_ && !truncate_;
    out.truncated = t_ >= length_ && truncate_;
  }
  Array do_render() override { return Array(DType::kUInt8, {4, 4, 3}); }

 private:
  int length_;
  bool truncate_;
  int t_ = 0;
  spaces::Box observation_space_{-1.0, 1.0, Shape{1}};
  spaces::Discrete action_space_{2};
  Metadata metadata_;
};

std::unique_ptr<SyncVectorEnv> bandit_envs(int n, bool continuous) {
  return std::make_unique<SyncVectorEnv>(
      n, [continuous](int) { return std::make_unique<BanditEnv>(continuous); },
      AutoresetMode::kSameStep);
}

PpoConfig small_config(std::int64_t envs, std::int64_t steps) {
  PpoConfig config;
  config.num_envs = envs;
  config.num_steps = steps;
  config.num_minibatches = 2;
  config.policy.mlp_hidden = {16};
  config.policy.trunk_hidden = 16;
  return config;
}

double probability_of_action_one(Policy& policy) {
  torch::NoGradGuard no_grad;
  const ObservationTensors obs{{"", torch::full({1, 1}, 0.5f)}};
  return policy.evaluate(obs, torch::ones({1}, torch::kInt64)).log_prob.exp().item<double>();
}

std::vector<torch::Tensor> parameters_of(Policy& policy) {
  std::vector<torch::Tensor> copies;
  for (const auto& p : policy.parameters()) copies.push_back(p.detach().clone());
  return copies;
}

bool same_parameters(const std::vector<torch::Tensor>& a, const std::vector<torch::Tensor>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!torch::equal(a[i], b[i])) return false;
  }
  return true;
}

TEST(PpoConfig, JsonRoundTripKeepsEveryField) {
  PpoConfig config;
  config.seed = 12345678901234ULL;
  config.num_envs = 3;
  config.num_steps = 20;
  config.total_env_steps = 7777;
  config.learning_rate = 1e-3;
  config.anneal_learning_rate = false;
  config.adam_epsilon = 1e-7;
  config.gamma = 0.95;
  config.gae_lambda = 0.9;
  config.update_epochs = 3;
  config.num_minibatches = 5;
  config.normalize_advantages = false;
  config.normalize_rewards = false;
  config.clip_range = 0.3;
  config.clip_value_loss = false;
  config.entropy_coef = 0.02;
  config.value_coef = 0.25;
  config.max_grad_norm = 1.5;
  config.target_kl = 0.05;
  config.augment = true;
  config.shift_pad = 2;
  config.preempt_stragglers = true;
  config.preempt_done_fraction = 0.75;
  config.preempt_min_steps_fraction = 0.5;
  config.policy.cnn = CnnArchitecture::kNature;
  config.policy.cnn_features = 128;
  config.policy.mlp_hidden = {32, 16, 8};
  config.policy.trunk_hidden = 0;
  config.policy.initial_log_std = -0.5;
  config.policy.separate_value_network = true;
  config.policy.normalize_observations = false;
  config.policy.observation_clip = 5.0;
  const std::string text = config_to_json(config);
  const PpoConfig back = config_from_json(text);
  EXPECT_EQ(config_to_json(back), text);
  EXPECT_EQ(back.seed, config.seed);
  EXPECT_EQ(back.policy.cnn, CnnArchitecture::kNature);
  EXPECT_EQ(back.policy.mlp_hidden, config.policy.mlp_hidden);
  EXPECT_DOUBLE_EQ(back.adam_epsilon, 1e-7);
  EXPECT_TRUE(back.preempt_stragglers);
  EXPECT_DOUBLE_EQ(back.preempt_done_fraction, 0.75);
  EXPECT_DOUBLE_EQ(back.preempt_min_steps_fraction, 0.5);
  // Every field is a member (one per field of the structs, policy nested).
  const nlohmann::json json = nlohmann::json::parse(text);
  EXPECT_EQ(json.size(), 25u);
  EXPECT_EQ(json.at("policy").size(), 8u);
  EXPECT_EQ(json.at("policy").at("cnn"), "nature");
}

TEST(PpoConfig, JsonTakesASubsetAndRefusesUnknownOrIllTypedMembers) {
  const PpoConfig partial = config_from_json(R"({"gamma": 0.5, "policy": {"cnn": "nature"}})");
  EXPECT_DOUBLE_EQ(partial.gamma, 0.5);
  EXPECT_EQ(partial.num_steps, PpoConfig().num_steps);
  EXPECT_EQ(partial.policy.cnn, CnnArchitecture::kNature);
  EXPECT_EQ(partial.policy.cnn_features, PolicyConfig().cnn_features);
  try {
    config_from_json(R"({"gama": 0.5})");
    FAIL() << "an unknown member was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("\"gama\""), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("gamma"), std::string::npos) << error.what();
  }
  EXPECT_THROW(config_from_json(R"({"gamma": "high"})"), std::invalid_argument);
  EXPECT_THROW(config_from_json(R"({"policy": {"cnn": "resnet"}})"), std::invalid_argument);
  EXPECT_THROW(config_from_json(R"({"gamma": 1.5})"), std::invalid_argument);
  EXPECT_THROW(config_from_json(R"({"num_minibatches": 3})"), std::invalid_argument);  // 1024 % 3
  EXPECT_THROW(config_from_json("{"), std::invalid_argument);
}

// The configs shipped in examples/trainer/ppo/configs (the README's commands name them) parse and
// validate: a misspelt member or an out-of-range value there would only fail a user's run.
// Straggler preemption's fractions are in [0, 1], and a rollout cut at its minimum must still
// fill every minibatch.
TEST(PpoConfig, PreemptionSettingsAreChecked) {
  const auto message = [](const std::string& text) {
    try {
      config_from_json(text);
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message(R"({"preempt_done_fraction": 1.5})").find("preempt_done_fraction"),
            std::string::npos);
  EXPECT_NE(message(R"({"preempt_min_steps_fraction": -0.1})").find("preempt_min_steps_fraction"),
            std::string::npos);
  // 8 envs x ceil(0.25 * 16) = 32 transitions at the minimum: fewer than 64 minibatches.
  const std::string few = message(
      R"({"preempt_stragglers": true, "num_envs": 8, "num_steps": 16, "num_minibatches": 64})");
  EXPECT_NE(few.find("fewer than num_minibatches (64)"), std::string::npos) << few;
  EXPECT_EQ(message(R"({"preempt_stragglers": true, "num_envs": 8, "num_steps": 16,
                        "num_minibatches": 32})"),
            "accepted");
}

TEST(PpoConfig, EveryShippedConfigParses) {
  const std::filesystem::path folder =
      std::filesystem::path(PIXELGYM_SOURCE_DIR) / "examples" / "trainer" / "ppo" / "configs";
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".json") continue;
    names.push_back(entry.path().filename().string());
    std::ifstream file(entry.path());
    std::stringstream text;
    text << file.rdbuf();
    EXPECT_NO_THROW(config_from_json(text.str())) << entry.path();
  }
  std::sort(names.begin(), names.end());
  // The ones the README and `make demo` name.
  for (const char* name : {"action_repeat_8.json", "reacher.json", "swingup.json"}) {
    EXPECT_TRUE(std::binary_search(names.begin(), names.end(), std::string(name))) << name;
  }
}

TEST(Trainer, RequiresSameStepAutoresetAndMatchingNumEnvs) {
  SyncVectorEnv next_step(
      2, [](int) { return std::make_unique<BanditEnv>(false); }, AutoresetMode::kNextStep);
  EXPECT_THROW(Trainer(next_step, small_config(2, 4)), std::invalid_argument);
  auto envs = bandit_envs(2, false);
  EXPECT_THROW(Trainer(*envs, small_config(3, 4)), std::invalid_argument);
  Trainer trainer(*envs, small_config(2, 4));
  EXPECT_THROW(trainer.update(), std::logic_error);  // nothing collected yet
}

// Given a training run's env loop, the trainer steps the envs through it (the loop's log and
// digest are the trainer's), and refuses a loop seeded other than its env seed.
TEST(Trainer, StepsTheRunsEnvLoopSeededWithItsEnvSeed) {
  auto envs = bandit_envs(2, false);
  trainer::SingleProcessCommunicator alone;
  PpoConfig config = small_config(2, 4);
  config.seed = 7;
  trainer::EnvLoop wrong_seed(*envs, 8, "run_episode");
  EXPECT_THROW(Trainer(wrong_seed, config, alone), std::invalid_argument);
  trainer::EnvLoop loop(*envs, 7, "run_episode");
  Trainer trainer(loop, config, alone);
  trainer.collect();
  EXPECT_EQ(loop.batches(), 4);
  EXPECT_EQ(&trainer.env_action_log(), &loop.action_log());
  EXPECT_EQ(trainer.env_digest(), loop.digest());
  EXPECT_TRUE(trainer.env_action_log_complete());
}

// Episodes of 3 steps, rollouts of 5 steps, 2 envs: steps 0-2 are episode 1 (ending at t = 2),
// steps 3-4 begin episode 2.
TEST(Trainer, TruncatedStepsBootstrapFromTheFinalObservationsValue) {
  for (const bool truncate : {true, false}) {
    SCOPED_TRACE(truncate ? "truncated" : "terminated");
    SyncVectorEnv envs(
        2, [truncate](int) { return std::make_unique<CounterEnv>(3, truncate); },
        AutoresetMode::kSameStep);
    PpoConfig config = small_config(2, 5);
    config.num_minibatches = 1;
    config.normalize_rewards = false;  // the advantage below is checked with the raw reward
    Trainer trainer(envs, config);
    const RolloutStats stats = trainer.collect();
    ASSERT_EQ(stats.episodes.size(), 2u);
    EXPECT_DOUBLE_EQ(stats.episodes[0].episode_return, 3.0);
    EXPECT_EQ(stats.episodes[0].length, 3);
    const RolloutStorage& s = trainer.storage();
    const torch::Tensor final_value =
        trainer.policy().value({{"", torch::full({1, 1}, 0.3f)}});  // obs at t = 3
    for (int t = 0; t < 5; ++t) {
      for (int n = 0; n < 2; ++n) {
        const bool end = t == 2;
        EXPECT_EQ(s.truncated[t][n].item<int>(), end && truncate ? 1 : 0);
        EXPECT_EQ(s.terminated[t][n].item<int>(), end && !truncate ? 1 : 0);
        const float expected = end && truncate ? final_value.item<float>() : 0.0f;
        EXPECT_FLOAT_EQ(s.final_values[t][n].item<float>(), expected) << t << " " << n;
        // SameStep: the step after the end acts in the next episode's first observation.
        EXPECT_FLOAT_EQ(s.observations.at("")[t][n][0].item<float>(),
                        static_cast<float>(t % 3) / 10.0f);
      }
    }
    // The episode's last advantage: r + gamma V(final) - V(s_2) (truncated) or r - V(s_2).
    const double gamma = config.gamma;
    const double v2 = s.values[2][0].item<double>();
    const double expected = 1.0 + (truncate ? gamma * final_value.item<double>() : 0.0) - v2;
    EXPECT_NEAR(s.advantages[2][0].item<double>(), expected, 1e-5);
  }
}

// normalize_rewards: the rollout holds exactly the rewards vector::NormalizeReward gives for the
// same steps (envs of different episode lengths, so that the returns differ), across rollouts;
// the Episode records keep the env's own returns; set_reward_scaling restores the state and
// refuses a bad one.
TEST(Trainer, NormalizedRewardsAreNormalizeRewardsAndEpisodesKeepTheEnvsReturns) {
  const auto counters = [](int n) { return std::make_unique<CounterEnv>(2 + n, n % 2 == 0); };
  SyncVectorEnv envs(3, counters, AutoresetMode::kSameStep);
  PpoConfig config = small_config(3, 4);
  config.num_minibatches = 1;
  ASSERT_TRUE(config.normalize_rewards);  // the default
  Trainer trainer(envs, config);
  vector::NormalizeReward reference(
      std::make_unique<SyncVectorEnv>(3, counters, AutoresetMode::kSameStep), config.gamma);
  reference.reset(config.seed);
  const Value actions = reference.action_space().zeros();  // CounterEnv ignores its action
  std::vector<double> episode_returns;
  for (int rollout = 0; rollout < 3; ++rollout) {
    const RolloutStats stats = trainer.collect();
    for (const Episode& episode : stats.episodes) episode_returns.push_back(episode.episode_return);
    for (int t = 0; t < 4; ++t) {
      const vector::VectorStepResult& step = reference.step(actions);
      for (int n = 0; n < 3; ++n) {
        EXPECT_FLOAT_EQ(trainer.storage().rewards[t][n].item<float>(),
                        static_cast<float>(step.rewards.data<double>()[n]))
            << "rollout " << rollout << " step " << t << " env " << n;
      }
    }
    trainer.update();
  }
  EXPECT_NE(trainer.storage().rewards[0][0].item<float>(), 1.0f);  // they were scaled
  // Episodes of 2, 3 and 4 steps of reward 1: returns are the lengths.
  ASSERT_FALSE(episode_returns.empty());
  for (const double r : episode_returns) EXPECT_TRUE(r == 2.0 || r == 3.0 || r == 4.0) << r;
  EXPECT_EQ(trainer.reward_scaling().statistics.var, reference.statistics().var);
  EXPECT_EQ(trainer.reward_scaling().returns, reference.discounted_returns());

  RewardScaling scaling = trainer.reward_scaling();
  scaling.returns.pop_back();
  EXPECT_THROW(trainer.set_reward_scaling(scaling), std::invalid_argument);
  scaling = trainer.reward_scaling();
  scaling.statistics.var[0] = -1.0;
  EXPECT_THROW(trainer.set_reward_scaling(scaling), std::invalid_argument);
  scaling = trainer.reward_scaling();
  scaling.returns[1] = 7.5;
  trainer.set_reward_scaling(scaling);
  EXPECT_EQ(trainer.reward_scaling().returns[1], 7.5);
}

// A non-finite loss stops the update with an error that names it, before the optimizer writes
// NaN into the weights.
TEST(Trainer, ANonFiniteLossIsAnErrorAndNoStepIsTaken) {
  auto envs = bandit_envs(2, true);
  Trainer trainer(*envs, small_config(2, 4));
  trainer.collect();
  {
    torch::NoGradGuard no_grad;
    trainer.policy().parameters()[0].view(-1)[0].fill_(std::nan(""));
  }
  const std::vector<torch::Tensor> parameters = parameters_of(trainer.policy());
  try {
    trainer.update();
    FAIL() << "no error for a NaN loss";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("diverged"), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find("epoch 1, minibatch 1"), std::string::npos)
        << error.what();
  }
  // Nothing was stepped: every parameter is as before (the planted NaN included).
  const std::vector<torch::Tensor> after = parameters_of(trainer.policy());
  ASSERT_EQ(after.size(), parameters.size());
  for (std::size_t i = 0; i < after.size(); ++i) {
    EXPECT_TRUE(torch::equal(after[i].nan_to_num(), parameters[i].nan_to_num())) << i;
  }
}

TEST(Trainer, LearnsTheRewardedActionOfADiscreteBandit) {
  auto envs = bandit_envs(4, false);
  PpoConfig config = small_config(4, 16);
  config.learning_rate = 1e-2;
  config.entropy_coef = 0.0;
  Trainer trainer(*envs, config);
  const double before = probability_of_action_one(trainer.policy());
  EXPECT_NEAR(before, 0.5, 0.05);
  double mean_return = 0.0;
  for (int i = 0; i < 12; ++i) {
    const RolloutStats rollout = trainer.collect();
    mean_return = 0.0;
    for (const Episode& e : rollout.episodes) mean_return += e.episode_return;
    mean_return /= static_cast<double>(rollout.episodes.size());
    const UpdateStats stats = trainer.update();
    EXPECT_TRUE(std::isfinite(stats.policy_loss));
    EXPECT_EQ(stats.minibatches, config.update_epochs * config.num_minibatches);
  }
  EXPECT_GT(probability_of_action_one(trainer.policy()), 0.95);
  EXPECT_GT(mean_return, 0.85);
  EXPECT_EQ(trainer.env_steps(), 12 * 64);
  EXPECT_EQ(trainer.updates(), 12);
}

TEST(Trainer, TrainsThroughAVectorWrapper) {
  vector::RecordEpisodeStatistics envs(bandit_envs(4, false));
  PpoConfig config = small_config(4, 16);
  config.learning_rate = 1e-2;
  config.entropy_coef = 0.0;
  Trainer trainer(envs, config);
  for (int i = 0; i < 12; ++i) {
    EXPECT_EQ(trainer.collect().episodes.size(), 64u);  // one-step episodes
    trainer.update();
  }
  EXPECT_GT(probability_of_action_one(trainer.policy()), 0.95);
}

TEST(Trainer, MovesTheGaussianMeanToTheBestActionOfAContinuousBandit) {
  auto envs = bandit_envs(4, true);
  PpoConfig config = small_config(4, 32);
  config.learning_rate = 1e-2;
  config.entropy_coef = 0.0;
  config.policy.initial_log_std = -1.0;
  Trainer trainer(*envs, config);
  const ObservationTensors obs{{"", torch::full({1, 1}, 0.5f)}};
  auto mean_action = [&] {
    torch::NoGradGuard no_grad;
    return trainer.policy().act(obs, true).action.item<double>();
  };
  EXPECT_NEAR(mean_action(), 0.0, 0.05);
  for (int i = 0; i < 20; ++i) {
    trainer.collect();
    trainer.update();
  }
  EXPECT_NEAR(mean_action(), 0.5, 0.1);
}

TEST(Trainer, FirstMinibatchStartsAtRatioOneWithAndWithoutAugmentation) {
  std::vector<std::vector<torch::Tensor>> updated;  // the parameters after the update, per case
  for (const bool augment : {false, true}) {
    SCOPED_TRACE(augment ? "augment" : "no augmentation");
    SyncVectorEnv envs(
        2,
        [](int) {
          auto env = std::make_unique<testing::ScriptedEnv>(
              testing::box(0, 255, {36, 36, 3}, DType::kUInt8),
              std::make_shared<spaces::Discrete>(3), /*episode_length=*/3, /*truncate=*/true);
          env->record = false;
          return env;
        },
        AutoresetMode::kSameStep);
    PpoConfig config = small_config(2, 4);
    config.num_minibatches = 1;
    config.update_epochs = 1;
    config.augment = augment;
    Trainer trainer(envs, config);
    trainer.collect();
    const UpdateStats stats = trainer.update();
    EXPECT_NEAR(stats.approx_kl, 0.0, 1e-7);
    EXPECT_DOUBLE_EQ(stats.clip_fraction, 0.0);
    EXPECT_TRUE(std::isfinite(stats.value_loss));
    updated.push_back(parameters_of(trainer.policy()));
  }
  // Same seed, same rollout: only the shifts tell the two updates apart, so the images were
  // shifted (were every shift (pad, pad), the identity, the parameters would be equal).
  EXPECT_FALSE(same_parameters(updated[0], updated[1]));
}

TEST(Trainer, SameSeedSameParametersAndRngStateResumesTheRandomness) {
  auto run = [](std::uint64_t seed) {
    auto envs = bandit_envs(2, true);
    PpoConfig config = small_config(2, 8);
    config.seed = seed;
    Trainer trainer(*envs, config);
    for (int i = 0; i < 2; ++i) {
      trainer.collect();
      trainer.update();
    }
    return parameters_of(trainer.policy());
  };
  EXPECT_TRUE(same_parameters(run(3), run(3)));
  EXPECT_FALSE(same_parameters(run(3), run(4)));

  // The update's randomness (minibatch order) is the generator state's alone: a trainer whose
  // generator drew differently and was then set to A's state updates as A does.
  auto envs_a = bandit_envs(2, true);
  auto envs_b = bandit_envs(2, true);
  PpoConfig config = small_config(2, 8);
  Trainer a(*envs_a, config);
  Trainer b(*envs_b, config);
  a.collect();
  b.collect();
  const TrainerRngState state = a.rng_state();
  b.set_rng_state({at::detail::createCPUGenerator(99).get_state(), state.augmentation});
  b.update();  // a different order
  auto envs_d = bandit_envs(2, true);
  Trainer d(*envs_d, config);
  d.collect();
  d.set_rng_state(state);
  a.update();
  d.update();
  EXPECT_TRUE(same_parameters(parameters_of(a.policy()), parameters_of(d.policy())));
  EXPECT_FALSE(same_parameters(parameters_of(a.policy()), parameters_of(b.policy())));
}

// With a separate value network a target_kl stop ends the policy's steps only: the value
// network trains on through the remaining epochs, and the policy's parameters end as if the
// update had stopped there (Adam's momentum does not carry them on).
TEST(Trainer, AKlStopWithASeparateValueNetworkStopsOnlyThePolicy) {
  auto run = [](std::int64_t epochs, UpdateStats& stats) {
    auto envs = bandit_envs(2, true);
    PpoConfig config = small_config(2, 8);
    config.policy.separate_value_network = true;
    config.update_epochs = epochs;
    // The first minibatch's ratio is exactly 1; the second's KL exceeds this.
    config.target_kl = 1e-12;
    Trainer trainer(*envs, config);
    trainer.collect();
    stats = trainer.update();
    std::map<std::string, torch::Tensor> parameters;
    for (const auto& item : trainer.policy().named_parameters()) {
      parameters[item.key()] = item.value().detach().clone();
    }
    return parameters;
  };
  UpdateStats four_stats;
  UpdateStats one_stats;
  const auto four = run(4, four_stats);
  const auto one = run(1, one_stats);
  EXPECT_EQ(four_stats.minibatches, 2);
  EXPECT_EQ(four_stats.epochs, 1);
  EXPECT_EQ(four_stats.value_minibatches, 6);
  EXPECT_EQ(one_stats.minibatches, 2);
  EXPECT_EQ(one_stats.value_minibatches, 0);
  int value_parameters = 0;
  for (const auto& [name, tensor] : four) {
    if (name.rfind("value_", 0) == 0) {
      ++value_parameters;
      EXPECT_FALSE(torch::equal(tensor, one.at(name))) << name << " did not train on";
    } else {
      EXPECT_TRUE(torch::equal(tensor, one.at(name))) << name << " moved after the stop";
    }
  }
  EXPECT_GT(value_parameters, 0);
}

std::unique_ptr<SyncVectorEnv> counter_envs(int n) {
  return std::make_unique<SyncVectorEnv>(
      n, [](int) { return std::make_unique<CounterEnv>(5, true); }, AutoresetMode::kSameStep);
}

// replay_env brings fresh envs to where a trainer's envs are, from its action log: the next
// rollout sees the same observations, episodes in progress continued (5-step episodes, 4-step
// rollouts), and the same episode ends.
TEST(Trainer, ReplayEnvContinuesTheEpisodesInProgress) {
  const PpoConfig config = small_config(2, 4);
  auto envs_a = counter_envs(2);
  Trainer a(*envs_a, config);
  a.collect();
  a.update();
  a.collect();
  a.update();
  const std::string log = a.env_action_log();
  EXPECT_EQ(log.size(), 16U * sizeof(std::int64_t));  // 2 rollouts x 4 steps x 2 envs

  auto envs_b = counter_envs(2);
  Trainer b(*envs_b, config);
  b.set_progress(a.env_steps(), a.updates());
  try {
    b.replay_env(log.substr(0, log.size() - 8));
    ADD_FAILURE() << "a short log was replayed";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(),
                 "replay of the env actions: an action log of 8 batches of 16 bytes (for 16 env "
                 "steps) expected, got 120 bytes");
  }
  EXPECT_EQ(b.env_digest(), 0U);  // not reset yet
  b.replay_env(log);
  EXPECT_EQ(b.env_action_log(), log);
  // The digest a checkpoint keeps says the replay arrived where the envs were...
  EXPECT_NE(a.env_digest(), 0U);
  EXPECT_EQ(b.env_digest(), a.env_digest());
  // ...and tells other places apart: the first rollout's half of the log leaves the envs at
  // step 4 of their episodes, not step 3 of the next.
  auto envs_c = counter_envs(2);
  Trainer c(*envs_c, config);
  c.set_progress(a.env_steps() / 2, 1);
  c.replay_env(log.substr(0, log.size() / 2));
  EXPECT_NE(c.env_digest(), a.env_digest());
  const RolloutStats next_a = a.collect();
  const RolloutStats next_b = b.collect();
  // Step 8 of a 5-step episode cycle: observations 0.3, 0.4, then 0.0 after the truncation.
  EXPECT_TRUE(torch::equal(a.storage().observations.at(""), b.storage().observations.at("")));
  EXPECT_FLOAT_EQ(b.storage().observations.at("")[0][0][0].item<float>(), 0.3F);
  ASSERT_EQ(next_b.episodes.size(), next_a.episodes.size());
  for (std::size_t e = 0; e < next_a.episodes.size(); ++e) {
    EXPECT_EQ(next_b.episodes[e].length, next_a.episodes[e].length);
    EXPECT_EQ(next_b.episodes[e].episode_return, next_a.episodes[e].episode_return);
  }
  EXPECT_THROW(b.replay_env(log), std::logic_error);  // the envs already went on
}

TEST(Trainer, LearningRateAnnealsLinearlyOverTheRun) {
  auto envs = bandit_envs(2, false);
  PpoConfig config = small_config(2, 8);
  config.total_env_steps = 64;  // 4 rollouts of 16
  Trainer trainer(*envs, config);
  std::vector<double> rates;
  for (int i = 0; i < 4; ++i) {
    trainer.collect();
    rates.push_back(trainer.update().learning_rate);
  }
  const double lr = config.learning_rate;
  EXPECT_DOUBLE_EQ(rates[0], lr);
  EXPECT_DOUBLE_EQ(rates[1], lr * 0.75);
  EXPECT_DOUBLE_EQ(rates[3], lr * 0.25);
  EXPECT_DOUBLE_EQ(trainer.optimizer().param_groups()[0].options().get_lr(), lr * 0.25);
}

}  // namespace
}  // namespace pixelgym::ppo
