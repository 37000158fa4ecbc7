#include "pixelgym/wrappers/resize_observation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "tests/wrappers/image_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::expect_invalid;
using testing::image_box;
using testing::ImageEnv;
using testing::pixels_and_state;

// A random uint8 image of the given shape.
Array random_image(Shape shape, std::uint64_t seed) {
  Rng rng(seed);
  Array image(DType::kUInt8, std::move(shape));
  for (std::int64_t i = 0; i < image.size(); ++i) {
    image.data<std::uint8_t>()[i] = static_cast<std::uint8_t>(rng.uniform(0.0, 256.0));
  }
  return image;
}

// cv::resize called directly on `image` (H, W, C), the reference the wrapper must match.
Array opencv_resize(const Array& image, std::int64_t height, std::int64_t width,
                    int interpolation) {
  const int channels = static_cast<int>(image.shape()[2]);
  const cv::Mat source(static_cast<int>(image.shape()[0]), static_cast<int>(image.shape()[1]),
                       CV_8UC(channels), const_cast<void*>(image.raw_data()));
  cv::Mat target;
  cv::resize(source, target, cv::Size(static_cast<int>(width), static_cast<int>(height)), 0, 0,
             interpolation);
  Array result(DType::kUInt8, {height, width, channels});
  std::copy(target.data, target.data + result.nbytes(), result.data<std::uint8_t>());
  return result;
}

// The wrapper's output for `image` given as the bare observation of an ImageEnv.
Array resize_through_wrapper(const Array& image, ImageSize size) {
  auto env =
      std::make_unique<ImageEnv>(image_box(image.shape()[0], image.shape()[1], image.shape()[2]));
  env->next = Value(image);
  ResizeObservation wrapper(std::move(env), size);
  return wrapper.reset(0).obs.array();
}

TEST(ResizeObservationTest, BareBoxSpaceIsExact) {
  ResizeObservation wrapper(std::make_unique<ImageEnv>(image_box(48, 64, 3)), {24, 32});
  EXPECT_TRUE(
      wrapper.observation_space().equals(spaces::Box(0.0, 255.0, {24, 32, 3}, DType::kUInt8)))
      << wrapper.observation_space().to_string();
  EXPECT_EQ(wrapper.size().height, 24);
  EXPECT_EQ(wrapper.size().width, 32);
}

TEST(ResizeObservationTest, KeepsOneChannelAndTwoDimensionalImages) {
  ResizeObservation one(std::make_unique<ImageEnv>(image_box(8, 8, 1)), {4, 6});
  EXPECT_EQ(one.observation_space().shape().value(), (Shape{4, 6, 1}));
  auto gray = std::make_shared<spaces::Box>(0.0, 255.0, Shape{8, 8}, DType::kUInt8);
  ResizeObservation two(std::make_unique<ImageEnv>(gray), {4, 6});
  EXPECT_EQ(two.observation_space().shape().value(), (Shape{4, 6}));
  const Value obs = two.reset(0).obs;
  EXPECT_EQ(obs.array().shape(), (Shape{4, 6}));
}

TEST(ResizeObservationTest, DictSpaceReplacesOnlyThePixels) {
  ResizeObservation wrapper(std::make_unique<ImageEnv>(pixels_and_state(48, 64, 3)), {24, 32});
  const auto& dict = dynamic_cast<const spaces::Dict&>(wrapper.observation_space());
  const auto& inner = dynamic_cast<const spaces::Dict&>(wrapper.env().observation_space());
  ASSERT_EQ(dict.entries().size(), 4U);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(dict.entries()[i].first, inner.entries()[i].first);  // same keys, same order
  }
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {24, 32, 3}, DType::kUInt8)));
  EXPECT_TRUE(dict.at("state").equals(inner.at("state")));
  EXPECT_TRUE(dict.at("depth").equals(inner.at("depth")));
  EXPECT_TRUE(dict.at("velocity").equals(inner.at("velocity")));
}

// The largest per-element difference between two uint8 arrays of one shape.
int max_difference(const Array& a, const Array& b) {
  int most = 0;
  for (std::int64_t i = 0; i < a.size(); ++i) {
    most = std::max(most, std::abs(a.data<std::uint8_t>()[i] - b.data<std::uint8_t>()[i]));
  }
  return most;
}

TEST(ResizeObservationTest, ShrinkingByANonIntegerFactorMatchesOpenCvInterAreaWithinOneLevel) {
  const Array image = random_image({48, 64, 3}, 1);
  const Array resized = resize_through_wrapper(image, {20, 28});
  // AreaResize: OpenCV's weights, summed in another order (wrappers/area_resize.h).
  EXPECT_LE(max_difference(resized, opencv_resize(image, 20, 28, cv::INTER_AREA)), 1);
  // Guards the test: the other interpolation is further off.
  EXPECT_GT(max_difference(resized, opencv_resize(image, 20, 28, cv::INTER_LINEAR)), 8);
}

TEST(ResizeObservationTest, ShrinkingByIntegerFactorsIsOpenCvInterAreaExactly) {
  const Array image = random_image({48, 64, 3}, 5);
  const Array resized = resize_through_wrapper(image, {24, 16});
  EXPECT_TRUE(resized.equals(opencv_resize(image, 24, 16, cv::INTER_AREA)));
  EXPECT_FALSE(resized.equals(opencv_resize(image, 24, 16, cv::INTER_LINEAR)));
}

TEST(ResizeObservationTest, EnlargingMatchesOpenCvInterLinear) {
  const Array image = random_image({12, 10, 3}, 2);
  const Array resized = resize_through_wrapper(image, {30, 25});
  EXPECT_TRUE(resized.equals(opencv_resize(image, 30, 25, cv::INTER_LINEAR)));
  EXPECT_FALSE(resized.equals(opencv_resize(image, 30, 25, cv::INTER_AREA)));
}

TEST(ResizeObservationTest, GrowingEitherSideIsLinear) {
  const Array image = random_image({20, 10, 1}, 3);
  const Array resized = resize_through_wrapper(image, {10, 17});  // shorter but wider
  EXPECT_TRUE(resized.equals(opencv_resize(image, 10, 17, cv::INTER_LINEAR)));
}

TEST(ResizeObservationTest, SameSizeIsTheSameImage) {
  const Array image = random_image({9, 7, 3}, 4);
  EXPECT_TRUE(resize_through_wrapper(image, {9, 7}).equals(image));
}

TEST(ResizeObservationTest, DictOtherKeysPassThroughUntouched) {
  auto env = std::make_unique<ImageEnv>(pixels_and_state(16, 16, 3));
  ImageEnv& inner = *env;
  ResizeObservation wrapper(std::move(env), {8, 8});
  const Value obs = testing::reset_and_step(wrapper);
  // The inner env draws the same noise again from the same seed: compare with its own step.
  ResetResult reset;
  reset.obs = inner.observation_space().zeros();
  inner.reset_into(reset, 3);
  StepResult step;
  step.obs = inner.observation_space().zeros();
  inner.step_into(inner.action_space().zeros(), step);
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(obs.dict().at(key).equals(step.obs.dict().at(key))) << key;
  }
  EXPECT_TRUE(obs.dict().at("pixels").array().equals(
      opencv_resize(step.obs.dict().at("pixels").array(), 8, 8, cv::INTER_AREA)));
  EXPECT_TRUE(wrapper.observation_space().contains(obs));
}

TEST(ResizeObservationTest, ResizesTheKeyAsked) {
  ResizeObservation wrapper(std::make_unique<ImageEnv>(pixels_and_state(16, 16, 3)), {4, 5},
                            "depth");
  const auto& dict = dynamic_cast<const spaces::Dict&>(wrapper.observation_space());
  EXPECT_EQ(dict.at("depth").shape().value(), (Shape{4, 5, 1}));
  EXPECT_EQ(dict.at("pixels").shape().value(), (Shape{16, 16, 3}));
  EXPECT_EQ(wrapper.reset(0).obs.dict().at("depth").array().shape(), (Shape{4, 5, 1}));
}

TEST(ResizeObservationTest, RefusesBadSizes) {
  for (const ImageSize size : {ImageSize{0, 8}, ImageSize{8, 0}, ImageSize{-1, 8}, ImageSize{8, -5},
                               ImageSize{8193, 8}, ImageSize{8, 100000}}) {
    expect_invalid(
        [&] { ResizeObservation(std::make_unique<ImageEnv>(pixels_and_state(16, 16, 3)), size); },
        {"ResizeObservation", "size", "8192", "\"pixels\"",
         std::to_string(size.height) + "x" + std::to_string(size.width)});
  }
  // Both ends of the range are accepted.
  EXPECT_NO_THROW(ResizeObservation(std::make_unique<ImageEnv>(image_box(4, 4, 3)), {1, 1}));
  EXPECT_NO_THROW(ResizeObservation(std::make_unique<ImageEnv>(image_box(4, 4, 3)), {8192, 1}));
}

TEST(ResizeObservationTest, RefusesAnAbsentKey) {
  expect_invalid(
      [] {
        ResizeObservation(std::make_unique<ImageEnv>(pixels_and_state(16, 16, 3)), {8, 8},
                          "camera");
      },
      {"ResizeObservation", "\"camera\"", "not in", "image keys: \"pixels\", \"depth\""});
}

TEST(ResizeObservationTest, RefusesANonImageKey) {
  expect_invalid(
      [] {
        ResizeObservation(std::make_unique<ImageEnv>(pixels_and_state(16, 16, 3)), {8, 8}, "state");
      },
      {"ResizeObservation", "\"state\"", "uint8", "float32", "image keys: \"pixels\", \"depth\""});
}

TEST(ResizeObservationTest, RefusesAFloatImage) {
  auto space = std::make_shared<spaces::Box>(0.0, 1.0, Shape{8, 8, 3});
  expect_invalid(
      [&] {
        ResizeObservation(std::make_unique<ImageEnv>(space), {4, 4});
      },
      {"ResizeObservation", "\"pixels\"", "uint8", "float32", "image keys: none"});
  auto dict = std::make_shared<spaces::Dict>(spaces::Dict::Entries{{"pixels", space}});
  expect_invalid(
      [&] {
        ResizeObservation(std::make_unique<ImageEnv>(dict), {4, 4});
      },
      {"ResizeObservation", "\"pixels\"", "float32", "image keys: none"});
}

TEST(ResizeObservationTest, RefusesFourChannels) {
  expect_invalid(
      [] {
        ResizeObservation(std::make_unique<ImageEnv>(image_box(8, 8, 4)), {4, 4});
      },
      {"ResizeObservation", "C = 1 or 3", "(8, 8, 4)"});
}

TEST(ResizeObservationTest, RefusesAnotherKeyOnABareBox) {
  expect_invalid(
      [] {
        ResizeObservation(std::make_unique<ImageEnv>(image_box(8, 8, 3)), {4, 4}, "rgb");
      },
      {"ResizeObservation", "\"rgb\"", "bare Box", "image keys: none"});
  EXPECT_NO_THROW(ResizeObservation(std::make_unique<ImageEnv>(image_box(8, 8, 3)), {4, 4}, ""));
}

}  // namespace
}  // namespace pixelgym::wrappers
