#include "pixelgym/envs/registry.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pixelgym/envs/time_limit.h"
#include "tests/envs/probe_env.h"

namespace pixelgym {
namespace {

using ::testing::HasSubstr;

EnvSpec probe_spec(const std::string& id) {
  EnvSpec spec;
  spec.id = id;
  spec.description = "probe";
  spec.params = {{"episode_length", 20, "steps until terminated"}, {"gain", 0.1, "unused"}};
  spec.factory = [](const Params& kwargs, const MakeOptions& /*options*/) {
    return std::make_unique<testing::ProbeEnv>(
        testing::Fault::kNone, static_cast<int>(kwargs.at("episode_length").as_int()));
  };
  return spec;
}

std::string error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const std::invalid_argument& error) {
    return error.what();
  }
  return "(no exception)";
}

TEST(RegistryTest, MakeBuildsWithKwargsAndSetsSpec) {
  Registry registry;
  registry.register_env(probe_spec("Probe-v0"));
  std::unique_ptr<Env> env = registry.make("Probe-v0", {{"episode_length", 1}});
  ASSERT_NE(env->spec(), nullptr);
  EXPECT_EQ(env->spec()->id, "Probe-v0");
  EXPECT_EQ(env->name(), "Probe-v0");
  env->reset(0);
  EXPECT_TRUE(env->step(testing::action(0.0F)).terminated);
}

TEST(RegistryTest, MaxEpisodeStepsAppliesTimeLimitAndCanBeOverridden) {
  Registry registry;
  EnvSpec spec = probe_spec("Probe-v0");
  spec.max_episode_steps = 5;
  registry.register_env(spec);
  std::unique_ptr<Env> env = registry.make("Probe-v0");
  auto* limit = dynamic_cast<TimeLimit*>(env.get());
  ASSERT_NE(limit, nullptr);
  EXPECT_EQ(limit->max_episode_steps(), 5);
  EXPECT_EQ(env->name(), "TimeLimit<Probe-v0>");
  auto overridden = registry.make("Probe-v0", {{"max_episode_steps", 9}});
  EXPECT_EQ(dynamic_cast<TimeLimit&>(*overridden).max_episode_steps(), 9);
  auto unlimited = registry.make("Probe-v0", {{"max_episode_steps", 0}});
  EXPECT_EQ(dynamic_cast<TimeLimit*>(unlimited.get()), nullptr);
  EXPECT_THAT(error_of([&] {
                registry.make("Probe-v0", {{"max_episode_steps", -1}});
              }),
              HasSubstr("max_episode_steps"));
}

TEST(RegistryTest, UnknownIdSuggestsClosest) {
  Registry registry;
  registry.register_env(probe_spec("CartPoleSwingup-v0"));
  registry.register_env(probe_spec("CartPoleBalance-v0"));
  registry.register_env(probe_spec("ArmReach-v0"));
  const std::string message = error_of([&] { registry.make("CartPoleSwingUp-v1"); });
  EXPECT_THAT(message, HasSubstr("unknown env id \"CartPoleSwingUp-v1\""));
  EXPECT_THAT(message, HasSubstr("did you mean CartPoleSwingup-v0"));
  EXPECT_EQ(registry.closest_ids("armreach-v0", 1), (std::vector<std::string>{"ArmReach-v0"}));
}

TEST(RegistryTest, UnknownKwargListsValidOnesWithTypesAndDefaults) {
  Registry registry;
  registry.register_env(probe_spec("Probe-v0"));
  const std::string message = error_of([&] { registry.make("Probe-v0", {{"lenght", 3}}); });
  EXPECT_THAT(message, HasSubstr("Probe-v0: unknown kwarg \"lenght\""));
  EXPECT_THAT(message, HasSubstr("episode_length (int, default 20)"));
  EXPECT_THAT(message, HasSubstr("gain (float, default 0.1)"));
  EXPECT_THAT(message, HasSubstr("max_episode_steps (int, default 0)"));
}

// Gymnasium's render_mode: "rgb_array", the one mode, is accepted and changes nothing; any other
// ("human": a window) is refused naming the mode offered, by make and describe alike.
TEST(RegistryTest, RenderModeOtherThanRgbArrayIsRefusedNamingIt) {
  Registry registry;
  registry.register_env(probe_spec("Probe-v0"));
  EXPECT_TRUE(registry.make("Probe-v0", {{"render_mode", "rgb_array"}})
                  ->spec()
                  ->kwargs.count("render_mode") == 0);
  for (const Param& mode : {Param("human"), Param(1)}) {
    const std::string message = error_of([&] {
      registry.make("Probe-v0", {{"render_mode", mode}});
    });
    EXPECT_THAT(message, HasSubstr("Probe-v0: render_mode must be \"rgb_array\", the only render "
                                   "mode (pixelgym renders off-screen, headless"));
    EXPECT_THAT(message, HasSubstr("got " + mode.to_string()));
    EXPECT_THAT(error_of([&] {
                  registry.describe("Probe-v0", {{"render_mode", mode}});
                }),
                HasSubstr("render_mode must be \"rgb_array\""));
  }
}

TEST(RegistryTest, WrongKwargTypeIsRejected) {
  Registry registry;
  registry.register_env(probe_spec("Probe-v0"));
  EXPECT_THAT(error_of([&] {
                registry.make("Probe-v0", {{"episode_length", "long"}});
              }),
              HasSubstr("kwarg \"episode_length\" must be an int, got string \"long\""));
  EXPECT_NO_THROW(registry.make("Probe-v0", {{"gain", 1}}));  // int accepted for float
}

TEST(RegistryTest, RegisterRejectsBadIdsDuplicatesAndReservedKwargs) {
  Registry registry;
  EXPECT_THAT(error_of([&] { registry.register_env(probe_spec("NoVersion")); }),
              HasSubstr("Name-vN"));
  EXPECT_THROW(registry.register_env(probe_spec("Bad Name-v0")), std::invalid_argument);
  registry.register_env(probe_spec("Probe-v0"));
  EXPECT_THAT(error_of([&] { registry.register_env(probe_spec("Probe-v0")); }),
              HasSubstr("already registered"));
  EnvSpec reserved = probe_spec("Reserved-v0");
  reserved.params.push_back({"max_episode_steps", 3, ""});
  EXPECT_THROW(registry.register_env(reserved), std::invalid_argument);
  EnvSpec no_factory = probe_spec("NoFactory-v0");
  no_factory.factory = nullptr;
  EXPECT_THROW(registry.register_env(no_factory), std::invalid_argument);
}

TEST(RegistryTest, RegisteredIdsAreSorted) {
  Registry registry;
  registry.register_env(probe_spec("B-v0"));
  registry.register_env(probe_spec("A-v1"));
  EXPECT_EQ(registry.registered_ids(), (std::vector<std::string>{"A-v1", "B-v0"}));
}

TEST(RegistryTest, DefaultRegistryHoldsBuiltinsAndAcceptsUserEnvs) {
  const std::vector<std::string> ids = registered_ids();
  EXPECT_NE(std::find(ids.begin(), ids.end(), "GridWorld-v0"), ids.end());
  register_env(probe_spec("UserProbe-v0"));
  EXPECT_NO_THROW(make("UserProbe-v0"));
  EXPECT_THAT(error_of([] { make("Nope-v0"); }), HasSubstr("GridWorld-v0"));
}

}  // namespace
}  // namespace pixelgym
