// DrQ's pieces: its config's JSON form and the errors naming each bad member, the squashed
// Gaussian's log-probability, the clipped double Q target, the temperature's direction, the
// actor's and the target's update periods, and an update that learns a fixed batch.
#include "examples/trainer/drq/drq.h"

#include <ATen/CPUGeneratorImpl.h>
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "tests/examples/trainer/torch_common/learner_test_support.h"

namespace pixelgym::drq {
namespace {

using nlohmann::json;
using trainer::testing::all_equal;
using trainer::testing::parameter_copies;
using trainer::testing::pixel_space;
using trainer::testing::random_batch;

constexpr auto parse = trainer::testing::parse_config<DrqConfig>;
constexpr auto expect_refused = trainer::testing::expect_refused<DrqConfig>;

TEST(DrqConfigTest, JsonRoundTripsAndBadMembersAreNamed) {
  DrqConfig config;
  config.hidden_dim = 64;
  config.target_entropy = -3.5;
  config.encoder = EncoderArchitecture::kDrqV2;
  json out;
  to_json(out, config);
  const DrqConfig back = parse(out);
  EXPECT_EQ(back.hidden_dim, 64);
  EXPECT_EQ(back.target_entropy, -3.5);
  EXPECT_EQ(back.encoder, EncoderArchitecture::kDrqV2);
  // The default target entropy is -|A|, written as null.
  json defaults;
  to_json(defaults, DrqConfig{});
  EXPECT_TRUE(defaults.at("target_entropy").is_null());
  EXPECT_TRUE(std::isnan(parse(defaults).target_entropy));
  EXPECT_EQ(DrqConfig{}.entropy_target(6), -6.0);
  EXPECT_EQ(back.entropy_target(6), -3.5);

  expect_refused({{"hiden_dim", 3}}, "hiden_dim");
  expect_refused({{"hidden_dim", 0}}, "hidden_dim");
  expect_refused({{"init_temperature", 0.0}}, "init_temperature");
  expect_refused({{"actor_update_every", 0}}, "actor_update_every");
  expect_refused({{"augmented_copies", 9}}, "augmented_copies");
  expect_refused({{"log_std_min", 1.0}, {"log_std_max", 0.0}}, "log_std_max");
  expect_refused({{"encoder", "big"}}, "encoder");
}

// A learner on 32x32 grey stacks of 3 with one state key (or the state key alone), and a batch
// of random transitions whose reward is the sign of the action.
struct Fixture {
  InputLayout input;
  DrqConfig config;
  ReplayBatch batch;

