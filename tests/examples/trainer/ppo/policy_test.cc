// Policy: output shapes and bounds for Box and Discrete actions, Dict observations (an image and
// a vector key), every image layout the wrappers produce (frame stacks included), log-probs and
// entropies against the Normal and Categorical formulas written out, sampling against the
// distribution scored, observation normalization, the random shift, and zero-copy views.
#include "examples/trainer/ppo/policy.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/spaces/multi_discrete.h"

namespace pixelgym::ppo {
namespace {

constexpr double kLog2Pi = 1.8378770664093453;

SpacePtr box(double low, double high, Shape shape, DType dtype = DType::kFloat32) {
  return std::make_shared<spaces::Box>(low, high, std::move(shape), dtype);
}

torch::Tensor batch_of(std::int64_t b, const Shape& shape, DType dtype) {
  std::vector<std::int64_t> sizes{b};
  sizes.insert(sizes.end(), shape.begin(), shape.end());
  if (dtype == DType::kUInt8) return torch::randint(0, 256, sizes, torch::kUInt8);
  return torch::randn(sizes);
}

// Makes the action head ignore its input: logits (or the Gaussian mean) = `bias`.
void set_constant_head(Policy& policy, const std::vector<float>& bias) {
  torch::NoGradGuard no_grad;
  for (auto& item : policy.named_parameters()) {
    if (item.key() == "action_head.weight") item.value().zero_();
    if (item.key() == "action_head.bias") item.value().copy_(torch::tensor(bias));
  }
}

TEST(Policy, BoxActionsHaveTheRightShapesAndEnvActionsStayInBounds) {
  torch::manual_seed(1);
  const spaces::Box actions({-1.0, -2.0}, {1.0, 0.5}, {2});
  PolicyConfig config;
  config.initial_log_std = 1.0;  // std e: many samples fall outside the bounds
  Policy policy(*box(-5, 5, {3}), actions, config);
  const ObservationTensors obs{{"", torch::randn({64, 3})}};
  const ActResult out = policy.act(obs, /*deterministic=*/false);
  EXPECT_EQ(out.action.sizes(), (std::vector<std::int64_t>{64, 2}));
  EXPECT_EQ(out.env_action.sizes(), (std::vector<std::int64_t>{64, 2}));
  EXPECT_EQ(out.log_prob.sizes(), (std::vector<std::int64_t>{64}));
  EXPECT_EQ(out.value.sizes(), (std::vector<std::int64_t>{64}));
  EXPECT_EQ(out.env_action.scalar_type(), torch::kFloat32);
  const torch::Tensor low = torch::tensor({-1.0f, -2.0f});
  const torch::Tensor high = torch::tensor({1.0f, 0.5f});
  EXPECT_TRUE((out.env_action >= low).all().item<bool>());
  EXPECT_TRUE((out.env_action <= high).all().item<bool>());
  // Clipped, not squashed: in-bounds samples pass unchanged, the others sit on the bound.
  EXPECT_TRUE(((out.action < low) | (out.action > high)).any().item<bool>());
  EXPECT_TRUE(torch::equal(out.env_action, torch::max(torch::min(out.action, high), low)));
  // Deterministic: the mean, the same twice.
  const ActResult mode1 = policy.act(obs, true);
  const ActResult mode2 = policy.act(obs, true);
  EXPECT_TRUE(torch::equal(mode1.action, mode2.action));
}

TEST(Policy, ClippedElementsCountsTheActionElementsOutsideTheBounds) {
  const spaces::Box actions({-1.0, -2.0}, {1.0, 0.5}, {2});
  Policy policy(*box(-5, 5, {3}), actions, PolicyConfig{});
  const ObservationTensors obs{{"", torch::randn({16, 3})}};
  set_constant_head(policy, {3.0F, 0.0F});  // the first element past its bound, the second in
  EXPECT_EQ(policy.act(obs, /*deterministic=*/true).clipped_elements(), 16);
  set_constant_head(policy, {-3.0F, 0.7F});  // both past a bound
  EXPECT_EQ(policy.act(obs, true).clipped_elements(), 32);
  set_constant_head(policy, {0.5F, -1.0F});
  EXPECT_EQ(policy.act(obs, true).clipped_elements(), 0);
  // Discrete actions are never clipped.
  Policy discrete(*box(-5, 5, {3}), spaces::Discrete(3), PolicyConfig{});
  EXPECT_EQ(discrete.act(obs, true).clipped_elements(), 0);
}

TEST(Policy, DiscreteActionsAreIndicesAndEnvActionsAddTheStart) {
  torch::manual_seed(2);
  Policy policy(*box(-1, 1, {4}), spaces::Discrete(3, /*start=*/2));
  const ObservationTensors obs{{"", torch::randn({500, 4})}};
  const ActResult out = policy.act(obs, false);
  EXPECT_EQ(out.action.sizes(), (std::vector<std::int64_t>{500}));
  EXPECT_EQ(out.action.scalar_type(), torch::kInt64);
  EXPECT_EQ(out.env_action.scalar_type(), torch::kInt64);
  EXPECT_EQ(out.action.min().item<std::int64_t>(), 0);
  EXPECT_EQ(out.action.max().item<std::int64_t>(), 2);
  EXPECT_TRUE(torch::equal(out.env_action, out.action + 2));
  EXPECT_EQ(out.log_prob.sizes(), (std::vector<std::int64_t>{500}));
  EXPECT_TRUE((out.log_prob <= 0).all().item<bool>());
}

TEST(Policy, DictOfAnImageAndAVectorUsesBoth) {
  torch::manual_seed(3);
  spaces::Dict space(
      {{"pixels", box(0, 255, {64, 64, 3}, DType::kUInt8)}, {"joint_pos", box(-1, 1, {2})}});
  Policy policy(space, spaces::Box(-1, 1, {1}));
  ASSERT_EQ(policy.inputs().size(), 2u);
  EXPECT_TRUE(policy.inputs()[0].image);
  EXPECT_EQ(policy.inputs()[0].layout, ImageLayout::kHWC);
  EXPECT_FALSE(policy.inputs()[1].image);
  ObservationTensors obs{{"pixels", batch_of(8, {64, 64, 3}, DType::kUInt8)},
                         {"joint_pos", torch::randn({8, 2})}};
  const ActResult out = policy.act(obs, true);
  EXPECT_EQ(out.action.sizes(), (std::vector<std::int64_t>{8, 1}));
  EXPECT_EQ(out.value.sizes(), (std::vector<std::int64_t>{8}));
  // Changing either key changes the value: both encoders reach the heads.
  ObservationTensors other_pixels = obs;
  other_pixels["pixels"] = batch_of(8, {64, 64, 3}, DType::kUInt8);
  ObservationTensors other_joints = obs;
  other_joints["joint_pos"] = torch::randn({8, 2});
  EXPECT_FALSE(torch::allclose(policy.value(obs), policy.value(other_pixels)));
  EXPECT_FALSE(torch::allclose(policy.value(obs), policy.value(other_joints)));
  // A missing key or a wrong shape is refused, naming the key.
  ObservationTensors missing{{"pixels", obs["pixels"]}};
  EXPECT_THROW(policy.act(missing, true), std::invalid_argument);
  ObservationTensors wrong = obs;
  wrong["joint_pos"] = torch::randn({8, 3});
  EXPECT_THROW(policy.act(wrong, true), std::invalid_argument);
}

// separate_value_network: the value reads an encoder of its own (every part of the shared one
// copied under a "value_" prefix), the value's gradient reaches none of the policy's layers and
// the action's none of the value's, and the shared layers start with the same weights as without
// the option.
TEST(Policy, SeparateValueNetworkSharesNoLayerWithThePolicy) {
  spaces::Dict space(
      {{"pixels", box(0, 255, {64, 64, 3}, DType::kUInt8)}, {"joint_pos", box(-1, 1, {2})}});
  PolicyConfig config;
  config.separate_value_network = true;
  torch::manual_seed(10);
  Policy separate(space, spaces::Box(-1, 1, {1}), config);
  torch::manual_seed(10);
  Policy shared(space, spaces::Box(-1, 1, {1}));

  const auto separate_parameters = separate.named_parameters();
  const auto shared_parameters = shared.named_parameters();
  std::size_t value_parameters = 0;
  for (const auto& item : separate_parameters) {
    if (item.key().rfind("value_", 0) == 0 && item.key().rfind("value_head", 0) != 0) {
      ++value_parameters;
      // Each value_ parameter mirrors a policy one of the same shape.
      const torch::Tensor* twin = separate_parameters.find(item.key().substr(6));
      ASSERT_NE(twin, nullptr) << item.key();
      EXPECT_EQ(twin->sizes(), item.value().sizes()) << item.key();
    } else {
      const torch::Tensor* same = shared_parameters.find(item.key());
      ASSERT_NE(same, nullptr) << item.key();
      if (item.key().rfind("value_head", 0) != 0) {
        EXPECT_TRUE(torch::equal(*same, item.value())) << item.key();
      }
    }
  }
  // Weights and biases of cnn0 (the small CNN: 2 convolutions and a linear), mlp (2 linears)
  // and trunk (1 linear).
  EXPECT_EQ(value_parameters, 12u);
  EXPECT_EQ(separate_parameters.size(), shared_parameters.size() + value_parameters);

  ObservationTensors obs{{"pixels", batch_of(4, {64, 64, 3}, DType::kUInt8)},
                         {"joint_pos", torch::randn({4, 2})}};
  const auto gradient_reaches = [&](const torch::Tensor& loss) {
    separate.zero_grad();
    loss.backward();
    std::vector<std::string> reached;
    for (const auto& item : separate.named_parameters()) {
      const torch::Tensor& grad = item.value().grad();
      if (grad.defined() && grad.abs().sum().item<double>() > 0.0) reached.push_back(item.key());
    }
    return reached;
  };
  const torch::Tensor actions = torch::zeros({4, 1});
  for (const std::string& key : gradient_reaches(separate.evaluate(obs, actions).value.sum())) {
    EXPECT_EQ(key.rfind("value_", 0), 0u) << key << " gets the value's gradient";
  }
  const auto from_log_prob = gradient_reaches(separate.evaluate(obs, actions).log_prob.sum());
  EXPECT_FALSE(from_log_prob.empty());
  for (const std::string& key : from_log_prob) {
    EXPECT_NE(key.rfind("value_", 0), 0u) << key << " gets the policy's gradient";
  }
}

// The frame-stack layouts (FrameStackObservation: new_axis, channels_first, channels_last; with
// or without ChannelFirstObservation) of the same three RGB frames give the same network input:
// policies with the same weights give the same values.
TEST(Policy, EveryFrameStackLayoutOfTheSameFramesGivesTheSameOutput) {
  const std::int64_t k = 3, c = 3, h = 36, w = 40;
  const torch::Tensor frames =
      torch::randint(0, 256, {5, k, h, w, c}, torch::kUInt8);  // (B,k,H,W,C)
  struct Case {
    Shape shape;
    ImageLayout layout;
    torch::Tensor batch;
  };
  const std::vector<Case> cases = {
      {{k, h, w, c}, ImageLayout::kStackedHWC, frames},
      {{k, c, h, w}, ImageLayout::kStackedCHW, frames.permute({0, 1, 4, 2, 3}).contiguous()},
      {{k * c, h, w}, ImageLayout::kCHW, frames.permute({0, 1, 4, 2, 3}).reshape({5, k * c, h, w})},
      {{h, w, k * c}, ImageLayout::kHWC, frames.permute({0, 2, 3, 1, 4}).reshape({5, h, w, k * c})},
  };
  torch::Tensor reference;
  for (const Case& each : cases) {
    torch::manual_seed(4);
    Policy policy(*box(0, 255, each.shape, DType::kUInt8), spaces::Discrete(2));
    ASSERT_EQ(policy.inputs()[0].layout, each.layout) << shape_to_string(each.shape);
    EXPECT_EQ(policy.inputs()[0].channels, k * c);
    EXPECT_EQ(policy.inputs()[0].height, h);
    EXPECT_EQ(policy.inputs()[0].width, w);
    const torch::Tensor value = policy.value({{"", each.batch}});
    if (!reference.defined()) {
      reference = value;
    } else {
      EXPECT_TRUE(torch::allclose(value, reference, 1e-5, 1e-6)) << shape_to_string(each.shape);
    }
  }
}

TEST(Policy, GrayscaleImagesAndStacksOfThem) {
  torch::manual_seed(5);
  Policy gray(*box(0, 255, {64, 48}, DType::kUInt8), spaces::Discrete(2));
  EXPECT_EQ(gray.inputs()[0].layout, ImageLayout::kHW);
  EXPECT_EQ(gray.inputs()[0].channels, 1);
  EXPECT_EQ(gray.act({{"", batch_of(2, {64, 48}, DType::kUInt8)}}, false).value.size(0), 2);
  Policy stacked(*box(0, 255, {4, 64, 48}, DType::kUInt8), spaces::Discrete(2));  // new_axis
  EXPECT_EQ(stacked.inputs()[0].layout, ImageLayout::kCHW);
  EXPECT_EQ(stacked.inputs()[0].channels, 4);
  EXPECT_EQ(stacked.inputs()[0].height, 64);
  EXPECT_EQ(stacked.inputs()[0].width, 48);
}

TEST(Policy, ImagesAreScaledToUnitRangeInsideTheNetwork) {
  // An all-255 uint8 image through the policy equals its own modules fed float 1.0: the
  // scaling by 1/255 happens inside the network.
  torch::manual_seed(6);
  Policy policy(*box(0, 255, {3, 36, 36}, DType::kUInt8), spaces::Discrete(2));
  const torch::Tensor full = torch::full({1, 3, 36, 36}, 255, torch::kUInt8);
  const torch::Tensor half = torch::full({1, 3, 36, 36}, 128, torch::kUInt8);
  auto cnn = policy.named_children()["cnn0"];
  auto trunk = policy.named_children()["trunk"];
  auto head = policy.named_children()["value_head"];
  torch::Tensor by_hand =
      cnn->as<torch::nn::SequentialImpl>()->forward(torch::ones({1, 3, 36, 36}));
  by_hand = trunk->as<torch::nn::SequentialImpl>()->forward(by_hand);
  by_hand = head->as<torch::nn::LinearImpl>()->forward(by_hand).squeeze(1);
  EXPECT_TRUE(torch::allclose(policy.value({{"", full}}), by_hand, 1e-5, 1e-6));
  EXPECT_FALSE(torch::allclose(policy.value({{"", half}}), by_hand, 1e-5, 1e-6));
}

TEST(Policy, GaussianLogProbAndEntropyMatchTheNormalFormula) {
  torch::manual_seed(7);
  Policy policy(*box(-1, 1, {3}), spaces::Box(-1, 1, {2}));
  const std::vector<double> mean{0.25, -0.5};
  const std::vector<double> log_std{0.3, -0.7};
  set_constant_head(policy, {0.25f, -0.5f});
  {
    torch::NoGradGuard no_grad;
    policy.named_parameters()["log_std"].copy_(torch::tensor({0.3f, -0.7f}));
  }
  const ObservationTensors obs{{"", torch::randn({3, 3})}};
  const std::vector<std::vector<double>> actions{{0.0, 0.0}, {1.5, -2.0}, {0.25, -0.4}};
  const torch::Tensor action_tensor =
      torch::tensor({0.0f, 0.0f, 1.5f, -2.0f, 0.25f, -0.4f}).reshape({3, 2});
  const Evaluation e = policy.evaluate(obs, action_tensor);
  double entropy = 0.0;
  for (double s : log_std) entropy += 0.5 + 0.5 * kLog2Pi + s;
  for (int row = 0; row < 3; ++row) {
    double log_prob = 0.0;
    for (int i = 0; i < 2; ++i) {
      const double sigma = std::exp(log_std[i]);
      const double z = (actions[row][i] - mean[i]) / sigma;
      log_prob += -0.5 * z * z - std::log(sigma) - 0.5 * kLog2Pi;
    }
    EXPECT_NEAR(e.log_prob[row].item<double>(), log_prob, 1e-5) << "row " << row;
    EXPECT_NEAR(e.entropy[row].item<double>(), entropy, 1e-5) << "row " << row;
  }
  // act scores its own samples the same way, and they follow N(mean, sigma).
  const ObservationTensors many{{"", torch::randn({20000, 3})}};
  const ActResult out = policy.act(many, false);
  EXPECT_TRUE(
      torch::allclose(out.log_prob, policy.evaluate(many, out.action).log_prob, 1e-4, 1e-5));
  for (int i = 0; i < 2; ++i) {
    const torch::Tensor column = out.action.select(1, i);
    EXPECT_NEAR(column.mean().item<double>(), mean[i], 0.03);
    EXPECT_NEAR(column.std().item<double>(), std::exp(log_std[i]), 0.03);
  }
  // Deterministic: the mean itself.
  const ActResult mode = policy.act(obs, true);
  EXPECT_NEAR(mode.action[1][0].item<double>(), mean[0], 1e-6);
  EXPECT_NEAR(mode.action[1][1].item<double>(), mean[1], 1e-6);
}

TEST(Policy, CategoricalLogProbAndEntropyMatchTheSoftmaxFormula) {
  torch::manual_seed(8);
  Policy policy(*box(-1, 1, {3}), spaces::Discrete(3));
  const std::vector<double> logits{1.0, 2.0, 0.5};
  set_constant_head(policy, {1.0f, 2.0f, 0.5f});
  double normalizer = 0.0;
  for (double l : logits) normalizer += std::exp(l);
  std::vector<double> p;
  double entropy = 0.0;
  for (double l : logits) {
    p.push_back(std::exp(l) / normalizer);
    entropy -= p.back() * std::log(p.back());
  }
  const ObservationTensors obs{{"", torch::randn({3, 3})}};
  const Evaluation e = policy.evaluate(obs, torch::tensor({0, 1, 2}, torch::kInt64));
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(e.log_prob[a].item<double>(), std::log(p[static_cast<std::size_t>(a)]), 1e-5);
    EXPECT_NEAR(e.entropy[a].item<double>(), entropy, 1e-5);
  }
  // Samples follow the probabilities; the mode is the argmax.
  const ObservationTensors many{{"", torch::randn({20000, 3})}};
  const ActResult out = policy.act(many, false);
  for (int a = 0; a < 3; ++a) {
    const double frequency = (out.action == a).to(torch::kFloat64).mean().item<double>();
    EXPECT_NEAR(frequency, p[static_cast<std::size_t>(a)], 0.015) << "action " << a;
  }
  EXPECT_TRUE((policy.act(obs, true).action == 1).all().item<bool>());
}

TEST(Policy, ObservationNormalizationUsesTheRunningStatistics) {
  PolicyConfig config;
  config.observation_clip = 3.0;
  torch::manual_seed(9);
  Policy normalized(*box(-100, 100, {2}), spaces::Discrete(2), config);
  config.normalize_observations = false;
  torch::manual_seed(9);
  Policy plain(*box(-100, 100, {2}), spaces::Discrete(2), config);

  const torch::Tensor data =
      torch::tensor({10.0f, -4.0f, 14.0f, -2.0f, 12.0f, 0.0f}).reshape({3, 2});
  normalized.update_observation_statistics({{"", data}});
  const wrappers::RunningStatistics statistics = normalized.observation_statistics("");
  wrappers::RunningStatistics expected = wrappers::RunningStatistics::initial(2);
  expected.update_batch(3, [&](std::size_t row, std::size_t i) {
    return static_cast<double>(
        data[static_cast<std::int64_t>(row)][static_cast<std::int64_t>(i)].item<float>());
  });
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_DOUBLE_EQ(statistics.mean[i], expected.mean[i]);
    EXPECT_DOUBLE_EQ(statistics.var[i], expected.var[i]);
  }
  EXPECT_DOUBLE_EQ(statistics.count, expected.count);

