#include "pixelgym/envs/spaces/multi_discrete.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace pixelgym::spaces {
namespace {

TEST(MultiDiscreteTest, SamplesAreContainedAcrossSeeds) {
  const MultiDiscrete space({3, 2, 5}, {0, 1, -2});
  for (std::uint64_t seed = 0; seed < 100; ++seed) {
    Rng rng(seed);
    const Value sample = space.sample(rng);
    ASSERT_TRUE(space.contains(sample)) << space.mismatch(sample);
  }
}

TEST(MultiDiscreteTest, ContainsRejectsWrongDtypeShapeAndRange) {
  const MultiDiscrete space({3, 2});
  EXPECT_TRUE(space.contains(Array::from_vector<std::int64_t>({2}, {2, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<std::int64_t>({2}, {3, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<std::int64_t>({2}, {-1, 0})));
  EXPECT_FALSE(space.contains(Array::from_vector<double>({2}, {1, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<double>({2}, {NAN, 1})));
  EXPECT_FALSE(space.contains(Array::from_vector<std::int64_t>({3}, {0, 0, 0})));
}

TEST(MultiDiscreteTest, ShapedNvec) {
  const MultiDiscrete space({2, 2, 3, 3}, {}, Shape{2, 2});
  EXPECT_EQ(space.shape(), (Shape{2, 2}));
  Rng rng(0);
  EXPECT_EQ(space.sample(rng).array().shape(), (Shape{2, 2}));
}

TEST(MultiDiscreteTest, RejectsInvalidConstruction) {
  EXPECT_THROW(MultiDiscrete({3, 0}), std::invalid_argument);
  EXPECT_THROW(MultiDiscrete({3, 2}, {0}), std::invalid_argument);
  EXPECT_THROW(MultiDiscrete({3, 2}, {}, Shape{3}), std::invalid_argument);
}

// The largest value of an entry, start + nvec - 1, must be an int64; one that is exactly the
// largest int64 is contained (start + nvec alone would overflow there).
TEST(MultiDiscreteTest, EntriesUpToTheLargestInt64) {
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  try {
    MultiDiscrete({3, 2}, {0, kMax});
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("start + nvec - 1 must fit in int64"),
              std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("(entry 1)"), std::string::npos) << error.what();
  }
  const MultiDiscrete space({3}, {kMax - 2});
  EXPECT_TRUE(space.contains(Array::from_vector<std::int64_t>({1}, {kMax})));
  EXPECT_TRUE(space.contains(Array::from_vector<std::int64_t>({1}, {kMax - 2})));
  EXPECT_FALSE(space.contains(Array::from_vector<std::int64_t>({1}, {kMax - 3})));
  // The message names the largest value without computing start + nvec (UBSan caught that).
  EXPECT_NE(space.mismatch(Array::from_vector<std::int64_t>({1}, {kMax - 3}))
                .find(std::to_string(kMax) + "}"),
            std::string::npos);
  Rng rng(0);
  for (int i = 0; i < 20; ++i) ASSERT_TRUE(space.contains(space.sample(rng)));
}

TEST(MultiDiscreteTest, ToStringAndEquals) {
  EXPECT_EQ(MultiDiscrete({3, 2}).to_string(), "MultiDiscrete([3, 2])");
  EXPECT_TRUE(MultiDiscrete({3, 2}).equals(MultiDiscrete({3, 2})));
  EXPECT_FALSE(MultiDiscrete({3, 2}).equals(MultiDiscrete({3, 3})));
}

}  // namespace
}  // namespace pixelgym::spaces
