#include "pixelgym/envs/spaces/multi_binary.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pixelgym::spaces {
namespace {

TEST(MultiBinaryTest, SamplesAreContainedAcrossSeeds) {
  const MultiBinary space({2, 3});
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    Rng rng(seed);
    const Value sample = space.sample(rng);
    ASSERT_TRUE(space.contains(sample)) << space.mismatch(sample);
  }
}

TEST(MultiBinaryTest, ContainsRejectsWrongDtypeShapeAndValues) {
  const MultiBinary space({3});
  EXPECT_TRUE(space.contains(Array::from_vector<std::uint8_t>({3}, {0, 1, 1})));
  EXPECT_TRUE(space.contains(Array::from_vector<bool>({3}, {true, false, true})));
  EXPECT_FALSE(space.contains(Array::from_vector<std::uint8_t>({3}, {0, 2, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<float>({3}, {0, 1, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<float>({3}, {NAN, 1, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<std::uint8_t>({2}, {0, 1})));
}

TEST(MultiBinaryTest, ToStringAndEquals) {
  EXPECT_EQ(MultiBinary({4}).to_string(), "MultiBinary(4)");
  EXPECT_EQ(MultiBinary({2, 2}).to_string(), "MultiBinary((2, 2))");
  EXPECT_TRUE(MultiBinary({4}).equals(MultiBinary({4})));
  EXPECT_FALSE(MultiBinary({4}).equals(MultiBinary({2, 2})));
  EXPECT_THROW(MultiBinary({-1}), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::spaces
