#include "pixelgym/wrappers/channel_first_observation.h"

#include <gtest/gtest.h>

#include <memory>

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

void expect_transposed(const Array& hwc, const Array& chw) {
  const std::int64_t height = hwc.shape()[0];
  const std::int64_t width = hwc.shape()[1];
  const std::int64_t channels = hwc.shape()[2];
  ASSERT_EQ(chw.shape(), (Shape{channels, height, width}));
  const std::uint8_t* in = hwc.data<std::uint8_t>();
  const std::uint8_t* out = chw.data<std::uint8_t>();
  for (std::int64_t c = 0; c < channels; ++c) {
    for (std::int64_t y = 0; y < height; ++y) {
      for (std::int64_t x = 0; x < width; ++x) {
        ASSERT_EQ(out[(c * height + y) * width + x], in[(y * width + x) * channels + c])
            << "c=" << c << " y=" << y << " x=" << x;
      }
    }
  }
}

TEST(ChannelFirstObservationTest, BareBoxSpaceAndLayout) {
  auto env = std::make_unique<ImageEnv>(image_box(5, 7, 3));
  ImageEnv& inner = *env;
  ChannelFirstObservation wrapper(std::move(env));
  EXPECT_TRUE(wrapper.observation_space().equals(spaces::Box(0.0, 255.0, {3, 5, 7}, DType::kUInt8)))
      << wrapper.observation_space().to_string();
  const Value obs = testing::reset_and_step(wrapper);
  expect_transposed(testing::reset_and_step(inner).array(), obs.array());
}

TEST(ChannelFirstObservationTest, OneChannel) {
  auto env = std::make_unique<ImageEnv>(image_box(4, 6, 1));
  ImageEnv& inner = *env;
  ChannelFirstObservation wrapper(std::move(env));
  EXPECT_EQ(wrapper.observation_space().shape().value(), (Shape{1, 4, 6}));
  expect_transposed(testing::reset_and_step(inner).array(),
                    testing::reset_and_step(wrapper).array());
}

TEST(ChannelFirstObservationTest, DictKeyAndOtherKeysUntouched) {
  auto env = std::make_unique<ImageEnv>(pixels_and_state(5, 7, 3));
  ImageEnv& inner = *env;
  ChannelFirstObservation wrapper(std::move(env));
  const auto& dict = dynamic_cast<const spaces::Dict&>(wrapper.observation_space());
  const auto& inner_dict = dynamic_cast<const spaces::Dict&>(inner.observation_space());
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {3, 5, 7}, DType::kUInt8)));
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(dict.at(key).equals(inner_dict.at(key))) << key;
  }
  const Value obs = testing::reset_and_step(wrapper);
  const Value expected = testing::reset_and_step(inner);
  expect_transposed(expected.dict().at("pixels").array(), obs.dict().at("pixels").array());
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(obs.dict().at(key).equals(expected.dict().at(key))) << key;
  }
}

TEST(ChannelFirstObservationTest, RefusesBadKeys) {
  expect_invalid(
      [] {
        ChannelFirstObservation(std::make_unique<ImageEnv>(pixels_and_state(8, 8, 3)), "missing");
      },
      {"ChannelFirstObservation", "\"missing\"", "not in", "image keys: \"pixels\", \"depth\""});
  expect_invalid(
      [] {
        ChannelFirstObservation(std::make_unique<ImageEnv>(pixels_and_state(8, 8, 3)), "state");
      },
      {"ChannelFirstObservation", "\"state\"", "float32", "image keys: \"pixels\", \"depth\""});
  auto gray = std::make_shared<spaces::Box>(0.0, 255.0, Shape{8, 8}, DType::kUInt8);
  expect_invalid([&] { ChannelFirstObservation(std::make_unique<ImageEnv>(gray)); },
                 {"ChannelFirstObservation", "\"pixels\"", "(H, W, C)", "(8, 8)"});
  auto floats = std::make_shared<spaces::Box>(0.0, 1.0, Shape{8, 8, 3});
  expect_invalid([&] { ChannelFirstObservation(std::make_unique<ImageEnv>(floats)); },
                 {"ChannelFirstObservation", "float32", "image keys: none"});
}

}  // namespace
}  // namespace pixelgym::wrappers
