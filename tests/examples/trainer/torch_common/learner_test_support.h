// What the tests of the off-policy learners (DrQ's, DrQ-v2's) and of their shared torch layer
// have in common: checks of a config's JSON form (every member round-trips, bad members are
// refused by name, the shipped recipes parse), an observation space of pixels beside a state
// key, a batch of random transitions to fit, and copies of a module's parameters to compare.
#pragma once

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "examples/trainer/torch_common/replay_buffer.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"

namespace pixelgym::trainer::testing {

/// The Config that `in` reads into (from_json, which validates).
template <typename Config>
Config parse_config(const nlohmann::json& in) {
  Config config;
  from_json(in, config);
  return config;
}

/// Fails unless reading `in` throws std::invalid_argument whose message contains `word`.
template <typename Config>
void expect_refused(const nlohmann::json& in, const std::string& word) {
  try {
    parse_config<Config>(in);
    ADD_FAILURE() << in.dump() << " was accepted; expected an error naming " << word;
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find(word), std::string::npos) << error.what();
  }
}

/// Each member, changed alone to another valid value, is written, read and written back as it
/// was, so that none is written but not read. Integers go up by one, floats halve, bools flip,
/// the encoder's name changes, and a null (a target entropy's default) becomes -2.
template <typename Config>
void expect_every_member_round_trips() {
  nlohmann::json defaults;
  to_json(defaults, Config{});
  for (const auto& item : defaults.items()) {
    const std::string& key = item.key();
    const nlohmann::json& value = item.value();
    nlohmann::json changed = defaults;
    nlohmann::json& member = changed[key];
    if (value.is_boolean()) {
      member = !value.get<bool>();
    } else if (value.is_number_integer()) {
      member = value.get<std::int64_t>() + 1;
    } else if (value.is_number_float()) {
      member = value.get<double>() * 0.5;
    } else if (value.is_string()) {
      member = value.get<std::string>() == "drqv2" ? "fine" : "drqv2";
    } else {
      member = -2.0;
    }
    nlohmann::json back;
    to_json(back, parse_config<Config>(changed));
    EXPECT_EQ(back.at(key), member) << key;
  }
}

/// Reads every .json file in `folder` (an algorithm's shipped recipes) as a Config; returns how
/// many there were.
template <typename Config>
int expect_every_config_parses(const std::filesystem::path& folder) {
  int parsed = 0;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream in(entry.path());
    EXPECT_NO_THROW(parse_config<Config>(nlohmann::json::parse(in))) << entry.path();
    ++parsed;
  }
  return parsed;
}

/// A Dict of uint8 "pixels" of shape `pixels` and a 2-value "joint_pos".
inline spaces::Dict pixel_space(Shape pixels) {
  return spaces::Dict({{"pixels", std::make_shared<spaces::Box>(0.0, 255.0, pixels, DType::kUInt8)},
                       {"joint_pos", std::make_shared<spaces::Box>(-1.0, 1.0, Shape{2})}});
}

/// 16 random terminal transitions (the target is the reward) of a 1-element action whose reward
/// is the action's sign: with `pixels`, stacks of 3 grey 32x32 frames beside a 2-value state
/// key; without, the state key alone.
inline ReplayBatch random_batch(bool pixels) {
  std::mt19937 rng(3);
  const std::size_t b = 16;
  ReplayBatch batch;
  batch.size = static_cast<std::int64_t>(b);
  if (pixels) {
    for (auto* images : {&batch.images, &batch.next_images}) {
      images->assign(1, std::vector<std::uint8_t>(b * 3 * 32 * 32));
      for (auto& v : (*images)[0]) v = static_cast<std::uint8_t>(rng() % 256);
    }
  }
  for (auto* vectors : {&batch.vectors, &batch.next_vectors}) {
    vectors->assign(1, std::vector<float>(b * 2));
    for (auto& v : (*vectors)[0]) v = static_cast<float>(rng() % 100) / 100.0f;
  }
  batch.actions.resize(b);
  batch.rewards.resize(b);
  batch.discounts.assign(b, 0.0f);
  for (std::size_t i = 0; i < b; ++i) {
    batch.actions[i] = static_cast<float>(rng() % 200) / 100.0f - 1.0f;
    batch.rewards[i] = batch.actions[i] > 0.0f ? 1.0f : -1.0f;
  }
  return batch;
}

/// Detached copies of `module`'s parameters, in order.
inline std::vector<torch::Tensor> parameter_copies(const torch::nn::Module& module) {
  std::vector<torch::Tensor> out;
  for (const auto& p : module.parameters()) out.push_back(p.detach().clone());
  return out;
}

/// Whether two lists of tensors are equal element by element.
inline bool all_equal(const std::vector<torch::Tensor>& a, const std::vector<torch::Tensor>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!torch::equal(a[i], b[i])) return false;
  }
  return true;
}

}  // namespace pixelgym::trainer::testing
