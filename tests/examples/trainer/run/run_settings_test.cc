// RunSettings in config.json: the env's kwargs are typed JSON ("env_kwargs") and come back with
// their types; a config of an earlier release, with "set" strings, reads as `--set` does (the
// env's declared types); a kwarg that is not a boolean, integer, float or string is refused by
// name; two configs that differ only in a kwarg's type differ.
#include "pixelgym/trainer/run_settings.h"

#include <gtest/gtest.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

namespace pixelgym::trainer {
namespace {

using nlohmann::json;

class NoAlgorithm final : public AlgorithmFactory {
 public:
  std::string name() const override { return "none"; }
  json parse_config(const std::string& text) const override {
    json config = {{"seed", 0}, {"num_envs", 1}, {"total_env_steps", 10}};
    config.update(json::parse(text));
    return config;
  }
  int set_threads(int requested) const override { return requested; }
  std::unique_ptr<Algorithm> make(EnvLoop&, const json&, Communicator&) const override {
    return nullptr;
  }
  std::unique_ptr<Actor> load_actor(const Space&, const Space&, const json&,
                                    const LoadedCheckpoint&) const override {
    return nullptr;
  }
};

json config_with(const json& kwargs_member, const char* name) {
  return {{"env_id", "CartPoleSwingup-v1"},
          {name, kwargs_member},
          {"wrap", json::array({"frame_stack=3"})},
          {"num_threads", 1},
          {"checkpoint_every", 10},
          {"minutes", 0.0},
          {"eval_episodes", 5},
          {"none", json::object()}};
}

TEST(RunSettingsTest, EnvKwargsAreTypedJsonAndComeBackWithTheirTypes) {
  const NoAlgorithm algorithm;
  RunSettings settings;
  settings.env_id = "CartPoleSwingup-v1";
  settings.env_kwargs = {
      {"obs_mode", "pixels"}, {"width", 64}, {"pole_length", 1.5}, {"msaa", 4}, {"grey", true}};
  settings.algorithm = "none";
  settings.algorithm_config = algorithm.parse_config("{}");
  const json written = settings_to_json(settings);
  EXPECT_EQ(written.at("env_kwargs"),
            json::parse(R"({"obs_mode": "pixels", "width": 64, "pole_length": 1.5, "msaa": 4,
                            "grey": true})"));
  EXPECT_FALSE(written.contains("set"));
  const RunSettings read = settings_from_json(written, "config.json", algorithm);
  EXPECT_EQ(read.env_kwargs, settings.env_kwargs);
  EXPECT_EQ(read.env_kwargs.at("width").type(), ParamType::kInt);
  EXPECT_EQ(read.env_kwargs.at("pole_length").type(), ParamType::kFloat);
}

TEST(RunSettingsTest, AConfigOfAnEarlierReleaseReadsItsSetStringsAsTheEnvDeclaresThem) {
  const NoAlgorithm algorithm;
  const RunSettings read = settings_from_json(
      config_with(
          json::array({"obs_mode=pixels", "width=64", "action_repeat=8", "max_episode_steps=100"}),
          "set"),
      "old/config.json", algorithm);
  const Params expected = {
      {"obs_mode", "pixels"}, {"width", 64}, {"action_repeat", 8}, {"max_episode_steps", 100}};
  EXPECT_EQ(read.env_kwargs, expected);
  // Written again, the kwargs are typed.
  EXPECT_EQ(settings_to_json(read).at("env_kwargs").at("width"), 64);

  try {
    settings_from_json(config_with(json::array({"width=wide"}), "set"), "old/config.json",
                       algorithm);
    ADD_FAILURE() << "width=wide was read";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what())
                  .find("old/config.json: not a pixelgym train config: "
                        "CartPoleSwingup-v1: --set width: "),
              std::string::npos)
        << error.what();
  }
}

TEST(RunSettingsTest, RefusesAKwargThatIsNotABooleanIntegerFloatOrString) {
  const NoAlgorithm algorithm;
  try {
    settings_from_json(config_with(json::parse(R"({"width": [64]})"), "env_kwargs"),
                       "run/config.json", algorithm);
    ADD_FAILURE() << "a list was read as a kwarg";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(),
                 "run/config.json: not a pixelgym train config: env_kwargs.width: a boolean, "
                 "integer, float or string expected, got [64]");
  }
}

TEST(RunSettingsTest, KwargsThatDifferInTypeAreADifference) {
  const NoAlgorithm algorithm;
  const RunSettings a = settings_from_json(
      config_with(json::parse(R"({"width": 64})"), "env_kwargs"), "a", algorithm);
  const RunSettings b = settings_from_json(
      config_with(json::parse(R"({"width": 64.0})"), "env_kwargs"), "b", algorithm);
  EXPECT_EQ(settings_differences(a, a), "");
  EXPECT_EQ(settings_differences(a, b),
            "env_kwargs: config.json has {\"width\":64}, the checkpoint {\"width\":64.0}");
}

}  // namespace
}  // namespace pixelgym::trainer
