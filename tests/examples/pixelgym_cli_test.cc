// Runs the `pixelgym` binary and checks exit codes and output, as a user or a script sees them.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>

#include "render/image_io.h"

namespace pixelgym {
namespace {

using ::testing::HasSubstr;

struct CliRun {
  int exit_code;
  std::string output;  // stdout and stderr
};

CliRun run(const std::string& arguments) {
  const std::string command = std::string(PIXELGYM_CLI) + " " + arguments + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return {-1, "popen failed"};
  std::string output;
  std::array<char, 4096> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) output += buffer.data();
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

TEST(PixelgymCliTest, ListShowsGridWorldWithDescription) {
  const CliRun result = run("list");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_THAT(result.output, HasSubstr("GridWorld-v0"));
  EXPECT_THAT(result.output, HasSubstr("4x4 grid"));
}

TEST(PixelgymCliTest, InfoShowsSpacesAndConfigKeys) {
  const CliRun result = run("info GridWorld-v0");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("observation_space: Discrete(16)"));
  EXPECT_THAT(result.output, HasSubstr("action_space:      Discrete(4)"));
  EXPECT_THAT(result.output, HasSubstr("render_width"));
  EXPECT_THAT(result.output, HasSubstr("max_episode_steps: 50"));
}

TEST(PixelgymCliTest, CheckGridWorldPasses) {
  const CliRun result = run("check GridWorld-v0 --seed 3");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("all 11 checks passed"));
}

TEST(PixelgymCliTest, CheckUnknownIdFailsAndSuggests) {
  const CliRun result = run("check Nope-v0");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("unknown env id \"Nope-v0\""));
  EXPECT_THAT(result.output, HasSubstr("GridWorld-v0"));
}

TEST(PixelgymCliTest, UnknownSubcommandAndBadFlagsExitTwoWithUsage) {
  for (const char* arguments :
       {"frobnicate", "", "check", "check GridWorld-v0 --bogus",
        "snapshot GridWorld-v0 --seed x --out a.png", "check GridWorld-v0 --set novalue"}) {
    const CliRun result = run(std::string(arguments));
    EXPECT_EQ(result.exit_code, 2) << arguments << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("Usage")) << arguments;
  }
}

TEST(PixelgymCliTest, HelpExitsZero) {
  const CliRun result = run("snapshot --help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_THAT(result.output, HasSubstr("--steps"));
}

TEST(PixelgymCliTest, SetPassesTypedKwargsAndReportsUnknownOnes) {
  const std::string out = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/cli/gridworld_small.png";
  std::filesystem::remove(out);
  const CliRun small = run("snapshot GridWorld-v0 --seed 0 --steps 3 --out " + out +
                           " --set render_width=96 --set render_height=64");
  ASSERT_EQ(small.exit_code, 0) << small.output;
  const render::Image image = render::read_png(out);
  EXPECT_EQ(image.width, 96);
  EXPECT_EQ(image.height, 64);

  const CliRun unknown = run("info GridWorld-v0 --set colour=red");
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_THAT(unknown.output, HasSubstr("unknown kwarg \"colour\""));
  EXPECT_THAT(unknown.output, HasSubstr("render_width (int, default 256)"));

  const CliRun bad_value = run("info GridWorld-v0 --set render_width=wide");
  EXPECT_EQ(bad_value.exit_code, 1);
  EXPECT_THAT(bad_value.output, HasSubstr("cannot read \"wide\" as a int"));
}

TEST(PixelgymCliTest, SnapshotIsReproducibleFromTheSeed) {
  const std::string dir = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/cli/";
  ASSERT_EQ(run("snapshot GridWorld-v0 --seed 4 --steps 7 --out " + dir + "a.png").exit_code, 0);
  ASSERT_EQ(run("snapshot GridWorld-v0 --seed 4 --steps 7 --out " + dir + "b.png").exit_code, 0);
  EXPECT_EQ(render::read_png(dir + "a.png").pixels, render::read_png(dir + "b.png").pixels);
}

// Each subcommand keeps its own defaults: snapshot's --steps is 0 (the frame after reset), not
// bench's 2000.
TEST(PixelgymCliTest, SnapshotDefaultsToTheFrameAfterReset) {
  const std::string dir = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/cli/";
  const CliRun plain = run("snapshot GridWorld-v0 --seed 2 --out " + dir + "reset_default.png");
  ASSERT_EQ(plain.exit_code, 0) << plain.output;
  EXPECT_THAT(plain.output, HasSubstr("seed 2, 0 steps)"));
  ASSERT_EQ(
      run("snapshot GridWorld-v0 --seed 2 --steps 0 --out " + dir + "reset_zero.png").exit_code, 0);
  EXPECT_EQ(render::read_png(dir + "reset_default.png").pixels, render::read_png(dir + "reset_zero.png").pixels);
}

TEST(PixelgymCliTest, SnapshotOfTheObservationIsWhatTheAgentSees) {
  const std::string out = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/cli/observation.png";
  const CliRun result = run("snapshot CartPoleSwingup-v0 --seed 0 --observation --out " + out);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const render::Image image = render::read_png(out);
  EXPECT_EQ(image.width, 84);
  EXPECT_EQ(image.height, 84);
  const CliRun index = run("snapshot GridWorld-v0 --seed 0 --observation --out " + out);
  EXPECT_EQ(index.exit_code, 1);
  EXPECT_THAT(index.output, HasSubstr("obs_mode=pixels"));
}

TEST(PixelgymCliTest, SnapshotToUnwritablePathFailsClearly) {
  const CliRun result = run("snapshot GridWorld-v0 --seed 0 --out /proc/pixelgym/x.png");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("/proc/pixelgym"));
}

