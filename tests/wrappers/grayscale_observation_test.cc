#include "pixelgym/wrappers/grayscale_observation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

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

// One (1, n, 3) image holding the given RGB colours side by side, through the wrapper.
std::vector<int> gray_of(const std::vector<std::array<int, 3>>& colours) {
  const auto n = static_cast<std::int64_t>(colours.size());
  Array image(DType::kUInt8, {1, n, 3});
  for (std::int64_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) {
      image.data<std::uint8_t>()[i * 3 + c] =
          static_cast<std::uint8_t>(colours[static_cast<std::size_t>(i)][c]);
    }
  }
  auto env = std::make_unique<ImageEnv>(image_box(1, n, 3));
  env->next = Value(image);
  GrayscaleObservation wrapper(std::move(env));
  const Array gray = wrapper.reset(0).obs.array();
  EXPECT_EQ(gray.shape(), (Shape{1, n}));
  return std::vector<int>(gray.data<std::uint8_t>(), gray.data<std::uint8_t>() + n);
}

TEST(GrayscaleObservationTest, SpacesAreExact) {
  GrayscaleObservation flat(std::make_unique<ImageEnv>(image_box(6, 5, 3)));
  EXPECT_TRUE(flat.observation_space().equals(spaces::Box(0.0, 255.0, {6, 5}, DType::kUInt8)))
      << flat.observation_space().to_string();
  EXPECT_FALSE(flat.keep_dim());
  GrayscaleObservation kept(std::make_unique<ImageEnv>(image_box(6, 5, 3)), true);
  EXPECT_TRUE(kept.observation_space().equals(spaces::Box(0.0, 255.0, {6, 5, 1}, DType::kUInt8)));
  EXPECT_EQ(kept.reset(0).obs.array().shape(), (Shape{6, 5, 1}));
}

TEST(GrayscaleObservationTest, Itu601WeightsOnKnownColours) {
  // Y = 0.299 R + 0.587 G + 0.114 B: red and blue differ, so an RGB/BGR swap fails here.
  const std::vector<int> gray =
      gray_of({{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {255, 255, 255}, {0, 0, 0}, {128, 128, 128}});
  EXPECT_EQ(gray, (std::vector<int>{76, 150, 29, 255, 0, 128}));
}

TEST(GrayscaleObservationTest, MatchesTheFormulaOnRandomColours) {
  Rng rng(5);
  std::vector<std::array<int, 3>> colours;
  for (int i = 0; i < 200; ++i) {
    colours.push_back({static_cast<int>(rng.uniform(0, 256)), static_cast<int>(rng.uniform(0, 256)),
                       static_cast<int>(rng.uniform(0, 256))});
  }
  const std::vector<int> gray = gray_of(colours);
  for (std::size_t i = 0; i < colours.size(); ++i) {
    const double y = 0.299 * colours[i][0] + 0.587 * colours[i][1] + 0.114 * colours[i][2];
    EXPECT_NEAR(gray[i], std::round(y), 1.0) << i;
  }
}

TEST(GrayscaleObservationTest, DictMatchesOpenCvAndPassesOtherKeys) {
  auto env = std::make_unique<ImageEnv>(pixels_and_state(12, 10, 3));
  ImageEnv& inner = *env;
  GrayscaleObservation wrapper(std::move(env), true);
  const auto& dict = dynamic_cast<const spaces::Dict&>(wrapper.observation_space());
  const auto& inner_dict = dynamic_cast<const spaces::Dict&>(inner.observation_space());
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {12, 10, 1}, DType::kUInt8)));
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(dict.at(key).equals(inner_dict.at(key))) << key;
  }
  const Value obs = testing::reset_and_step(wrapper);
  const Value expected = testing::reset_and_step(inner);  // same seed, same noise
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(obs.dict().at(key).equals(expected.dict().at(key))) << key;
  }
  const Array& rgb = expected.dict().at("pixels").array();
  const cv::Mat source(12, 10, CV_8UC3, const_cast<void*>(rgb.raw_data()));
  cv::Mat reference;
  cv::cvtColor(source, reference, cv::COLOR_RGB2GRAY);
  const Array& gray = obs.dict().at("pixels").array();
  ASSERT_EQ(gray.nbytes(), reference.total());
  EXPECT_TRUE(
      std::equal(reference.data, reference.data + reference.total(), gray.data<std::uint8_t>()));
  EXPECT_TRUE(wrapper.observation_space().contains(obs));
}

// Every value of each channel, in random combinations over a large image: the same bytes as
// cv::cvtColor (the wrapper computes OpenCV's fixed point itself).
TEST(GrayscaleObservationTest, MatchesOpenCvOnALargeRandomImage) {
  Rng rng(11);
  Array image(DType::kUInt8, {256, 384, 3});
  for (std::int64_t i = 0; i < image.size(); ++i) {
    image.data<std::uint8_t>()[i] = static_cast<std::uint8_t>(rng.uniform(0.0, 256.0));
  }
  auto env = std::make_unique<ImageEnv>(testing::image_box(256, 384, 3));
  env->next = Value(image);
  GrayscaleObservation wrapper(std::move(env));
  const Array gray = wrapper.reset(0).obs.array();
  const cv::Mat source(256, 384, CV_8UC3, image.raw_data());
  cv::Mat reference;
  cv::cvtColor(source, reference, cv::COLOR_RGB2GRAY);
  ASSERT_EQ(gray.nbytes(), reference.total());
  EXPECT_TRUE(
      std::equal(reference.data, reference.data + reference.total(), gray.data<std::uint8_t>()));
}

TEST(GrayscaleObservationTest, RefusesAOneChannelImage) {
  expect_invalid(
      [] {
        GrayscaleObservation(std::make_unique<ImageEnv>(pixels_and_state(8, 8, 3)), false, "depth");
      },
      {"GrayscaleObservation", "\"depth\"", "C = 3", "(8, 8, 1)", "image keys: \"pixels\""});
  expect_invalid([] { GrayscaleObservation(std::make_unique<ImageEnv>(image_box(8, 8, 1))); },
                 {"GrayscaleObservation", "\"pixels\"", "C = 3", "image keys: none"});
}

TEST(GrayscaleObservationTest, RefusesAbsentAndNonImageKeys) {
  expect_invalid(
      [] {
        GrayscaleObservation(std::make_unique<ImageEnv>(pixels_and_state(8, 8, 3)), false, "rgb");
      },
      {"GrayscaleObservation", "\"rgb\"", "not in", "image keys: \"pixels\""});
  expect_invalid(
      [] {
        GrayscaleObservation(std::make_unique<ImageEnv>(pixels_and_state(8, 8, 3)), false,
                             "velocity");
      },
      {"GrayscaleObservation", "\"velocity\"", "float32", "image keys: \"pixels\""});
}

TEST(GrayscaleObservationTest, RefusesAFloatImage) {
  auto space = std::make_shared<spaces::Box>(0.0, 1.0, Shape{8, 8, 3});
  expect_invalid([&] { GrayscaleObservation(std::make_unique<ImageEnv>(space)); },
                 {"GrayscaleObservation", "\"pixels\"", "float32", "image keys: none"});
}

}  // namespace
}  // namespace pixelgym::wrappers
