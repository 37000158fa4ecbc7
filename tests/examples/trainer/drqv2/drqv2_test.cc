// DrQ-v2's pieces: its config's JSON form and the errors naming each bad member, the target
// critic's soft update, and an update that learns a fixed batch. (Its input layout and random
// shift are the shared torch layer's: tests/examples/trainer/torch_common/shared_layer_test.cc.)
#include "examples/trainer/drqv2/drqv2.h"

#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "tests/examples/trainer/torch_common/learner_test_support.h"

namespace pixelgym::drqv2 {
namespace {

using nlohmann::json;
using trainer::testing::parameter_copies;
using trainer::testing::pixel_space;

constexpr auto parse = trainer::testing::parse_config<DrqV2Config>;
constexpr auto expect_refused = trainer::testing::expect_refused<DrqV2Config>;

TEST(DrqV2ConfigTest, JsonRoundTripsAndBadMembersAreNamed) {
  DrqV2Config config;
  config.encoder = EncoderArchitecture::kDrqV2;
  config.batch_size = 64;
  config.noise_end = 0.2;
  config.actor_preactivation_penalty = 0.01;
  json out;
  to_json(out, config);
  EXPECT_EQ(out.at("encoder"), "drqv2");
  const DrqV2Config back = parse(out);
  EXPECT_EQ(back.encoder, EncoderArchitecture::kDrqV2);
  EXPECT_EQ(back.batch_size, 64);
  EXPECT_EQ(back.noise_end, 0.2);
  EXPECT_EQ(back.actor_preactivation_penalty, 0.01);
  EXPECT_EQ(parse({{"encoder", "fine"}}).encoder, EncoderArchitecture::kFine);
  EXPECT_EQ(parse(json::object()).hidden_dim, DrqV2Config{}.hidden_dim);

  expect_refused({{"batch_sise", 4}}, "batch_sise");
  expect_refused({{"batch_size", 0}}, "batch_size");
  expect_refused({{"batch_size", "big"}}, "batch_size");
  expect_refused({{"gamma", 1.5}}, "gamma");
  expect_refused({{"encoder", "resnet"}}, "encoder");
  expect_refused({{"n_step", 0}}, "n_step");
  expect_refused({{"num_envs", 2}, {"iteration_env_steps", 3}}, "iteration_env_steps");
  expect_refused({{"replay_capacity", 5}}, "replay_capacity");
  expect_refused({{"updates_per_env_step", -1}}, "updates_per_env_step");
  expect_refused({{"actor_preactivation_penalty", -0.1}}, "actor_preactivation_penalty");
}

TEST(DrqV2ConfigTest, NoiseFollowsItsSchedule) {
  DrqV2Config config;
  config.noise_start = 1.0;
  config.noise_end = 0.2;
  config.noise_schedule_env_steps = 100;
  EXPECT_DOUBLE_EQ(config.noise_std(0), 1.0);
  EXPECT_DOUBLE_EQ(config.noise_std(50), 0.6);
  EXPECT_DOUBLE_EQ(config.noise_std(100), 0.2);
  EXPECT_DOUBLE_EQ(config.noise_std(1000), 0.2);
}

// A learner on 32x32 gray stacks of 3 with one state key, and a batch of random transitions.
struct Fixture {
  InputLayout input;
  DrqV2Config config;
  ReplayBatch batch;

