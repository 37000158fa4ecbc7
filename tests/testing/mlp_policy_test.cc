// MlpPolicy: a small policy file written here by hand, its action worked out by hand; base64 on
// RFC 4648's examples; and each kind of bad file refused with what was expected and what it has.
#include "pixelgym/testing/mlp_policy.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace pixelgym::testing {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

std::string base64_floats(const std::vector<float>& values) {
  std::vector<std::uint8_t> bytes(values.size() * 4);
  std::memcpy(bytes.data(), values.data(), bytes.size());
  return encode_base64(bytes);
}

// Inputs a (2) and b (1); a hidden ReLU layer of 2; 4 outputs, of which the first 2 are the
// action's pre-tanh mean; the action's bounds [-1, 1] and [0, 10].
json small_policy() {
  return {{"format", "pixelgym mlp policy"},
          {"version", 1},
          {"env_id", "Some-v0"},
          {"env_kwargs", {{"obs_mode", "state"}, {"action_repeat", 2}, {"shadows", false}}},
          {"inputs", {{{"key", "a"}, {"size", 2}}, {{"key", "b"}, {"size", 1}}}},
          {"layers",
           {{{"inputs", 3},
             {"outputs", 2},
             {"activation", "relu"},
             {"weight", base64_floats({1, 0, 2, 0, -1, 1})},
             {"bias", base64_floats({0.5f, 0})}},
            {{"inputs", 2},
             {"outputs", 4},
             {"activation", "none"},
             {"weight", base64_floats({1, 1, 0, -1, 7, 7, 7, 7})},
             {"bias", base64_floats({0, 0.25f, 9, 9})}}}},
          {"action", {{"size", 2}, {"low", {-1.0, 0.0}}, {"high", {1.0, 10.0}}}}};
}

// A file of `text` in the temporary folder, named for this process (ctest runs each test in a
// process of its own, several at once, and the sanitizer builds share the folder).
std::string write(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("pixelgym_mlp_policy_" + std::to_string(::getpid()) + "_" + name);
  std::ofstream(path) << text;
  return path.string();
}

Value observation(std::vector<float> a, std::vector<float> b) {
  ValueDict dict;
  dict.insert("b", Value(Array::from_vector<float>({static_cast<std::int64_t>(b.size())}, b)));
  dict.insert("a", Value(Array::from_vector<float>({static_cast<std::int64_t>(a.size())}, a)));
  return Value(std::move(dict));
}

TEST(MlpPolicyTest, ActsAsTheLayersWorkedOutByHand) {
  const MlpPolicy policy = MlpPolicy::load(write("small.json", small_policy().dump()));
  EXPECT_EQ(policy.env_id(), "Some-v0");
  EXPECT_EQ(policy.action_size(), 2);
  EXPECT_EQ(policy.env_kwargs().at("obs_mode").as_string(), "state");
  EXPECT_EQ(policy.env_kwargs().at("action_repeat").as_int(), 2);
  EXPECT_EQ(policy.env_kwargs().at("shadows").as_bool(), false);
  // x = (a0, a1, b) = (1, 3, 0.5): hidden = relu(1 + 2 * 0.5 + 0.5, -3 + 0.5) = (2.5, 0);
  // out = (2.5, -0 + 0.25); action = (tanh 2.5, 5 + 5 tanh 0.25).
  const Array action = policy.act(observation({1, 3}, {0.5f}));
  ASSERT_EQ(action.shape(), Shape({2}));
  EXPECT_EQ(action.dtype(), DType::kFloat32);
  EXPECT_FLOAT_EQ(action.data<float>()[0], static_cast<float>(std::tanh(2.5)));
  EXPECT_FLOAT_EQ(action.data<float>()[1], static_cast<float>(5.0 + 5.0 * std::tanh(0.25)));
  // The inputs are read by key, in the file's order, whatever the Dict's order.
  const Array other = policy.act(observation({0, -1}, {0}));
  // x = (0, -1, 0): hidden = relu(0.5, 1) = (0.5, 1); out = (1.5, -1 + 0.25).
  EXPECT_FLOAT_EQ(other.data<float>()[0], static_cast<float>(std::tanh(1.5)));
  EXPECT_FLOAT_EQ(other.data<float>()[1], static_cast<float>(5.0 + 5.0 * std::tanh(-0.75)));
}