  explicit Fixture(bool pixels = true) {
    const spaces::Box action(-1.0, 1.0, Shape{1});
    input = pixels
                ? trainer::input_layout(pixel_space({3, 32, 32}), action, 3, "drq", "T-v0")
                : trainer::input_layout(spaces::Box(-1.0, 1.0, Shape{2}), action, 1, "drq", "T-v0");
    config.batch_size = 16;
    config.hidden_dim = 32;
    config.feature_dim = 16;
    batch = random_batch(pixels);
  }
};

// The sample's log-probability is the Gaussian's at the pre-tanh value, less log(1 - tanh^2),
// summed over the action's elements: computed here in double precision from the same draw.
TEST(DrqAgentTest, TheSquashedGaussianLogProbabilityIsTheChangeOfVariables) {
  Fixture f(false);
  f.input.action_size = 3;
  f.input.action_low.assign(3, -1.0f);
  f.input.action_high.assign(3, 1.0f);
  f.config.log_std_min = -5.0;
  f.config.log_std_max = 2.0;
  torch::manual_seed(0);
  Agent agent(f.input, f.config);
  const torch::Tensor features = torch::randn({64, 2});
  at::Generator generator = at::detail::createCPUGenerator(7);
  const PolicySample sample = agent.sample(features, generator);

  // The same draw again, by hand.
  at::Generator again = at::detail::createCPUGenerator(7);
  torch::NoGradGuard no_grad;
  const auto parts = agent.actor->forward(features).chunk(2, 1);
  const torch::Tensor mean = parts[0].to(torch::kFloat64);
  const torch::Tensor log_std = -5.0 + 0.5 * 7.0 * (torch::tanh(parts[1].to(torch::kFloat64)) + 1);
  const torch::Tensor eps =
      torch::randn(parts[0].sizes(), again, parts[0].options()).to(torch::kFloat64);
  const torch::Tensor x = mean + eps * log_std.exp();
  const torch::Tensor gaussian =
      -0.5 * ((x - mean) / log_std.exp()).square() - log_std - 0.5 * std::log(2 * M_PI);
  const torch::Tensor expected = (gaussian - torch::log(1 - torch::tanh(x).square())).sum(1);
  EXPECT_TRUE(torch::allclose(sample.action.to(torch::kFloat64), torch::tanh(x), 1e-5, 1e-6));
  // Where tanh saturates the naive log(1 - tanh^2) loses precision; compare where it does not.
  const torch::Tensor fine = (x.abs() < 4).all(1);
  EXPECT_GT(fine.sum().item<int>(), 32);
  EXPECT_TRUE(torch::allclose(sample.log_prob.to(torch::kFloat64).index({fine}),
                              expected.index({fine}), 1e-3, 1e-3))
      << sample.log_prob.index({fine}).slice(0, 0, 4) << expected.index({fine}).slice(0, 0, 4);
  // The mean action is the tanh of the Gaussian's mean.
  EXPECT_TRUE(torch::allclose(agent.mean_action(features).to(torch::kFloat64), torch::tanh(mean),
                              1e-5, 1e-6));
}

// The target is the reward plus the discounted minimum of the two target critics: raising one
// of them changes nothing, lowering it lowers the target.
TEST(DrqLearnerTest, TheTargetTakesTheLowerOfTheTwoTargetCritics) {
  const auto target_after_shift = [](double shift) {
    Fixture f(false);
    f.batch.discounts.assign(16, 0.9f);
    f.config.init_temperature = 1e-8;  // no entropy term
    Learner learner(f.input, f.config);
    {
      torch::NoGradGuard no_grad;
      auto parameters = learner.agent().target_q2->parameters();
      parameters.back().add_(shift);  // the output bias
    }
    at::Generator augmentation = at::detail::createCPUGenerator(1);
    at::Generator sampling = at::detail::createCPUGenerator(2);
    return learner.update(f.batch, augmentation, sampling).target_mean;
  };
  const double base = target_after_shift(0.0);
  EXPECT_NEAR(target_after_shift(100.0), base, 0.05);
  EXPECT_LT(target_after_shift(-100.0), base - 80.0);
}

// The temperature falls while the policy's entropy is above the target and rises while it is
// below.
TEST(DrqLearnerTest, TheTemperatureMovesTowardsTheTargetEntropy) {
  const auto alpha_after = [](double target_entropy) {
    Fixture f;
    f.config.target_entropy = target_entropy;
    f.config.actor_update_every = 1;
    Learner learner(f.input, f.config);
    at::Generator augmentation = at::detail::createCPUGenerator(1);
    at::Generator sampling = at::detail::createCPUGenerator(2);
    for (int u = 0; u < 10; ++u) learner.update(f.batch, augmentation, sampling);
    return learner.agent().log_alpha.exp().item<double>();
  };
  EXPECT_LT(alpha_after(-50.0), 0.1 * 0.995);
  EXPECT_GT(alpha_after(50.0), 0.1 * 1.005);
}

// With actor_update_every 2 and target_update_every 3 the actor moves on updates 0, 2, 4 and the
// target critic on updates 0, 3 (counting from 0), by tau of the way to the critic.
TEST(DrqLearnerTest, TheActorAndTheTargetMoveOnTheirOwnPeriods) {
  Fixture f;
  f.config.actor_update_every = 2;
  f.config.target_update_every = 3;
  f.config.critic_tau = 0.25;
  Learner learner(f.input, f.config);
  Agent& agent = learner.agent();
  EXPECT_TRUE(all_equal(parameter_copies(*agent.q1), parameter_copies(*agent.target_q1)));
  EXPECT_TRUE(
      all_equal(parameter_copies(*agent.critic_head), parameter_copies(*agent.target_head)));
  for (const auto& p : agent.target_head->parameters()) EXPECT_FALSE(p.requires_grad());
  at::Generator augmentation = at::detail::createCPUGenerator(1);
  at::Generator sampling = at::detail::createCPUGenerator(2);
  for (int u = 0; u < 5; ++u) {
    const auto actor_before = parameter_copies(*agent.actor);
    const auto target_before = parameter_copies(*agent.target_q1);
    const UpdateStats stats = learner.update(f.batch, augmentation, sampling);
    const bool actor_due = u % 2 == 0;
    EXPECT_EQ(!all_equal(actor_before, parameter_copies(*agent.actor)), actor_due)
        << "update " << u;
    EXPECT_EQ(std::isnan(stats.actor_loss), !actor_due) << "update " << u;
    const auto target_after = parameter_copies(*agent.target_q1);
    if (u % 3 == 0) {
      const auto critic = parameter_copies(*agent.q1);
      for (std::size_t i = 0; i < critic.size(); ++i) {
        const torch::Tensor expected = target_before[i] + 0.25 * (critic[i] - target_before[i]);
        EXPECT_TRUE(torch::allclose(target_after[i], expected, 1e-5, 1e-6)) << "update " << u;
      }
    } else {
      EXPECT_TRUE(all_equal(target_before, target_after)) << "update " << u;
    }
  }
  EXPECT_EQ(learner.updates(), 5);
}

TEST(DrqLearnerTest, UpdatesFitAFixedBatchAndAreDeterministic) {
  for (const bool pixels : {true, false}) {
    for (const std::int64_t copies_of_each : {1, 2}) {
      Fixture f(pixels);
      f.config.augmented_copies = copies_of_each;
      const auto run = [&](std::vector<double>* losses) {
        Learner learner(f.input, f.config);
        at::Generator augmentation = at::detail::createCPUGenerator(1);
        at::Generator sampling = at::detail::createCPUGenerator(2);
        for (int u = 0; u < 60; ++u) {
          losses->push_back(learner.update(f.batch, augmentation, sampling).critic_loss);
        }
        return parameter_copies(learner.agent());
      };
      std::vector<double> losses, again;
      const auto a = run(&losses);
      const auto b = run(&again);
      EXPECT_LT(losses.back(), 0.3 * losses.front())
          << (pixels ? "pixels" : "state") << " x" << copies_of_each << ": " << losses.front()
          << " -> " << losses.back();
      EXPECT_EQ(losses, again);
      EXPECT_TRUE(all_equal(a, b));
    }
  }
}

}  // namespace
}  // namespace pixelgym::drq
