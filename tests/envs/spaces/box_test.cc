#include "pixelgym/envs/spaces/box.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pixelgym::spaces {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(BoxTest, SamplesAreContainedAcrossSeedsForEveryBoundKind) {
  const std::vector<Box> boxes = {
      Box(-1.0, 1.0, {3}),
      Box(0.0, 255.0, {4, 4, 3}, DType::kUInt8),
      Box(-kInf, kInf, {5}, DType::kFloat64),
      Box({0.0, -kInf}, {kInf, 2.0}, {2}),
      Box(-5.0, 5.0, {2, 2}, DType::kInt32),
      Box(-kInf, kInf, {3}, DType::kInt64),
      // Bounds equal and infinite (found by fuzz/spaces_fuzz: Box(-inf, -inf) drew 0.37).
      Box(-kInf, -kInf, {}),
      Box({kInf, -kInf, 1.5}, {kInf, -kInf, 1.5}, {3}, DType::kFloat64),
  };
  for (const Box& box : boxes) {
    for (std::uint64_t seed = 0; seed < 50; ++seed) {
      Rng rng(seed);
      const Value sample = box.sample(rng);
      ASSERT_TRUE(box.contains(sample))
          << box.to_string() << " seed " << seed << ": " << box.mismatch(sample);
    }
  }
}

// int64's upper limit as a double is 2^63, past int64: converting it was undefined (found by
// fuzz/spaces_fuzz under UBSan), and on x86 every draw came out INT64_MIN.
TEST(BoxTest, AnInt64BoxOverTheWholeRangeDrawsDifferentValues) {
  const Box box(-kInf, kInf, {}, DType::kInt64);
  Rng rng(3);
  const std::int64_t first = box.sample(rng).array().data<std::int64_t>()[0];
  bool differs = false;
  for (int draw = 0; draw < 20 && !differs; ++draw) {
    differs = box.sample(rng).array().data<std::int64_t>()[0] != first;
  }
  EXPECT_TRUE(differs) << "every draw was " << first;
}

TEST(BoxTest, SeededSpaceSamplesRepeat) {
  Box box(-1.0, 1.0, {4});
  box.seed(5);
  const Value a = box.sample();
  box.seed(5);
  EXPECT_TRUE(box.sample().equals(a));
  box.seed(6);
  EXPECT_FALSE(box.sample().equals(a));
}

TEST(BoxTest, ContainsRejectsWrongDtypeShapeBoundsAndNan) {
  Box box(-1.0, 1.0, {2});
  EXPECT_TRUE(box.contains(Array::from_vector<float>({2}, {0.5F, -1.0F})));
  EXPECT_FALSE(box.contains(Array::from_vector<double>({2}, {0.5, -1.0})));
  EXPECT_FALSE(box.contains(Array::from_vector<float>({3}, {0, 0, 0})));
  EXPECT_FALSE(box.contains(Array::from_vector<float>({1, 2}, {0, 0})));
  EXPECT_FALSE(box.contains(Array::from_vector<float>({2}, {0.0F, 1.5F})));
  EXPECT_FALSE(box.contains(Array::from_vector<float>({2}, {NAN, 0.0F})));
  EXPECT_FALSE(box.contains(Value(ValueDict{})));
  EXPECT_NE(box.mismatch(Array::from_vector<float>({2}, {NAN, 0.0F})).find("NaN"),
            std::string::npos);
  EXPECT_NE(box.mismatch(Array::from_vector<double>({2}, {0, 0})).find("float64"),
            std::string::npos);
}

TEST(BoxTest, UnboundedFloatBoxContainsInfinityButNotNan) {
  Box box(-kInf, kInf, {1}, DType::kFloat64);
  EXPECT_TRUE(box.contains(Array::from_vector<double>({1}, {kInf})));
  EXPECT_FALSE(box.contains(Array::from_vector<double>({1}, {NAN})));
}

TEST(BoxTest, ConstructorRejectsInvalidBounds) {
  EXPECT_THROW(Box(1.0, -1.0, {2}), std::invalid_argument);
  EXPECT_THROW(Box(NAN, 1.0, {2}), std::invalid_argument);
  EXPECT_THROW(Box(0.0, 1.0, {2}, DType::kBool), std::invalid_argument);
  EXPECT_THROW(Box(0.5, 3.0, {2}, DType::kInt32), std::invalid_argument);
  EXPECT_THROW(Box(300.0, 400.0, {2}, DType::kUInt8), std::invalid_argument);
  EXPECT_THROW(Box({0.0}, {1.0, 2.0}, {2}), std::invalid_argument);
  EXPECT_THROW(Box(0.0, 1.0, {-1}), std::invalid_argument);
}

TEST(BoxTest, IntegerInfiniteBoundsClampToDtypeRange) {
  Box box(-kInf, kInf, {1}, DType::kUInt8);
  EXPECT_EQ(box.low()[0], 0.0);
  EXPECT_EQ(box.high()[0], 255.0);
  EXPECT_TRUE(box.is_bounded());
}

TEST(BoxTest, ToStringAndEquals) {
  EXPECT_EQ(Box(-1.0, 1.0, {1}).to_string(), "Box(-1.0, 1.0, (1,), float32)");
  EXPECT_EQ(Box(0.0, 255.0, {84, 84, 3}, DType::kUInt8).to_string(),
            "Box(0.0, 255.0, (84, 84, 3), uint8)");
  EXPECT_EQ(Box({0.0, -kInf}, {1.0, kInf}, {2}).to_string(),
            "Box([0.0, -inf], [1.0, inf], (2,), float32)");
  EXPECT_TRUE(Box(-1.0, 1.0, {2}).equals(Box(-1.0, 1.0, {2})));
  EXPECT_FALSE(Box(-1.0, 1.0, {2}).equals(Box(-1.0, 2.0, {2})));
  EXPECT_FALSE(Box(-1.0, 1.0, {2}).equals(Box(-1.0, 1.0, {2}, DType::kFloat64)));
  EXPECT_EQ(Box(-1.0, 1.0, {2}).shape(), (Shape{2}));
  EXPECT_EQ(Box(-1.0, 1.0, {2}).dtype(), DType::kFloat32);
}

}  // namespace
}  // namespace pixelgym::spaces