TEST(MlpPolicyTest, ObservationsWithoutItsInputsAreRefusedByKey) {
  const MlpPolicy policy = MlpPolicy::load(write("small.json", small_policy().dump()));
  EXPECT_THAT(
      [&] {
        policy.act(observation({1, 2, 3}, {0}));
      },
      ::testing::ThrowsMessage<std::invalid_argument>(
          HasSubstr("expected \"a\" of 2 floating elements, got 3 float32")));
  ValueDict only_a;
  only_a.insert("a", Value(Array::from_vector<float>({2}, {0, 0})));
  EXPECT_THAT([&] { policy.act(Value(std::move(only_a))); },
              ::testing::ThrowsMessage<std::invalid_argument>(
                  HasSubstr("expected the observation key \"b\", which it does not have")));
  EXPECT_THAT(
      [&] {
        policy.act(Value(Array::from_vector<float>({3}, {0, 0, 0})));
      },
      ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("expected a Dict")));
}

TEST(MlpPolicyTest, Base64IsRfc4648s) {
  const auto bytes = [](const std::string& text) {
    return std::vector<std::uint8_t>(text.begin(), text.end());
  };
  for (const auto& [plain, encoded] :
       std::vector<std::pair<std::string, std::string>>{{"", ""},
                                                        {"f", "Zg=="},
                                                        {"fo", "Zm8="},
                                                        {"foo", "Zm9v"},
                                                        {"foob", "Zm9vYg=="},
                                                        {"fooba", "Zm9vYmE="},
                                                        {"foobar", "Zm9vYmFy"}}) {
    EXPECT_EQ(encode_base64(bytes(plain)), encoded) << plain;
    EXPECT_EQ(decode_base64(encoded), bytes(plain)) << encoded;
  }
  std::vector<std::uint8_t> all(256);
  for (int i = 0; i < 256; ++i) all[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(i);
  EXPECT_EQ(decode_base64(encode_base64(all)), all);
  EXPECT_THAT([] { decode_base64("Zm9"); }, ::testing::ThrowsMessage<std::invalid_argument>(
                                                HasSubstr("blocks of 4 characters, got 3")));
  EXPECT_THAT([] { decode_base64("Zm!v"); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("got '!' at character 2")));
  EXPECT_THAT([] { decode_base64("Z=9v"); },
              ::testing::ThrowsMessage<std::invalid_argument>(HasSubstr("at character 1")));
  // The weights' bytes are little-endian float32: 1.0f is 00 00 80 3f.
  EXPECT_EQ(base64_floats({1.0f}), "AACAPw==");
}

TEST(MlpPolicyTest, BadFilesAreRefusedWithWhatWasExpected) {
  const auto refused = [](const std::string& name, const std::string& text,
                          const std::string& expected) {
    const std::string path = write(name, text);
    try {
      MlpPolicy::load(path);
      ADD_FAILURE() << name << " was accepted";
    } catch (const std::runtime_error& error) {
      EXPECT_THAT(error.what(), HasSubstr("MLP policy " + path + ": " + expected)) << name;
    }
  };
  const auto edited = [](const std::function<void(json&)>& edit) {
    json policy = small_policy();
    edit(policy);
    return policy.dump();
  };
  refused("missing.json", "", "expected JSON, got text that is not");
  EXPECT_THAT([] { MlpPolicy::load("/nonexistent/policy.json"); },
              ::testing::ThrowsMessage<std::runtime_error>(
                  HasSubstr("MLP policy /nonexistent/policy.json: cannot be opened for reading")));
  refused("root.json", "[1, 2]", "expected an object with \"format\", got [1,2]");
  refused("format.json", edited([](json& p) { p["format"] = "onnx"; }),
          "expected format \"pixelgym mlp policy\", got \"onnx\"");
  refused("version.json", edited([](json& p) { p["version"] = 2; }),
          "expected version 1 (what this pixelgym reads), got 2");
  refused("no_layers.json", edited([](json& p) { p.erase("layers"); }),
          "expected a member \"layers\" (an array of layers), got none");
  refused("chain.json", edited([](json& p) { p["layers"][1]["inputs"] = 3; }),
          "layer 1: expected 2 inputs (the layer before's outputs), got 3");
  refused("first.json", edited([](json& p) { p["inputs"][1]["size"] = 2; }),
          "layer 0: expected 4 inputs (the inputs' sizes together), got 3");
  refused("weight.json", edited([](json& p) {
            p["layers"][0]["weight"] = base64_floats({1, 2, 3});
          }),
          "layer 0: expected \"weight\" to hold 6 float32 values (24 bytes), got 12 bytes");
  refused("nan.json", edited([](json& p) {
            p["layers"][0]["bias"] = base64_floats({0, std::nanf("")});
          }),
          "layer 0: \"bias\" value 1 is not finite");
  refused("activation.json", edited([](json& p) { p["layers"][0]["activation"] = "gelu"; }),
          "layer 0: expected activation \"relu\" or \"none\", got \"gelu\"");
  refused("action.json", edited([](json& p) { p["action"]["size"] = 5; }),
          "expected an action of at most the last layer's 4 outputs, got size 5");
  refused("bounds.json", edited([](json& p) { p["action"]["low"] = {-1.0}; }),
          "action: expected \"low\" to hold 2 numbers (the action's size), got [-1.0]");
  refused("size.json", edited([](json& p) { p["inputs"][0]["size"] = -2; }),
          "input 0: expected \"size\" to be an integer from 1 to 16777216, got -2");
  // Sizes whose product would overflow are refused before any arithmetic on them.
  refused(
      "huge.json", edited([](json& p) {
        p["inputs"] = {{{"key", "a"}, {"size", std::int64_t{1} << 62}}};
        p["layers"][0]["inputs"] = std::int64_t{1} << 62;
        p["layers"][0]["weight"] = "";
      }),
      "input 0: expected \"size\" to be an integer from 1 to 16777216, got 4611686018427387904");
  refused("unsigned.json",
          edited([](json& p) { p["layers"][0]["outputs"] = 18446744073709551615ULL; }),
          "layer 0: expected \"outputs\" to be an integer from 1 to 16777216, got "
          "18446744073709551615");
  refused("twice.json", edited([](json& p) { p["inputs"][1]["key"] = "a"; }),
          "input 1: expected each key once, got \"a\" again");
  refused("entry.json", edited([](json& p) { p["inputs"][0] = 3; }),
          "input 0: expected an object with \"key\", got 3");
  refused("base64.json", edited([](json& p) { p["layers"][1]["bias"] = "AAAA!AAA"; }),
          "layer 1: \"bias\": expected base64, got '!' at character 4");
  refused("inverted.json", edited([](json& p) {
            p["action"]["low"] = {2.0, 0.0};
          }),
          "action: expected \"low\" <= \"high\", got 2.000000 > 1.000000 at element 0");
  refused("wide.json", edited([](json& p) {
            p["action"]["high"] = {1.0, 1e39};
          }),
          "action: expected \"high\" value 1 to be a finite float32, got 1e+39");
  refused("text_bound.json", edited([](json& p) {
            p["action"]["low"] = {-1.0, "zero"};
          }),
          "action: expected \"low\" to hold 2 numbers (the action's size)");
}

}  // namespace
}  // namespace pixelgym::testing
