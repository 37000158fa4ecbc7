#include "envs/spaces/dict.h"

#include <gtest/gtest.h>

#include <cmath>

#include "envs/spaces/box.h"
#include "envs/spaces/discrete.h"

namespace pixelgym::spaces {
namespace {

Dict pixel_space() {
  return Dict({{"pixels", std::make_shared<Box>(0.0, 255.0, Shape{8, 8, 3}, DType::kUInt8)},
               {"joint_pos", std::make_shared<Box>(-3.0, 3.0, Shape{2})}});
}

TEST(DictSpaceTest, SamplesAreContainedAcrossSeedsAndKeepKeyOrder) {
  const Dict space = pixel_space();
  for (std::uint64_t seed = 0; seed < 50; ++seed) {
    Rng rng(seed);
    const Value sample = space.sample(rng);
    ASSERT_TRUE(space.contains(sample)) << space.mismatch(sample);
    EXPECT_EQ(sample.dict().keys(), (std::vector<std::string>{"pixels", "joint_pos"}));
  }
}

TEST(DictSpaceTest, ContainsRejectsMissingExtraAndBadValues) {
  const Dict space = pixel_space();
  Rng rng(0);
  pixelgym::ValueDict value = space.sample(rng).dict();

  pixelgym::ValueDict missing;
  missing.insert("pixels", value.at("pixels"));
  EXPECT_NE(space.mismatch(missing).find("missing key \"joint_pos\""), std::string::npos);

  pixelgym::ValueDict extra = value;
  extra.insert("cube_pos", Array(DType::kFloat32, {3}));
  EXPECT_NE(space.mismatch(extra).find("unexpected key \"cube_pos\""), std::string::npos);

  pixelgym::ValueDict wrong_dtype = value;
  wrong_dtype.insert("joint_pos", Array(DType::kFloat64, {2}));
  EXPECT_NE(space.mismatch(wrong_dtype).find("key \"joint_pos\": dtype float64"),
            std::string::npos);

  pixelgym::ValueDict nan_value = value;
  nan_value.insert("joint_pos", Array::from_vector<float>({2}, {NAN, 0.0F}));
  EXPECT_FALSE(space.contains(nan_value));

  EXPECT_FALSE(space.contains(Array(DType::kFloat32, {2})));
}

TEST(DictSpaceTest, RejectsDuplicateEmptyAndNullEntries) {
  const auto box = std::make_shared<Box>(0.0, 1.0, Shape{1});
  EXPECT_THROW(Dict({{"a", box}, {"a", box}}), std::invalid_argument);
  EXPECT_THROW(Dict({{"", box}}), std::invalid_argument);
  EXPECT_THROW(Dict({{"a", nullptr}}), std::invalid_argument);
}

TEST(DictSpaceTest, AccessToStringEquals) {
  const Dict space({{"a", std::make_shared<Discrete>(3)}});
  EXPECT_EQ(space.to_string(), "Dict('a': Discrete(3))");
  EXPECT_TRUE(space.has("a"));
  EXPECT_THROW(space.at("b"), std::out_of_range);
  EXPECT_TRUE(space.equals(Dict({{"a", std::make_shared<Discrete>(3)}})));
  EXPECT_FALSE(space.equals(Dict({{"a", std::make_shared<Discrete>(4)}})));
  EXPECT_EQ(space.shape(), std::nullopt);
  EXPECT_EQ(space.dtype(), std::nullopt);
}

}  // namespace
}  // namespace pixelgym::spaces
