#include "pixelgym/envs/params.h"

#include <gtest/gtest.h>

namespace pixelgym {
namespace {

const std::vector<ParamSpec> kSpecs = {{"width", 84, "image width"},
                                       {"scale", 0.5, "a float"},
                                       {"camera", "side", "a string"},
                                       {"shadows", true, "a bool"}};

TEST(ParamsTest, LiteralsPickTheRightType) {
  EXPECT_EQ(Param(3).type(), ParamType::kInt);
  EXPECT_EQ(Param(3.0).type(), ParamType::kFloat);
  EXPECT_EQ(Param("x").type(), ParamType::kString);
  EXPECT_EQ(Param(true).type(), ParamType::kBool);
}

TEST(ParamsTest, ResolveFillsDefaultsAndKeepsGiven) {
  const Params resolved = resolve_params(kSpecs, {{"width", 64}}, "Test-v0");
  EXPECT_EQ(resolved.at("width").as_int(), 64);
  EXPECT_EQ(resolved.at("camera").as_string(), "side");
  EXPECT_EQ(resolved.size(), 4U);
}

TEST(ParamsTest, IntIsAcceptedForFloat) {
  const Params resolved = resolve_params(kSpecs, {{"scale", 2}}, "Test-v0");
  EXPECT_EQ(resolved.at("scale").type(), ParamType::kFloat);
  EXPECT_EQ(resolved.at("scale").as_float(), 2.0);
}

TEST(ParamsTest, UnknownKeyListsValidKeysWithTypesAndDefaults) {
  try {
    resolve_params(kSpecs, {{"widht", 64}}, "Test-v0");
    FAIL();
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("Test-v0"), std::string::npos);
    EXPECT_NE(message.find("\"widht\""), std::string::npos);
    EXPECT_NE(message.find("width (int, default 84)"), std::string::npos);
    EXPECT_NE(message.find("camera (string, default \"side\")"), std::string::npos);
  }
}

// A typo of a key is answered with the key it is a typo of, before the list of all.
TEST(ParamsTest, UnknownKeySuggestsTheClosestKey) {
  try {
    resolve_params(kSpecs, {{"widht", 64}}, "Test-v0");
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what())
                  .find("Test-v0: unknown kwarg \"widht\"; did you mean width? valid kwargs: "),
              std::string::npos)
        << error.what();
  }
  try {
    resolve_params(kSpecs, {{"colour", 1}}, "Test-v0");
    FAIL();
  } catch (const std::invalid_argument& error) {
    EXPECT_EQ(std::string(error.what()).find("did you mean"), std::string::npos) << error.what();
  }
}

TEST(ParamsTest, WrongTypeNamesExpectedAndGiven) {
  try {
    resolve_params(kSpecs, {{"width", "wide"}}, "Test-v0");
    FAIL();
  } catch (const std::invalid_argument& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("must be an int"), std::string::npos);
    EXPECT_NE(message.find("string \"wide\""), std::string::npos);
  }
  EXPECT_THROW(resolve_params(kSpecs, {{"width", 1.5}}, "T-v0"), std::invalid_argument);
  EXPECT_THROW(resolve_params(kSpecs, {{"shadows", 1}}, "T-v0"), std::invalid_argument);
}

TEST(ParamsTest, ParseFromText) {
  EXPECT_EQ(parse_param(ParamType::kInt, "64").as_int(), 64);
  EXPECT_EQ(parse_param(ParamType::kFloat, "0.25").as_float(), 0.25);
  EXPECT_TRUE(parse_param(ParamType::kBool, "on").as_bool());
  EXPECT_FALSE(parse_param(ParamType::kBool, "False").as_bool());
  EXPECT_EQ(parse_param(ParamType::kString, "top").as_string(), "top");
  EXPECT_THROW(parse_param(ParamType::kInt, "6.4"), std::invalid_argument);
  EXPECT_THROW(parse_param(ParamType::kInt, ""), std::invalid_argument);
  EXPECT_THROW(parse_param(ParamType::kFloat, "x"), std::invalid_argument);
  EXPECT_THROW(parse_param(ParamType::kBool, "maybe"), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym
