// `pixelgym snapshot ... --compare GOLDEN` and the snapshot's write checks, run as a user or a CI
// script runs them: exit codes, messages, and the files written.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include "pixelgym/envs/registry.h"
#include "pixelgym/render/image_io.h"
#include "tests/examples/cli_run.h"

namespace pixelgym {
namespace {

namespace fs = std::filesystem;

// These tests set the update switch themselves where they test it; `make goldens`
// (PIXELGYM_UPDATE_GOLDENS=1 ctest -R Golden) must not reach the others.
[[maybe_unused]] const bool kUpdateSwitchCleared = [] {
  ::unsetenv("PIXELGYM_UPDATE_GOLDENS");
  return true;
}();

using ::testing::HasSubstr;
using ::testing::Not;

using testing::CliRun;

const fs::path kFolder = fs::path(PIXELGYM_TEST_OUTPUT_DIR) / "snapshot_cli";

// Runs `pixelgym ARGUMENTS` with the diff images going to kFolder/out.
CliRun run(const std::string& arguments, const std::string& environment = "") {
  return testing::run_cli(
      arguments, "PIXELGYM_SNAPSHOT_OUTPUT_DIR=" + (kFolder / "out").string() + " " + environment);
}

// A path under this test's folder, with no file there yet.
std::string fresh(const std::string& name) {
  const fs::path path = kFolder / name;
  fs::create_directories(path.parent_path());
  fs::remove(path);
  return path.string();
}

// ReacherEasy draws the arm's joint angles and the target from the seed: seeds 0 and 1 give
// visibly different frames.
const std::string kEnv = "ReacherEasy-v0";

TEST(SnapshotCliTest, CompareMatchesAGoldenOfTheSameSeed) {
  const std::string golden = fresh("same_seed.png");
  ASSERT_EQ(run("snapshot " + kEnv + " --seed 3 --out " + golden).exit_code, 0);
  const CliRun result = run("snapshot " + kEnv + " --seed 3 --compare " + golden);
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("match: " + golden + ": the frame matches (0 2x2 windows"));
  EXPECT_THAT(result.output, HasSubstr("seed 3, 0 steps)"));
}

// --seed is 0 unless given, so a golden of seed 0 matches a plain --compare.
TEST(SnapshotCliTest, CompareDefaultsToSeedZero) {
  const std::string golden = fresh("seed_zero.png");
  ASSERT_EQ(run("snapshot " + kEnv + " --seed 0 --out " + golden).exit_code, 0);
  const CliRun result = run("snapshot " + kEnv + " --compare " + golden);
  EXPECT_EQ(result.exit_code, 0) << result.output;
}

TEST(SnapshotCliTest, MismatchExitsOneWithTheFiguresAndTheDiffImage) {
  const std::string golden = fresh("other_seed.png");
  fs::remove_all(kFolder / "out");
  ASSERT_EQ(run("snapshot " + kEnv + " --seed 1 --out " + golden).exit_code, 0);
  const CliRun result = run("snapshot " + kEnv + " --compare " + golden);
  EXPECT_EQ(result.exit_code, 1) << result.output;
  const std::string diff = (kFolder / "out" / "other_seed.diff.png").string();
  const std::string actual = (kFolder / "out" / "other_seed.actual.png").string();
  EXPECT_THAT(result.output, HasSubstr("mismatch: the frame differs from golden " + golden));
  EXPECT_THAT(result.output, HasSubstr("2x2 windows of pixels off by more than 8 (limit 4)"));
  EXPECT_THAT(result.output, HasSubstr("mean absolute difference"));
  EXPECT_THAT(result.output, HasSubstr("diff: " + diff));
  EXPECT_TRUE(fs::exists(diff));
  // The actual image is the seed-0 frame: it matches a golden written with seed 0.
  const std::string seed_zero = fresh("seed_zero_for_actual.png");
  ASSERT_EQ(run("snapshot " + kEnv + " --out " + seed_zero).exit_code, 0);
  EXPECT_EQ(render::read_png(actual).pixels, render::read_png(seed_zero).pixels);
}

TEST(SnapshotCliTest, GoldenOfAnotherSizeExitsOneNamingBothSizes) {
  const std::string golden = fresh("small.png");
  ASSERT_EQ(
      run("snapshot " + kEnv + " --out " + golden + " --set render_width=64 --set render_height=48")
          .exit_code,
      0);
  const CliRun result = run("snapshot " + kEnv + " --compare " + golden);
  EXPECT_EQ(result.exit_code, 1) << result.output;
  const std::string full_size = fresh("full_size.png");
  ASSERT_EQ(run("snapshot " + kEnv + " --out " + full_size).exit_code, 0);
  const render::Image full = render::read_png(full_size);
  EXPECT_THAT(result.output,
              HasSubstr("golden " + golden + " is 64x48, the frame " + std::to_string(full.width) +
                        "x" + std::to_string(full.height) + ": expected the same size"));
}

TEST(SnapshotCliTest, MissingGoldenExitsOneSayingHowToCreateIt) {
  const std::string golden = fresh("missing.png");
  const CliRun result = run("snapshot " + kEnv + " --compare " + golden);
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("no golden " + golden));
  EXPECT_THAT(result.output, HasSubstr("PIXELGYM_UPDATE_GOLDENS=1"));
  EXPECT_FALSE(fs::exists(golden));
  // The update switch writes it, and then it matches.
  const CliRun update =
      run("snapshot " + kEnv + " --compare " + golden, "PIXELGYM_UPDATE_GOLDENS=1");
  EXPECT_EQ(update.exit_code, 0) << update.output;
  EXPECT_THAT(update.output, HasSubstr("wrote golden " + golden));
  EXPECT_EQ(run("snapshot " + kEnv + " --compare " + golden).exit_code, 0);
}

// A new user once saw "wrote /dev/full" and exit 0. `--out /dev/full` is now refused before
// anything runs (exit 2: not a .png name); a .png name for the device reaches the write, which
// refuses a path that is not a regular file (exit 1).
TEST(SnapshotCliTest, OutToDevFullFails) {
  const CliRun plain = run("snapshot GridWorld-v0 --out /dev/full");
  EXPECT_EQ(plain.exit_code, 2) << plain.output;
  EXPECT_THAT(plain.output, HasSubstr("must end in .png"));
  EXPECT_THAT(plain.output, Not(HasSubstr("wrote")));
  const std::string link = fresh("full.png");
  fs::create_symlink("/dev/full", link);
  const CliRun result = run("snapshot GridWorld-v0 --out " + link);
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("cannot write " + link + ": it is a character device"));
  EXPECT_THAT(result.output, Not(HasSubstr("wrote")));
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  EXPECT_TRUE(fs::is_symlink(link));
}

TEST(SnapshotCliTest, NeitherOutNorCompareIsAUsageError) {
  const CliRun result = run("snapshot GridWorld-v0");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("give --out FILE.png"));
  EXPECT_THAT(run("snapshot GridWorld-v0 --compare golden.jpg").output,
              HasSubstr("must end in .png"));
}

}  // namespace
}  // namespace pixelgym
