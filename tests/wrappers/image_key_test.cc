#include "pixelgym/wrappers/image_key.h"

#include <gtest/gtest.h>

#include <memory>

#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/dict.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "tests/wrappers/image_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

using testing::expect_invalid;
using testing::image_box;
using testing::pixels_and_state;

TEST(ImageKeyTest, FindsADictKey) {
  const SpacePtr space = pixels_and_state(6, 8, 3);
  const ImageKey image = find_image(*space, "pixels", "Test");
  EXPECT_TRUE(image.in_dict);
  EXPECT_EQ(image.key, "pixels");
  EXPECT_EQ(image.index, 1U);
  EXPECT_EQ(image.shape, (Shape{6, 8, 3}));
  EXPECT_EQ(image.height(), 6);
  EXPECT_EQ(image.width(), 8);
  EXPECT_EQ(image.channels(), 3);
  EXPECT_EQ(find_image(*space, "depth", "Test").index, 2U);
}

TEST(ImageKeyTest, FindsABareBox) {
  const SpacePtr space = image_box(6, 8, 1);
  for (const char* key : {"pixels", ""}) {
    const ImageKey image = find_image(*space, key, "Test");
    EXPECT_FALSE(image.in_dict);
    EXPECT_EQ(image.key, "");
    EXPECT_EQ(image.shape, (Shape{6, 8, 1}));
  }
}

TEST(ImageKeyTest, TwoDimensionalImagesOnlyWhenAsked) {
  auto gray = std::make_shared<spaces::Box>(0.0, 255.0, Shape{6, 8}, DType::kUInt8);
  EXPECT_THROW(find_image(*gray, "pixels", "Test"), std::invalid_argument);
  EXPECT_EQ(find_image(*gray, "pixels", "Test", ImageRequirement{{0}}).channels(), 0);
}

TEST(ImageKeyTest, RefusesOtherSpaces) {
  const spaces::Discrete discrete(4);
  expect_invalid([&] { find_image(discrete, "pixels", "Test"); },
                 {"Test:", "Discrete", "\"pixels\"", "image keys: none"});
  const spaces::Box empty(0.0, 255.0, {0, 8, 3}, DType::kUInt8);
  expect_invalid([&] { find_image(empty, "pixels", "Test"); }, {"Test:", "(0, 8, 3)"});
  const spaces::Box rank4(0.0, 255.0, {1, 2, 2, 3}, DType::kUInt8);
  expect_invalid([&] { find_image(rank4, "pixels", "Test"); }, {"Test:", "(1, 2, 2, 3)"});
}

TEST(ImageKeyTest, ReplaceImageKeepsTheOtherEntries) {
  const SpacePtr space = pixels_and_state(6, 8, 3);
  const ImageKey image = find_image(*space, "pixels", "Test");
  const SpacePtr replaced = replace_image(*space, image, uint8_image_space({3, 4}));
  const auto& dict = dynamic_cast<const spaces::Dict&>(*replaced);
  EXPECT_TRUE(dict.at("pixels").equals(spaces::Box(0.0, 255.0, {3, 4}, DType::kUInt8)));
  EXPECT_EQ(dict.index("pixels"), 1U);
  const SpacePtr bare = image_box(6, 8, 3);
  const SpacePtr image_space = uint8_image_space({3, 4});
  EXPECT_EQ(replace_image(*bare, find_image(*bare, "", "Test"), image_space), image_space);
}

TEST(ImageKeyTest, CopyOtherEntriesLeavesTheImage) {
  const SpacePtr space = pixels_and_state(2, 2, 3);
  const ImageKey image = find_image(*space, "pixels", "Test");
  Rng rng(0);
  const Value in = space->sample(rng);
  Value out = space->zeros();
  const std::vector<Array> before = out.leaves();
  copy_other_entries(in, out, image);
  for (const char* key : {"state", "depth", "velocity"}) {
    EXPECT_TRUE(out.dict().at(key).equals(in.dict().at(key))) << key;
  }
  EXPECT_TRUE(out.dict().at("pixels").equals(space->zeros().dict().at("pixels")));
  // Written in place: the arrays are the ones out held before.
  const std::vector<Array> after = out.leaves();
  for (std::size_t i = 0; i < before.size(); ++i) EXPECT_TRUE(after[i].shares_memory(before[i]));
  EXPECT_FALSE(out.shares_memory(in));
}

TEST(ImageKeyTest, CopyValueDescendsIntoNestedDictsAndTuples) {
  const Value from = ValueDict{
      {"a", ValueTuple{Array::scalar<float>(1.5F), ValueDict{{"b", Array::scalar<int>(7)}}}}};
  Value to = ValueDict{
      {"a", ValueTuple{Array::scalar<float>(0.0F), ValueDict{{"b", Array::scalar<int>(0)}}}}};
  copy_value(from, to);
  EXPECT_TRUE(to.equals(from));
  EXPECT_FALSE(to.shares_memory(from));
}

}  // namespace
}  // namespace pixelgym::wrappers