TEST(PixelgymCliTest, RolloutPrintsReturns) {
  const CliRun result = run("rollout GridWorld-v0 --episodes 3 --seed 1");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("episode 2: return="));
  EXPECT_THAT(result.output, HasSubstr("mean_return="));
}

TEST(PixelgymCliTest, InspectWorksOnEveryAsset) {
  int count = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(
           std::string(PIXELGYM_SOURCE_DIR) + "/assets")) {
    if (entry.path().extension() != ".urdf") continue;
    ++count;
    const CliRun result = run("inspect " + entry.path().string());
    EXPECT_EQ(result.exit_code, 0) << entry.path() << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("simulates:"));
  }
  EXPECT_EQ(count, 8);
  const CliRun arm = run("inspect " + std::string(PIXELGYM_SOURCE_DIR) + "/assets/arm/arm.urdf");
  EXPECT_THAT(arm.output, HasSubstr("link3.obj   1152 triangles"));
  EXPECT_THAT(arm.output, HasSubstr("limits [-2.090, 2.090] rad"));
  EXPECT_THAT(arm.output, HasSubstr("total mass 23.200 kg"));
}

TEST(PixelgymCliTest, InspectRefusesEveryBadFileNamingTheProblem) {
  int count = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf")) {
    if (entry.path().extension() != ".urdf" || entry.path().filename() == "minimal_valid.urdf")
      continue;
    ++count;
    const CliRun result = run("inspect " + entry.path().string());
    EXPECT_EQ(result.exit_code, 1) << entry.path() << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("pixelgym: error: URDF " + entry.path().string() + ": "));
  }
  EXPECT_EQ(count, 18);
  EXPECT_EQ(
      run("inspect " + std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf/minimal_valid.urdf")
          .exit_code,
      0);
}

TEST(PixelgymCliTest, ViewRendersEveryAssetRobotVisibly) {
  for (const char* urdf : {"cartpole/cartpole.urdf", "pendulum/pendulum.urdf",
                           "acrobot/acrobot.urdf", "reacher/reacher.urdf", "arm/arm.urdf",
                           "objects/table.urdf", "objects/cube.urdf", "objects/target.urdf"}) {
    const std::string out = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/cli/view_" +
                            std::filesystem::path(urdf).stem().string() + ".png";
    std::filesystem::remove(out);
    const CliRun result = run("view " + std::string(PIXELGYM_SOURCE_DIR) + "/assets/" + urdf +
                              " --out " + out + " --width 160 --height 120");
    ASSERT_EQ(result.exit_code, 0) << urdf << ": " << result.output;
    const render::Image image = render::read_png(out);
    EXPECT_EQ(image.width, 160);
    EXPECT_EQ(image.height, 120);
    // Framed automatically: the robot fills a good part of the picture.
    const std::size_t at = result.output.find("robot covers ");
    ASSERT_NE(at, std::string::npos) << result.output;
    EXPECT_GT(std::stod(result.output.substr(at + 13)), 1.5) << urdf << ": " << result.output;
  }
}

TEST(PixelgymCliTest, ViewRefusesBadInput) {
  const std::string arm = std::string(PIXELGYM_SOURCE_DIR) + "/assets/arm/arm.urdf";
  const std::string out = std::string(PIXELGYM_TEST_OUTPUT_DIR) + "/cli/bad.png";
  EXPECT_EQ(run("view " + arm + " --out " + out + " --width 0").exit_code, 2);
  EXPECT_EQ(run("view " + arm + " --out " + out + " --width 9000").exit_code, 2);
  EXPECT_EQ(run("view " + arm + " --out " + out + " --msaa 3").exit_code, 2);
  EXPECT_EQ(run("view " + arm + " --out " + out + " --camera nowhere").exit_code, 2);
  EXPECT_EQ(run("view " + arm).exit_code, 2);  // --out is required
  const CliRun missing = run("view /nonexistent/robot.urdf --out " + out);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr("/nonexistent/robot.urdf"));
  const CliRun unwritable = run("view " + arm + " --out /proc/pixelgym/arm.png");
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_THAT(unwritable.output, HasSubstr("/proc/pixelgym"));
}

}  // namespace
}  // namespace pixelgym