  // The normalized policy sees (x - mean) / sqrt(var + 1e-8), clamped to +-3.
  const torch::Tensor x = torch::tensor({13.0f, -3.0f, 100.0f, -100.0f}).reshape({2, 2});
  const torch::Tensor mean = torch::tensor(expected.mean).to(torch::kFloat32);
  const torch::Tensor std = (torch::tensor(expected.var) + 1e-8).sqrt().to(torch::kFloat32);
  const torch::Tensor standardized = ((x - mean) / std).clamp(-3.0, 3.0);
  EXPECT_TRUE(
      torch::allclose(normalized.value({{"", x}}), plain.value({{"", standardized}}), 1e-5, 1e-6));
  EXPECT_THROW(normalized.observation_statistics("pixels"), std::out_of_range);
  wrappers::RunningStatistics bad = expected;
  bad.var[0] = -1.0;
  EXPECT_THROW(normalized.set_observation_statistics("", bad), std::invalid_argument);
}

TEST(RandomShift, PadsByRepeatingEdgesAndCrops) {
  const torch::Tensor image =
      torch::arange(15, torch::kFloat32).reshape({1, 1, 3, 5}).repeat({2, 2, 1, 1});
  // Image 0: offset (pad, pad), unchanged. Image 1: rows + 1 (up by one, last row repeated),
  // columns - 2 (right by two, first column repeated).
  const torch::Tensor shifts = torch::tensor({2, 2, 3, 0}, torch::kInt64).reshape({2, 2});
  const torch::Tensor out = random_shift(image, shifts, 2);
  EXPECT_TRUE(torch::equal(out[0], image[0]));
  const torch::Tensor expected = torch::tensor({5, 5, 5, 6, 7,       //
                                                10, 10, 10, 11, 12,  //
                                                10, 10, 10, 11, 12},
                                               torch::kFloat32)
                                     .reshape({3, 5});
  EXPECT_TRUE(torch::equal(out[1][0], expected));
  EXPECT_TRUE(torch::equal(out[1][1], expected));
  EXPECT_THROW(random_shift(image, torch::tensor({5, 0, 0, 0}, torch::kInt64).reshape({2, 2}), 2),
               std::invalid_argument);
}

