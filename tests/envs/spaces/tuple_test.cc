#include "pixelgym/envs/spaces/tuple.h"

#include <gtest/gtest.h>

#include <cmath>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/discrete.h"

namespace pixelgym::spaces {
namespace {

Tuple make_space() {
  return Tuple({std::make_shared<Discrete>(3), std::make_shared<Box>(-1.0, 1.0, Shape{2})});
}

TEST(TupleSpaceTest, SamplesAreContainedAcrossSeeds) {
  const Tuple space = make_space();
  for (std::uint64_t seed = 0; seed < 50; ++seed) {
    Rng rng(seed);
    const Value sample = space.sample(rng);
    ASSERT_TRUE(space.contains(sample)) << space.mismatch(sample);
  }
}

TEST(TupleSpaceTest, ContainsRejectsWrongLengthAndItems) {
  const Tuple space = make_space();
  EXPECT_FALSE(space.contains(pixelgym::ValueTuple{Array::scalar<std::int64_t>(1)}));
  EXPECT_FALSE(space.contains(pixelgym::ValueTuple{Array::scalar<std::int64_t>(3),
                                                   Array::from_vector<float>({2}, {0, 0})}));
  EXPECT_FALSE(space.contains(pixelgym::ValueTuple{Array::scalar<std::int64_t>(1),
                                                   Array::from_vector<double>({2}, {0, 0})}));
  EXPECT_FALSE(space.contains(pixelgym::ValueTuple{Array::scalar<std::int64_t>(1),
                                                   Array::from_vector<float>({2}, {NAN, 0})}));
  EXPECT_TRUE(space.contains(pixelgym::ValueTuple{Array::scalar<std::int64_t>(1),
                                                  Array::from_vector<float>({2}, {0, 0})}));
  EXPECT_FALSE(space.contains(Value(pixelgym::ValueDict{})));
}

TEST(TupleSpaceTest, ToStringAndEquals) {
  EXPECT_EQ(make_space().to_string(), "Tuple(Discrete(3), Box(-1.0, 1.0, (2,), float32))");
  EXPECT_TRUE(make_space().equals(make_space()));
  EXPECT_FALSE(make_space().equals(Tuple({std::make_shared<Discrete>(3)})));
  EXPECT_THROW(Tuple({nullptr}), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::spaces
