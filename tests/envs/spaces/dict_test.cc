#include "pixelgym/envs/spaces/dict.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/discrete.h"

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

TEST(DictSpaceTest, ReplacedInsertedRemovedChangeOneEntry) {
  const Dict space = pixel_space();  // "pixels", then "joint_pos"
  const auto small = std::make_shared<Box>(0.0, 255.0, Shape{4, 4, 1}, DType::kUInt8);
  const auto replaced = space.replaced("pixels", small);
  ASSERT_EQ(replaced->entries().size(), 2U);
  EXPECT_EQ(replaced->entries()[0].first, "pixels");  // same position
  EXPECT_TRUE(replaced->at("pixels").equals(*small));
  EXPECT_TRUE(replaced->at("joint_pos").equals(space.at("joint_pos")));
  EXPECT_FALSE(space.at("pixels").equals(*small));  // the original is unchanged

  const auto inserted = space.inserted("depth", small, 1);
  ASSERT_EQ(inserted->entries().size(), 3U);
  EXPECT_EQ(inserted->entries()[1].first, "depth");
  EXPECT_EQ(inserted->index("joint_pos"), 2U);
  EXPECT_EQ(space.inserted("depth", small)->entries().back().first, "depth");

  const auto removed = space.removed("pixels");
  ASSERT_EQ(removed->entries().size(), 1U);
  EXPECT_EQ(removed->entries()[0].first, "joint_pos");

  EXPECT_THROW(space.replaced("depth", small), std::out_of_range);
  EXPECT_THROW(space.removed("depth"), std::out_of_range);
  EXPECT_THROW(space.inserted("pixels", small), std::invalid_argument);
  EXPECT_THROW(space.inserted("depth", small, 3), std::out_of_range);
  EXPECT_THROW(space.replaced("pixels", nullptr), std::invalid_argument);
}

TEST(DictSpaceTest, ZerosIsLaidOutAsTheSpace) {
  const Dict space = pixel_space();
  const Value zeros = space.zeros();
  EXPECT_EQ(space.layout_mismatch(zeros), "");
  EXPECT_TRUE(space.contains(zeros));
  EXPECT_EQ(zeros.dict().at("pixels").array().shape(), (Shape{8, 8, 3}));
  // Layout ignores the values (a NaN is still laid out right) but not keys, order, dtype, shape.
  Value nan = space.zeros();
  nan.dict().at("joint_pos").array().data<float>()[0] = std::nanf("");
  EXPECT_EQ(space.layout_mismatch(nan), "");
  EXPECT_FALSE(space.contains(nan));
  pixelgym::ValueDict swapped;
  swapped.insert("joint_pos", zeros.dict().at("joint_pos"));
  swapped.insert("pixels", zeros.dict().at("pixels"));
  EXPECT_NE(space.layout_mismatch(swapped), "");
  pixelgym::ValueDict wrong_dtype = zeros.dict();
  wrong_dtype.insert("joint_pos", Array(DType::kFloat64, {2}));
  EXPECT_NE(space.layout_mismatch(wrong_dtype).find("float64"), std::string::npos);
  pixelgym::ValueDict missing = zeros.dict();
  missing.erase("pixels");
  EXPECT_NE(space.layout_mismatch(missing), "");
  EXPECT_NE(space.layout_mismatch(Array::scalar(1.0)), "");
}
}  // namespace
}  // namespace pixelgym::spaces