TEST(ArrayTensor, ViewsTheArrayWithoutCopyingAndKeepsItAlive) {
  torch::Tensor tensor;
  const void* data = nullptr;
  {
    Array array = Array::from_vector<float>({2, 2}, {1, 2, 3, 4});
    data = array.raw_data();
    tensor = array_tensor(array);
    array.data<float>()[3] = 9;  // seen through the view
  }
  EXPECT_EQ(tensor.data_ptr(), data);
  EXPECT_EQ(tensor.sizes(), (std::vector<std::int64_t>{2, 2}));
  EXPECT_FLOAT_EQ(tensor[1][1].item<float>(), 9.0f);
  const Value dict = ValueDict{{"pixels", Array(DType::kUInt8, {2, 4, 4, 3})},
                               {"joint_pos", Array(DType::kFloat32, {2, 3})}};
  const ObservationTensors tensors = observation_tensors(dict);
  EXPECT_EQ(tensors.at("pixels").scalar_type(), torch::kUInt8);
  EXPECT_EQ(tensors.at("pixels").data_ptr(), dict.dict().at("pixels").array().raw_data());
}

TEST(Policy, EachCnnHasItsLayersAndServesA64x64FrameStack) {
  struct Expected {
    CnnArchitecture cnn;
    const char* name;
    std::vector<std::vector<std::int64_t>> conv_weights;  // (out, in, kh, kw) per conv
    std::int64_t flat;                                    // the linear layer's input width
  };
  // (64 - k) / s + 1 per conv: nature 15, 6, 4; small 15, 6; fine 31, 15, 7; finer 31, 15, 13.
  const std::vector<Expected> expected = {
      {CnnArchitecture::kNature,
       "nature",
       {{32, 9, 8, 8}, {64, 32, 4, 4}, {64, 64, 3, 3}},
       64 * 4 * 4},
      {CnnArchitecture::kSmall, "small", {{16, 9, 8, 8}, {32, 16, 4, 4}}, 32 * 6 * 6},
      {CnnArchitecture::kFine, "fine", {{32, 9, 3, 3}, {32, 32, 3, 3}, {32, 32, 3, 3}}, 32 * 7 * 7},
      {CnnArchitecture::kFiner,
       "finer",
       {{32, 9, 3, 3}, {32, 32, 3, 3}, {32, 32, 3, 3}},
       32 * 13 * 13},
  };
  for (const Expected& e : expected) {
    SCOPED_TRACE(e.name);
    EXPECT_STREQ(to_string(e.cnn), e.name);
    EXPECT_EQ(parse_cnn_architecture(e.name), e.cnn);
    PolicyConfig config;
    config.cnn = e.cnn;
    torch::manual_seed(2);
    Policy policy(*box(0, 255, {64, 64, 9}, DType::kUInt8), *box(-1, 1, {1}), config);
    std::vector<std::vector<std::int64_t>> conv_weights;
    std::int64_t flat = 0;
    for (const auto& item : policy.named_parameters()) {
      if (item.key().rfind("cnn0.", 0) != 0 || item.key().find(".weight") == std::string::npos) {
        continue;
      }
      const auto sizes = item.value().sizes().vec();
      if (sizes.size() == 4) conv_weights.push_back(sizes);
      if (sizes.size() == 2) flat = sizes[1];
    }
    EXPECT_EQ(conv_weights, e.conv_weights);
    EXPECT_EQ(flat, e.flat);
    const ObservationTensors obs{{"", batch_of(5, {64, 64, 9}, DType::kUInt8)}};
    const ActResult out = policy.act(obs, false);
    EXPECT_EQ(out.action.sizes(), (std::vector<std::int64_t>{5, 1}));
    EXPECT_EQ(out.value.sizes(), (std::vector<std::int64_t>{5}));
    EXPECT_TRUE(torch::isfinite(out.value).all().item<bool>());
  }
  try {
    parse_cnn_architecture("impala");
    ADD_FAILURE() << "an unknown CNN name was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("\"fine\""), std::string::npos) << error.what();
  }
  PolicyConfig fine;
  fine.cnn = CnnArchitecture::kFine;  // 6x6: 2x2 after one conv, nothing after the second
  try {
    Policy(*box(0, 255, {6, 6, 3}, DType::kUInt8), *box(-1, 1, {1}), fine);
    ADD_FAILURE() << "a 6x6 image was accepted by the fine CNN";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("fine CNN"), std::string::npos) << error.what();
  }
}

TEST(Policy, RejectsSpacesItCannotServe) {
  EXPECT_THROW(Policy(*box(-1, 1, {2}), spaces::MultiDiscrete({2, 2})), std::invalid_argument);
  EXPECT_THROW(Policy(*box(-1, 1, {2}), spaces::Box(-1, 1, {2}, DType::kInt64)),
               std::invalid_argument);
  EXPECT_THROW(Policy(*box(0, 255, {8, 8, 3}, DType::kUInt8), spaces::Discrete(2)),
               std::invalid_argument);  // smaller than the CNN's receptive field
  PolicyConfig bad;
  bad.observation_clip = 0.0;
  EXPECT_THROW(Policy(*box(-1, 1, {2}), spaces::Discrete(2), bad), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::ppo
