// The trainer's recipes found by name (`train --config swingup`), --config's other forms (a file,
// inline JSON), and --set-algo's KEY=VALUE applied to a config.
#include "pixelgym/trainer/recipes.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <string>

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;

const std::vector<std::string> kAlgorithms = {"ppo", "drqv2"};

std::string file_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Matches a callable that throws std::invalid_argument whose message has each of `parts`.
template <typename... Parts>
auto refuses(Parts... parts) {
  return ::testing::ThrowsMessage<std::invalid_argument>(::testing::AllOf(HasSubstr(parts)...));
}

// The tests run in the build tree, where the source's recipes serve.
TEST(RecipesTest, TheBuildTreeFindsTheSourcesRecipes) {
  EXPECT_EQ(recipe_folder("ppo"), fs::path(PIXELGYM_SOURCE_DIR) / "examples/trainer/ppo/configs");
  const std::vector<std::string> ppo = recipe_names("ppo");
  EXPECT_NE(std::find(ppo.begin(), ppo.end(), "swingup"), ppo.end());
  EXPECT_NE(std::find(ppo.begin(), ppo.end(), "action_repeat_8"), ppo.end());
  EXPECT_TRUE(std::is_sorted(ppo.begin(), ppo.end()));
  const std::vector<std::string> drqv2 = recipe_names("drqv2");
  EXPECT_NE(std::find(drqv2.begin(), drqv2.end(), "cartpole"), drqv2.end());
  EXPECT_TRUE(recipe_names("sac").empty());
}

TEST(RecipesTest, ANameIsTheRecipeAFileItsTextAndJsonItself) {
  EXPECT_EQ(config_text("swingup", "ppo", kAlgorithms),
            file_text(recipe_folder("ppo") / "swingup.json"));
  EXPECT_EQ(json::parse(config_text("swingup", "ppo", kAlgorithms)).at("gamma"), 0.95);
  const fs::path file = fs::temp_directory_path() / "pixelgym_recipes_test.json";
  std::ofstream(file) << R"({"gamma": 0.5})";
  EXPECT_EQ(config_text(file.string(), "ppo", kAlgorithms), R"({"gamma": 0.5})");
  fs::remove(file);
  EXPECT_EQ(config_text(R"( {"gamma": 0.9})", "ppo", kAlgorithms), R"( {"gamma": 0.9})");
  EXPECT_THAT(
      [&] { config_text(file.string(), "ppo", kAlgorithms); },
      refuses("--config " + file.string() + ": cannot read " + file.string() + " (no such file)"));
}

// An unknown name lists the algorithm's recipes with the closest first, and the algorithm that
// has one of that name.
TEST(RecipesTest, AnUnknownNameSuggestsAndListsTheRecipes) {
  EXPECT_THAT([] { config_text("swingupp", "ppo", kAlgorithms); },
              refuses("--config \"swingupp\": ppo has no recipe named \"swingupp\"; did you "
                      "mean swingup",
                      "ppo's recipes: action_repeat_8, reacher, swingup",
                      "`pixelgym train --list-configs` shows them",
                      "--config also takes a file (FILE.json, or a path with a '/': ./swingupp) or "
                      "inline JSON"));
  EXPECT_THAT([] { config_text("cartpole", "ppo", kAlgorithms); },
              refuses("ppo has no recipe named \"cartpole\" (drqv2 has one: add --algo drqv2)"));
}

TEST(RecipesTest, SetAlgoSetsOneMemberAsJsonOrAWord) {
  const json config = json::parse(R"({"gamma": 0.9, "policy": {"cnn": "nature"}})");
  EXPECT_EQ(with_setting(config, "gamma=0.95").at("gamma"), 0.95);
  EXPECT_EQ(with_setting(config, "num_envs=16").at("num_envs"), 16);
  EXPECT_EQ(with_setting(config, "augment=false").at("augment"), false);
  EXPECT_EQ(with_setting(config, "policy.cnn=fine").at("policy"),
            json::parse(R"({"cnn": "fine"})"));
  EXPECT_EQ(with_setting(json::object(), "policy.mlp_hidden=[64,64]").at("policy").at("mlp_hidden"),
            json::parse("[64, 64]"));
  EXPECT_EQ(with_setting(config, "encoder=\"mrq\"").at("encoder"), "mrq");
  EXPECT_EQ(with_setting(config, "gamma=abc").at("gamma"), "abc");  // the algorithm refuses it
  EXPECT_THAT([&] { with_setting(config, "gamma"); },
              refuses("--set-algo expects KEY=VALUE (e.g. gamma=0.95), got \"gamma\""));
  EXPECT_THAT([&] { with_setting(config, "=1"); }, refuses("expects KEY=VALUE"));
  EXPECT_THAT([&] { with_setting(config, "gamma.x=1"); },
              refuses("--set-algo gamma.x=1: \"gamma\" is number 0.9, not an object"));
  EXPECT_THAT([&] { with_setting(config, "policy..cnn=1"); },
              refuses("expected KEY or KEY.MEMBER"));
}

}  // namespace
}  // namespace pixelgym::trainer
