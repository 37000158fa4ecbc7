#include "pixelgym/envs/suggestions.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pixelgym {
namespace {

const std::vector<std::string> kWrappers = {"resize", "grayscale", "channel_first", "frame_stack",
                                            "clip_action"};

TEST(SuggestionsTest, ATypoFindsWhatItIsATypoOf) {
  EXPECT_EQ(closest_names("grayscal", kWrappers), (std::vector<std::string>{"grayscale"}));
  EXPECT_EQ(closest_names("framestack", kWrappers), (std::vector<std::string>{"frame_stack"}));
  EXPECT_EQ(closest_names("widht", {"height", "width", "msaa"}),
            (std::vector<std::string>{"width"}));
  EXPECT_EQ(closest_names("RESIZE", kWrappers), (std::vector<std::string>{"resize"}));
}

// Both sides of the bound: a third of the name's length, at least 2.
TEST(SuggestionsTest, OnlyNamesWithinATyposDistanceAreSuggested) {
  EXPECT_EQ(closest_names("ab", {"abcd"}), (std::vector<std::string>{"abcd"}));  // 2
  EXPECT_TRUE(closest_names("ab", {"abcde"}).empty());                           // 3
  EXPECT_EQ(closest_names("abcdefghi", {"abcdefxyz"}).size(), 1U);               // 3 of 9
  EXPECT_TRUE(closest_names("abcdefghi", {"abcdewxyz"}).empty());                // 4 of 9
  EXPECT_TRUE(closest_names("blur", kWrappers).empty());
}

TEST(SuggestionsTest, ClosestComeFirstAndAtMostCount) {
  const std::vector<std::string> names = {"abcx", "abcd", "abxx", "axxx"};
  EXPECT_EQ(closest_names("abcd", names), (std::vector<std::string>{"abcd", "abcx", "abxx"}));
  EXPECT_EQ(closest_names("abcd", names, 1), (std::vector<std::string>{"abcd"}));
}

TEST(SuggestionsTest, DidYouMeanReadsAsASentence) {
  EXPECT_EQ(did_you_mean("widht", {"width", "height"}), "did you mean width?");
  EXPECT_EQ(did_you_mean("ab", {"abc", "abd"}), "did you mean abc or abd?");
  EXPECT_EQ(did_you_mean("ab", {"abc", "abd", "abe"}), "did you mean abc, abd or abe?");
  EXPECT_EQ(did_you_mean("blur", kWrappers), "");
  EXPECT_EQ(join_names({"a", "b", "c"}), "a, b, c");
  EXPECT_EQ(join_names({}), "");
}

}  // namespace
}  // namespace pixelgym