  Fixture() {
    input = input_layout(pixel_space({3, 32, 32}), spaces::Box(-1.0, 1.0, Shape{1}), 3, "drqv2",
                         "T-v0");
    config.batch_size = 16;
    config.hidden_dim = 32;
    config.feature_dim = 16;
    config.learning_rate = 1e-3;
    batch = trainer::testing::random_batch(true);
  }
};

TEST(DrqV2LearnerTest, TheTargetCriticStartsEqualAndMovesByTau) {
  Fixture f;
  f.config.critic_tau = 0.25;
  Learner learner(f.input, f.config);
  Agent& agent = learner.agent();
  const auto critic_before = parameter_copies(*agent.q1);
  const auto target_before = parameter_copies(*agent.target_q1);
  ASSERT_EQ(critic_before.size(), target_before.size());
  for (std::size_t i = 0; i < critic_before.size(); ++i) {
    EXPECT_TRUE(torch::equal(critic_before[i], target_before[i]));
  }
  at::Generator augmentation = at::detail::createCPUGenerator(1);
  at::Generator noise = at::detail::createCPUGenerator(2);
  learner.update(f.batch, 0, augmentation, noise);
  const auto critic_after = parameter_copies(*agent.q1);
  const auto target_after = parameter_copies(*agent.target_q1);
  bool moved = false;
  for (std::size_t i = 0; i < critic_after.size(); ++i) {
    // target' = target + tau (critic' - target): the critic after its step.
    const torch::Tensor expected = target_before[i] + 0.25 * (critic_after[i] - target_before[i]);
    EXPECT_TRUE(torch::allclose(target_after[i], expected, 1e-5, 1e-6)) << "parameter " << i;
    moved = moved || !torch::equal(target_after[i], target_before[i]);
  }
  EXPECT_TRUE(moved);
  for (const auto& p : agent.target_trunk->parameters()) EXPECT_FALSE(p.requires_grad());
}

TEST(DrqV2LearnerTest, UpdatesFitAFixedBatchAndAreDeterministic) {
  Fixture f;
  const auto run = [&](int updates, std::vector<double>* losses) {
    Learner learner(f.input, f.config);
    at::Generator augmentation = at::detail::createCPUGenerator(1);
    at::Generator noise = at::detail::createCPUGenerator(2);
    for (int u = 0; u < updates; ++u) {
      losses->push_back(learner.update(f.batch, 0, augmentation, noise).critic_loss);
    }
    return parameter_copies(learner.agent());
  };
  std::vector<double> losses, again;
  const auto a = run(60, &losses);
  const auto b = run(60, &again);
  EXPECT_LT(losses.back(), 0.2 * losses.front()) << losses.front() << " -> " << losses.back();
  EXPECT_EQ(losses, again);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_TRUE(torch::equal(a[i], b[i]));
}

// Each architecture's four convolutions leave the documented grid: at 64x64, 25x25 cells
// (drqv2), 5x5 (mrq), 11x11 (fine), 32 channels each, beside the state key's 2 values.
TEST(DrqV2LearnerTest, EncodersLeaveTheirDocumentedGrid) {
  const InputLayout input =
      input_layout(pixel_space({3, 64, 64}), spaces::Box(-1.0, 1.0, Shape{1}), 3, "drqv2", "T-v0");
  for (const auto& [architecture, cells] :
       std::vector<std::pair<EncoderArchitecture, std::int64_t>>{
           {EncoderArchitecture::kDrqV2, 25},
           {EncoderArchitecture::kMrq, 5},
           {EncoderArchitecture::kFine, 11}}) {
    DrqV2Config config;
    config.encoder = architecture;
    const Agent agent(input, config);
    EXPECT_EQ(agent.feature_size(), 32 * cells * cells + 2) << to_string(architecture);
  }
}

// A policy pushed deep into tanh's tail gets no gradient from the critic: without the penalty
// its output layer stays where it is; with it, Adam pulls the layer back.
TEST(DrqV2LearnerTest, ThePreactivationPenaltyPullsASaturatedActorBack) {
  const auto bias_after = [](double penalty) {
    Fixture f;
    f.config.actor_preactivation_penalty = penalty;
    Learner learner(f.input, f.config);
    torch::Tensor bias;
    for (const auto& item : learner.agent().actor_head->named_parameters()) {
      if (item.key().find("bias") != std::string::npos) bias = item.value();  // the last layer's
    }
    {
      torch::NoGradGuard no_grad;
      bias.fill_(30.0);
    }
    at::Generator augmentation = at::detail::createCPUGenerator(1);
    at::Generator noise = at::detail::createCPUGenerator(2);
    for (int u = 0; u < 20; ++u) learner.update(f.batch, 0, augmentation, noise);
    return bias.item<double>();
  };
  EXPECT_NEAR(bias_after(0.0), 30.0, 1e-6);
  EXPECT_LT(bias_after(0.01), 30.0 - 0.01);
}

}  // namespace
}  // namespace pixelgym::drqv2
