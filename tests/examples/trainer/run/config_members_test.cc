// Reading an algorithm's config members: integers are integers of the member's range, or are
// refused naming the member, the range and the value (JSON's own conversion truncated 2.9 to 2,
// wrapped -1 to 2^64 - 1 and left 1e30 undefined).
#include "pixelgym/trainer/config_members.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

using nlohmann::json;
using ::testing::HasSubstr;

template <typename T>
std::string refusal(const std::string& text) {
  T field{};
  try {
    read_member(json::parse(R"({"n": )" + text + "}"), "n", field, "Config");
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "accepted as " + std::to_string(field);
}

template <typename T>
T read(const std::string& text) {
  T field{};
  read_member(json::parse(R"({"n": )" + text + "}"), "n", field, "Config");
  return field;
}

TEST(ConfigMembersTest, IntegersAreWholeNumbersInTheMembersRange) {
  EXPECT_EQ(read<std::int64_t>("12"), 12);
  EXPECT_EQ(read<std::int64_t>("-3"), -3);
  EXPECT_EQ(read<std::int64_t>("1e6"), 1000000);  // a whole number written as a float
  EXPECT_EQ(read<std::int64_t>("2.0"), 2);
  EXPECT_EQ(read<std::uint64_t>("18446744073709551615"), UINT64_MAX);
  EXPECT_EQ(read<std::int64_t>("9223372036854775807"), INT64_MAX);
  EXPECT_EQ(read<std::int64_t>("-9223372036854775808"), INT64_MIN);
  EXPECT_EQ(read<int>("-2147483648"), INT32_MIN);
  // Absent: the field keeps its value.
  std::int64_t kept = 7;
  read_member(json::object(), "n", kept, "Config");
  EXPECT_EQ(kept, 7);
}

TEST(ConfigMembersTest, FractionsHugeAndNegativeUnsignedValuesAreRefusedByName) {
  const std::string int64_range =
      R"(Config JSON: member "n" must be an integer from -9223372036854775808 to )"
      "9223372036854775807, got ";
  EXPECT_EQ(refusal<std::int64_t>("2.9"), int64_range + "2.9");
  EXPECT_EQ(refusal<std::int64_t>("1.5"), int64_range + "1.5");
  EXPECT_EQ(refusal<std::int64_t>("1e30"), int64_range + "1e+30");
  EXPECT_EQ(refusal<std::int64_t>("9223372036854775808"), int64_range + "9223372036854775808");
  EXPECT_EQ(refusal<std::int64_t>("9.3e18"), int64_range + "9.3e+18");
  EXPECT_EQ(refusal<std::uint64_t>("-1"),
            R"(Config JSON: member "n" must be an integer from 0 to 18446744073709551615, got -1)");
  EXPECT_THAT(refusal<std::uint64_t>("-0.5"), HasSubstr("got -0.5"));
  EXPECT_THAT(refusal<int>("2147483648"), HasSubstr("from -2147483648 to 2147483647, got"));
  EXPECT_EQ(refusal<std::int64_t>(R"("12")"),
            R"(Config JSON: member "n" has the wrong type: expected an integer, got string "12")");
  EXPECT_THAT(refusal<std::int64_t>("true"), HasSubstr("expected an integer, got boolean"));
}

// Other types convert as JSON does; a value of another type is refused naming both types and
// the value (what a config file and `train --set-algo` both get).
TEST(ConfigMembersTest, WrongTypesNameWhatWasExpectedAndWhatWasGiven) {
  const auto refused = [](const std::string& text, auto field) {
    try {
      read_member(json::parse(R"({"x": )" + text + "}"), "x", field, "Config");
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused(R"("0.9")", 0.5),
            R"(Config JSON: member "x" has the wrong type: expected a number, got string "0.9")");
  EXPECT_EQ(refused("1", true),
            R"(Config JSON: member "x" has the wrong type: expected a boolean, got number 1)");
  EXPECT_EQ(refused("[1]", std::string("mrq")),
            R"(Config JSON: member "x" has the wrong type: expected a string, got array [1])");
  EXPECT_EQ(refused("7", std::vector<int>{64}),
            R"(Config JSON: member "x" has the wrong type: expected an array, got number 7)");
  double real = 0.5;
  read_member(json::parse(R"({"x": 2})"), "x", real, "Config");
  EXPECT_EQ(real, 2.0);
}

// An unknown member is answered with the closest known ones, then all of them.
TEST(ConfigMembersTest, UnknownMembersSuggestTheClosest) {
  const auto refused = [](const std::string& text) {
    try {
      require_known_members(json::parse(text), {"gamma", "gae_lambda", "num_envs"}, "Config");
    } catch (const std::invalid_argument& error) {
      return std::string(error.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(refused(R"({"gama": 0.9})"), R"(Config JSON: unknown member "gama"; did you mean )"
                                         "gamma? known: gamma, gae_lambda, num_envs");
  EXPECT_EQ(refused(R"({"colour": 1})"),
            R"(Config JSON: unknown member "colour"; known: gamma, gae_lambda, num_envs)");
  EXPECT_EQ(refused(R"({"gamma": 0.9})"), "accepted");
}

}  // namespace
}  // namespace pixelgym::trainer
