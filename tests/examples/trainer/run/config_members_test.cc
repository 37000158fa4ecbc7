// Reading an algorithm's config members: integers are integers of the member's range, or are
// refused naming the member, the range and the value (JSON's own conversion truncated 2.9 to 2,
// wrapped -1 to 2^64 - 1 and left 1e30 undefined).
#include "examples/trainer/run/config_members.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdint>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

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
  // Other types keep JSON's conversion, and its message.
  double real = 0;
  EXPECT_THROW(read_member(json::parse(R"({"x": "a"})"), "x", real, "Config"),
               std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::trainer
