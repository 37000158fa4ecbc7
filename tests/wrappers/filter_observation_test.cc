// FilterObservation: keeps the listed keys in the listed order, values copied; errors.
#include "pixelgym/wrappers/filter_observation.h"

#include <gtest/gtest.h>

#include <memory>

#include "pixelgym/envs/spaces/dict.h"
#include "tests/wrappers/image_env.h"
#include "tests/wrappers/test_util.h"

namespace pixelgym::wrappers {
namespace {

std::unique_ptr<testing::ImageEnv> dict_env() {
  return std::make_unique<testing::ImageEnv>(testing::pixels_and_state(6, 5, 3));
}

TEST(FilterObservationTest, KeepsTheKeysInTheGivenOrder) {
  auto inner = dict_env();
  testing::ImageEnv* probe = inner.get();
  const Value next = inner->observation_space().sample();
  probe->next = next;
  FilterObservation env(std::move(inner), {"velocity", "pixels"});
  const auto& dict = dynamic_cast<const spaces::Dict&>(env.observation_space());
  ASSERT_EQ(dict.entries().size(), 2U);
  EXPECT_EQ(dict.entries()[0].first, "velocity");
  EXPECT_EQ(dict.entries()[1].first, "pixels");
  EXPECT_TRUE(dict.at("pixels").equals(*testing::image_box(6, 5, 3)));
  const Value obs = testing::reset_and_step(env);
  EXPECT_EQ(obs.dict().keys(), (std::vector<std::string>{"velocity", "pixels"}));
  EXPECT_TRUE(obs.dict().at("velocity").equals(next.dict().at("velocity")));
  EXPECT_TRUE(obs.dict().at("pixels").equals(next.dict().at("pixels")));
  EXPECT_TRUE(env.observation_space().contains(obs));
  EXPECT_EQ(env.keys(), (std::vector<std::string>{"velocity", "pixels"}));
}

TEST(FilterObservationTest, Errors) {
  testing::expect_invalid([] { FilterObservation env(dict_env(), {}); },
                          {"FilterObservation", "at least one key",
                           "keys present: [\"state\", "
                           "\"pixels\", \"depth\", "
                           "\"velocity\"]"});
  testing::expect_invalid(
      [] {
        FilterObservation env(dict_env(), {"pixels", "joints", "x"});
      },
      {"FilterObservation", "[\"joints\", \"x\"] are not in",
       "keys present: [\"state\", \"pixels\""});
  testing::expect_invalid(
      [] {
        FilterObservation env(dict_env(), {"pixels", "state", "pixels"});
      },
      {"FilterObservation", "\"pixels\" is given twice"});
  testing::expect_invalid(
      [] {
        FilterObservation env(std::make_unique<testing::ImageEnv>(testing::image_box(4, 4, 3)),
                              {"pixels"});
      },
      {"FilterObservation", "must be a Dict", "Box(0.0, 255.0, (4, 4, 3), uint8)"});
}

}  // namespace
}  // namespace pixelgym::wrappers
