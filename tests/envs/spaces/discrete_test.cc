#include "pixelgym/envs/spaces/discrete.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <set>
#include <stdexcept>
#include <string>

namespace pixelgym::spaces {
namespace {

TEST(DiscreteTest, SamplesAreContainedAndCoverTheRangeAcrossSeeds) {
  const Discrete space(5, -2);
  std::set<std::int64_t> seen;
  for (std::uint64_t seed = 0; seed < 200; ++seed) {
    Rng rng(seed);
    const Value sample = space.sample(rng);
    ASSERT_TRUE(space.contains(sample)) << space.mismatch(sample);
    EXPECT_EQ(sample.array().dtype(), DType::kInt64);
    seen.insert(sample.array().item<std::int64_t>());
  }
  EXPECT_EQ(seen, (std::set<std::int64_t>{-2, -1, 0, 1, 2}));
}

TEST(DiscreteTest, ContainsRejectsWrongDtypeShapeAndRange) {
  const Discrete space(4);
  EXPECT_TRUE(space.contains(Array::scalar<std::int64_t>(3)));
  EXPECT_TRUE(space.contains(Array::scalar<std::int32_t>(0)));
  EXPECT_FALSE(space.contains(Array::scalar<std::int64_t>(4)));
  EXPECT_FALSE(space.contains(Array::scalar<std::int64_t>(-1)));
  EXPECT_FALSE(space.contains(Array::scalar<double>(1.0)));
  EXPECT_FALSE(space.contains(Array::scalar<double>(NAN)));
  EXPECT_FALSE(space.contains(Array::scalar<bool>(true)));
  EXPECT_FALSE(space.contains(Array::from_vector<std::int64_t>({1}, {1})));
  EXPECT_FALSE(space.contains(Value(ValueTuple{})));
  EXPECT_NE(space.mismatch(Array::scalar<std::int64_t>(4)).find("outside {0, ..., 3}"),
            std::string::npos);
}

TEST(DiscreteTest, RejectsNonPositiveN) {
  EXPECT_THROW(Discrete(0), std::invalid_argument);
  EXPECT_THROW(Discrete(-3), std::invalid_argument);
}

// Found by fuzz/spaces_fuzz.cc: start + n overflowed int64 (undefined behaviour) in mismatch().
TEST(DiscreteTest, RejectsARangePastInt64AndChecksTheEdgesWithoutOverflow) {
  constexpr std::int64_t kMax = std::numeric_limits<std::int64_t>::max();
  EXPECT_THROW(Discrete(7016890793931507553, 7006863666131853665), std::invalid_argument);
  // {int64 min, ..., -2}: the widest range there is, checked without overflow.
  const Discrete wide(kMax, std::numeric_limits<std::int64_t>::min());
  EXPECT_TRUE(wide.contains(Array::scalar<std::int64_t>(-2)));
  EXPECT_FALSE(wide.contains(Array::scalar<std::int64_t>(-1)));
  EXPECT_FALSE(wide.contains(Array::scalar<std::int64_t>(0)));
  // {int64 max - 2, ..., int64 max}: the message names the largest value without computing
  // start + n (UBSan caught that).
  const Discrete top(3, kMax - 2);
  EXPECT_TRUE(top.contains(Array::scalar<std::int64_t>(kMax)));
  EXPECT_NE(top.mismatch(Array::scalar<std::int64_t>(kMax - 3)).find(std::to_string(kMax) + "}"),
            std::string::npos);
}

// Values past 2^53 are judged exactly, not through a double (found by fuzz/spaces_fuzz).
TEST(DiscreteTest, LargeStartsAreJudgedExactly) {
  const Discrete space(97, 7006863666131853568);
  Rng rng(0);
  for (int draw = 0; draw < 50; ++draw) {
    const Value sample = space.sample(rng);
    ASSERT_TRUE(space.contains(sample)) << space.mismatch(sample);
  }
  EXPECT_FALSE(space.contains(Array::scalar<std::int64_t>(7006863666131853567)));
  EXPECT_TRUE(space.contains(Array::scalar<std::int64_t>(7006863666131853568 + 96)));
  EXPECT_FALSE(space.contains(Array::scalar<std::int64_t>(7006863666131853568 + 97)));
}

TEST(DiscreteTest, ToStringEqualsShape) {
  EXPECT_EQ(Discrete(4).to_string(), "Discrete(4)");
  EXPECT_EQ(Discrete(4, 1).to_string(), "Discrete(4, start=1)");
  EXPECT_TRUE(Discrete(4).equals(Discrete(4)));
  EXPECT_FALSE(Discrete(4).equals(Discrete(4, 1)));
  EXPECT_EQ(Discrete(4).shape(), Shape{});
}

}  // namespace
}  // namespace pixelgym::spaces
