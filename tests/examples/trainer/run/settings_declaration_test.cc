// A config that declares its settings once gets its JSON form, its range checks and its
// --list-settings description from that one list: each is checked here on a config of every
// kind of member, nested object included.
#include "pixelgym/trainer/settings_declaration.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace pixelgym::settings_test {

enum class Shape { kRound, kSquare };

struct Inner {
  bool on = true;
};

struct Example {
  std::uint64_t seed = 7;
  std::int64_t steps = 10;
  std::int64_t pad = 4;
  double rate = 0.5;
  double scale = 2.0;
  double bonus = 0.0;
  double target = std::numeric_limits<double>::quiet_NaN();
  bool fast = false;
  Shape shape = Shape::kSquare;
  std::vector<std::int64_t> widths = {64, 64};
  Inner inner;
};

template <typename Config, typename Visit>
std::enable_if_t<std::is_same_v<std::remove_const_t<Config>, Inner>> declare_settings(
    Config& c, Visit& visit) {
  visit.flag("on", c.on, "whether the inner part is on");
}

template <typename Config, typename Visit>
std::enable_if_t<std::is_same_v<std::remove_const_t<Config>, Example>> declare_settings(
    Config& c, Visit& visit) {
  visit.integer("seed", c.seed, std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max(),
                "the seed");
  visit.count("steps", c.steps, 1, "how many steps");
  visit.integer("pad", c.pad, std::int64_t{0}, std::int64_t{8}, "the pad");
  visit.number("rate", c.rate, 0.0, 1.0, "the rate");
  visit.positive("scale", c.scale, "the scale");
  visit.non_negative("bonus", c.bonus, "the bonus");
  visit.optional_number("target", c.target, -10.0, 10.0, "the target (null: none)");
  visit.flag("fast", c.fast, "go fast");
  static const trainer::ChoiceNames<Shape> shapes = {{"round", Shape::kRound},
                                                     {"square", Shape::kSquare}};
  visit.choice("shape", c.shape, shapes, "the shape");
  visit.counts("widths", c.widths, 1, "the widths");
  visit.object("inner", c.inner, "Inner", "the inner part");
}

namespace {

using nlohmann::json;
using ::testing::HasSubstr;

std::string refusal(const std::string& text) {
  Example config;
  try {
    trainer::read_settings(json::parse(text), config, "Example");
    trainer::check_settings(config, "Example");
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "accepted";
}

TEST(SettingsDeclarationTest, EverySettingSurvivesTheJsonRoundTrip) {
  json defaults;
  trainer::write_settings(defaults, Example{});
  EXPECT_EQ(defaults, json::parse(R"({"seed": 7, "steps": 10, "pad": 4, "rate": 0.5,
      "scale": 2.0, "bonus": 0.0, "target": null, "fast": false, "shape": "square",
      "widths": [64, 64], "inner": {"on": true}})"));
  const json changed = json::parse(R"({"seed": 8, "steps": 11, "pad": 5, "rate": 0.25,
      "scale": 3.0, "bonus": 1.5, "target": -2.0, "fast": true, "shape": "round",
      "widths": [32], "inner": {"on": false}})");
  Example config;
  trainer::read_settings(changed, config, "Example");
  trainer::check_settings(config, "Example");
  json written;
  trainer::write_settings(written, config);
  EXPECT_EQ(written, changed);
  // null reads back as NaN, and a subset leaves the rest alone.
  trainer::read_settings(json::parse(R"({"target": null})"), config, "Example");
  EXPECT_TRUE(std::isnan(config.target));
  EXPECT_EQ(config.seed, 8U);
}

TEST(SettingsDeclarationTest, BadMembersAndValuesOutOfRangeAreRefusedByName) {
  EXPECT_THAT(refusal(R"({"stpes": 3})"),
              HasSubstr(R"(Example JSON: unknown member "stpes"; did you mean steps?)"));
  EXPECT_THAT(refusal(R"({"inner": {"off": true}})"),
              HasSubstr(R"(Inner JSON: unknown member "off")"));
  EXPECT_THAT(refusal(R"({"rate": "high"})"),
              HasSubstr(R"(member "rate" has the wrong type: expected a number, got string)"));
  EXPECT_THAT(refusal(R"({"shape": "oval"})"),
              HasSubstr(R"(Example: member "shape": unknown shape "oval"; known: round, square)"));
  EXPECT_EQ(refusal(R"({"steps": 0})"), "Example: steps must be from 1 to 1099511627776, got 0");
  EXPECT_EQ(refusal(R"({"pad": 9})"), "Example: pad must be from 0 to 8, got 9");
  EXPECT_EQ(refusal(R"({"rate": 1.5})"), "Example: rate must be in [0, 1], got 1.5");
  EXPECT_EQ(refusal(R"({"scale": 0})"), "Example: scale must be > 0 and finite, got 0");
  EXPECT_EQ(refusal(R"({"bonus": -1})"), "Example: bonus must be >= 0 and finite, got -1");
  EXPECT_EQ(refusal(R"({"target": 11})"), "Example: target must be in [-10, 10], got 11");
  EXPECT_EQ(refusal(R"({"widths": [8, 0]})"), "Example: widths must each be >= 1, got 0");
  EXPECT_EQ(refusal(R"({"target": null, "widths": []})"), "accepted");
}

TEST(SettingsDeclarationTest, TheDescriptionHasEverySettingWithItsValueRangeAndHelp) {
  const std::vector<trainer::SettingDescription> described = trainer::describe_settings(Example{});
  std::vector<std::string> names;
  for (const trainer::SettingDescription& setting : described) names.push_back(setting.name);
  EXPECT_EQ(names, (std::vector<std::string>{"seed", "steps", "pad", "rate", "scale", "bonus",
                                             "target", "fast", "shape", "widths", "inner.on"}));
  EXPECT_EQ(described[1].value, json(10));
  EXPECT_EQ(described[1].range, "an integer from 1");
  EXPECT_EQ(described[1].help, "how many steps");
  EXPECT_EQ(described[3].range, "a number in [0, 1]");
  EXPECT_EQ(described[6].value, json(nullptr));
  EXPECT_EQ(described[8].value, json("square"));
  EXPECT_EQ(described[8].range, "one of round, square");
  EXPECT_EQ(described[10].value, json(true));
  EXPECT_EQ(described[10].help, "whether the inner part is on");
}

}  // namespace
}  // namespace pixelgym::settings_test
