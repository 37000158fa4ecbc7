// DtypeObservation: spaces and values for each kind of cast, saturation, Dict keys, errors.
#include "pixelgym/wrappers/dtype_observation.h"

#include <gtest/gtest.h>

#include <limits>
#include <memory>

#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "tests/wrappers/image_env.h"
#include "tests/wrappers/scripted_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::box;

constexpr double kInf = std::numeric_limits<double>::infinity();

// An ImageEnv (which copies `next` when set) over `space`, giving `next` every step.
std::unique_ptr<Env> giving(SpacePtr space, Value next) {
  auto env = std::make_unique<testing::ImageEnv>(std::move(space));
  env->next = std::move(next);
  return env;
}

TEST(DtypeObservationTest, ImageToFloat32) {
  DtypeObservation env(std::make_unique<testing::ImageEnv>(testing::pixels_and_state(4, 4, 3)),
                       DType::kFloat32, "pixels");
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {4, 4, 3}, DType::kFloat32)));
  EXPECT_TRUE(dict.at("state").equals(*box(-1.0, 1.0, {4})));
  const Value obs = testing::reset_and_step(env);
  EXPECT_TRUE(env.observation_space().contains(obs));
  EXPECT_EQ(env.key(), "pixels");
  EXPECT_EQ(env.dtype(), DType::kFloat32);
}

TEST(DtypeObservationTest, FloatToIntegerTruncatesAndSaturates) {
  const SpacePtr space = std::make_shared<spaces::Box>(std::vector<double>{-2.5, -kInf, 0.0, -1.0},
                                                       std::vector<double>{2.5, kInf, 300.5, 1.0},
                                                       Shape{4}, DType::kFloat64);
  DtypeObservation env(giving(space, Array::from_vector<double>({4}, {-2.7, 1e30, 299.9, 0.99})),
                       DType::kInt32);
  const double int_min = std::numeric_limits<std::int32_t>::min();
  const double int_max = std::numeric_limits<std::int32_t>::max();
  EXPECT_TRUE(env.observation_space().equals(
      spaces::Box(std::vector<double>{-2.0, int_min, 0.0, -1.0},
                  std::vector<double>{2.0, int_max, 300.0, 1.0}, {4}, DType::kInt32)))
      << env.observation_space().to_string();
  // -2.7 is outside the inner Box but shows the truncation toward zero and the saturation.
  const Value obs = testing::reset_and_step(env);
  EXPECT_TRUE(obs.equals(Array::from_vector<std::int32_t>(
      {4}, {-2, std::numeric_limits<std::int32_t>::max(), 299, 0})));
}

TEST(DtypeObservationTest, IntegerToIntegerAndToFloat) {
  const SpacePtr space = box(-100.0, 100.0, {3}, DType::kInt64);
  DtypeObservation narrow(giving(space, Array::from_vector<std::int64_t>({3}, {-100, 7, 100})),
                          DType::kInt32);
  EXPECT_TRUE(narrow.observation_space().equals(*box(-100.0, 100.0, {3}, DType::kInt32)));
  EXPECT_TRUE(testing::reset_and_step(narrow).equals(
      Array::from_vector<std::int32_t>({3}, {-100, 7, 100})));
  DtypeObservation wide(giving(space, Array::from_vector<std::int64_t>({3}, {-100, 7, 100})),
                        DType::kFloat64);
  EXPECT_TRUE(
      testing::reset_and_step(wide).equals(Array::from_vector<double>({3}, {-100.0, 7.0, 100.0})));
  // An unbounded int64 Box narrows to the int32 range, saturating.
  DtypeObservation unbounded(
      giving(box(-kInf, kInf, {2}, DType::kInt64),
             Array::from_vector<std::int64_t>({2}, {std::int64_t{1} << 40, -3})),
      DType::kInt32);
  EXPECT_TRUE(testing::reset_and_step(unbounded).equals(
      Array::from_vector<std::int32_t>({2}, {std::numeric_limits<std::int32_t>::max(), -3})));
}

TEST(DtypeObservationTest, Float64ToFloat32) {
  DtypeObservation env(
      giving(box(-1.0, 1.0, {2}, DType::kFloat64), Array::from_vector<double>({2}, {0.1, -1.0})),
      DType::kFloat32);
  EXPECT_TRUE(env.observation_space().equals(*box(-1.0, 1.0, {2})));
  EXPECT_TRUE(testing::reset_and_step(env).equals(Array::from_vector<float>({2}, {0.1F, -1.0F})));
}

TEST(DtypeObservationTest, Errors) {
  testing::expect_invalid(
      [] { DtypeObservation env(giving(box(-1.0, 300.0, {2}), Value()), DType::kUInt8); },
      {"DtypeObservation", "low bound -1 of element 0", "outside uint8's range [0, 255]"});
  testing::expect_invalid(
      [] { DtypeObservation env(giving(box(0.0, 300.0, {2}), Value()), DType::kUInt8); },
      {"DtypeObservation", "high bound 300 of element 0"});
  testing::expect_invalid(
      [] { DtypeObservation env(giving(box(0.0, 1.0, {2}), Value()), DType::kBool); },
      {"DtypeObservation", "got bool"});
  testing::expect_invalid(
      [] {
        DtypeObservation env(giving(std::make_shared<spaces::Discrete>(3), Value()),
                             DType::kFloat32);
      },
      {"DtypeObservation", "must be a Box or a Dict", "Discrete(3)"});
  testing::expect_invalid(
      [] {
        DtypeObservation env(
            std::make_unique<testing::ImageEnv>(testing::pixels_and_state(4, 4, 3)),
            DType::kFloat32, "joints");
      },
      {"DtypeObservation", "\"joints\" is not in",
       "Box keys: \"state\", \"pixels\", \"depth\", "
       "\"velocity\""});
}

}  // namespace
}  // namespace pixelgym::wrappers
