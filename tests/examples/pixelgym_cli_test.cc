// Runs the `pixelgym` binary and checks exit codes, output and written files, as a user or a
// script sees them. Every file a command writes is deleted first, so no test passes on a file an
// earlier run left; pictures are compared with what the library gives for the same seed.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pixelgym/engine/robot_model.h"
#include "pixelgym/engine/world.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/tasks/world_scene.h"
#include "pixelgym/render/image_io.h"
#include "pixelgym/render/renderer.h"
#include "pixelgym/wrappers/wrapper_spec.h"
#include "tests/examples/cli_run.h"

namespace pixelgym {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

using testing::CliRun;

// Runs `pixelgym ARGUMENTS`, with `environment` ("NAME=value ...") set for it.
CliRun run(const std::string& arguments, const std::string& environment = "") {
  return testing::run_cli(arguments, environment);
}

// A path under the test output folder, with no file there yet.
std::string fresh_output(const std::string& name) {
  const std::filesystem::path path = std::filesystem::path(PIXELGYM_TEST_OUTPUT_DIR) / "cli" / name;
  std::filesystem::remove(path);
  EXPECT_FALSE(std::filesystem::exists(path)) << path;
  return path.string();
}

std::string asset(const std::string& relative) {
  return std::string(PIXELGYM_SOURCE_DIR) + "/assets/" + relative;
}

std::vector<std::uint8_t> bytes(const Array& frame) {
  const auto* data = frame.data<std::uint8_t>();
  return {data, data + frame.size()};
}

// What `snapshot`, `rollout` and `bench` promise, written out with the library: reset(seed),
// actions from Rng(seed), an unseeded reset() when an episode ends.
struct ApiRollout {
  ApiRollout(const std::string& id, const Params& kwargs, std::uint64_t seed)
      : env(make(id, kwargs)), action_rng(seed), obs(env->reset(seed).obs) {}
  StepResult step() {
    StepResult result = env->step(env->action_space().sample(action_rng));
    obs = result.obs;
    return result;
  }
  std::unique_ptr<Env> env;
  Rng action_rng;
  Value obs;
};

// --- list, info ---

// The tool starts without LibTorch (loading it took 0.9 s of every start): only pixelgym-train,
// which runs train and eval, links it. The dynamic loader lists what the tool needs.
TEST(PixelgymCliTest, TheToolDoesNotLoadLibTorch) {
  const CliRun loaded = run("--version", "LD_TRACE_LOADED_OBJECTS=1");
  EXPECT_EQ(loaded.exit_code, 0) << loaded.output;
  EXPECT_THAT(loaded.output, HasSubstr("libBulletDynamics"));  // the trace lists libraries
  std::vector<std::string> torch;
  std::istringstream lines(loaded.output);
  for (std::string line; std::getline(lines, line);) {
    if (line.find("libtorch") != std::string::npos || line.find("libc10") != std::string::npos) {
      torch.push_back(line);
    }
  }
  EXPECT_THAT(torch, ::testing::IsEmpty());
}

TEST(PixelgymCliTest, ListShowsEveryRegisteredIdWithItsDescription) {
  const CliRun result = run("list");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const std::string& id : registered_ids()) {
    EXPECT_THAT(result.output, HasSubstr(id + "  ")) << id;
    EXPECT_THAT(result.output, HasSubstr(default_registry().spec(id)->description)) << id;
  }
}

TEST(PixelgymCliTest, InfoShowsSpacesAndConfigKeys) {
  const CliRun result = run("info GridWorld-v0");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("observation_space: Discrete(16)"));
  EXPECT_THAT(result.output, HasSubstr("action_space:      Discrete(4)"));
  EXPECT_THAT(result.output, HasSubstr("render_width"));
  EXPECT_THAT(result.output, HasSubstr("max_episode_steps: 50"));
}

// info answers from the spec (Registry::describe): with OpenGL broken (GALLIUM_DRIVER names no
// driver, so creating a context fails or crashes, as the snapshot shows) it still prints every
// env's spaces, each observation key's range, the cameras and the time limit.
// A machine whose libEGL.so.1 cannot be loaded (here: an empty file found first on the library
// path): asking for EGL names the library and the packages to install.
TEST(PixelgymCliTest, AnUnloadableLibEglNamesThePackagesToInstall) {
  const std::filesystem::path folder =
      std::filesystem::path(PIXELGYM_TEST_OUTPUT_DIR) / "cli" / "broken_egl";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "libEGL.so.1").flush();
  const CliRun result = run("rollout CartPoleSwingup-v1 --episodes 1 --set render_backend=egl",
                            "LD_LIBRARY_PATH=" + folder.string());
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("cannot load libEGL.so.1"));
  EXPECT_THAT(result.output, HasSubstr("install libegl1 and libegl-mesa0"));
}

// libOSMesa is loaded when an OSMesa context is first made, not linked: without it the tool starts,
// and asking for OSMesa names the package.
TEST(PixelgymCliTest, AnUnloadableLibOSMesaNamesThePackageToInstall) {
  const std::filesystem::path folder =
      std::filesystem::path(PIXELGYM_TEST_OUTPUT_DIR) / "cli" / "broken_osmesa";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  std::ofstream(folder / "libOSMesa.so.8").flush();
  const std::string without_osmesa = "LD_LIBRARY_PATH=" + folder.string();
  EXPECT_EQ(run("list", without_osmesa).exit_code, 0);
  const CliRun result =
      run("rollout CartPoleSwingup-v1 --episodes 1 --set render_backend=osmesa", without_osmesa);
  EXPECT_NE(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("cannot load libOSMesa.so.8"));
  EXPECT_THAT(result.output, HasSubstr("install libosmesa6"));
  // render_backend=auto draws with EGL instead.
  const CliRun fallback = run(
      "snapshot CartPoleSwingup-v1 --out " + fresh_output("without_osmesa.png"), without_osmesa);
  EXPECT_EQ(fallback.exit_code, 0) << fallback.output;
}

TEST(PixelgymCliTest, InfoShowsRangesCamerasAndLimitsWithoutOpenGl) {
#if defined(__SANITIZE_ADDRESS__)
  // info's renderer line tries EGL too, and Mesa's EGL leaks 6 KB when its display fails to open,
  // in a driver it unloads (no module to suppress: docs/reliability.md); the leak check is off for
  // these runs only.
  const std::string broken_gl =
      "GALLIUM_DRIVER=no-such-driver ASAN_OPTIONS=\"$ASAN_OPTIONS detect_leaks=0\"";
#else
  const std::string broken_gl = "GALLIUM_DRIVER=no-such-driver";
#endif
  EXPECT_NE(
      run("snapshot CartPoleSwingup-v0 --out " + fresh_output("no_gl.png"), broken_gl).exit_code,
      0);
  for (const std::string& id : registered_ids()) {
    const CliRun result = run("info " + id, broken_gl);
    ASSERT_EQ(result.exit_code, 0) << id << ": " << result.output;
    const EnvDescription description = describe(id);
    EXPECT_THAT(
        result.output,
        HasSubstr("observation_space: " + description.observation_space->to_string() + "\n"));
    if (description.cameras.empty()) {
      EXPECT_THAT(result.output, HasSubstr("cameras:           none\n")) << id;
    } else {
      EXPECT_THAT(result.output,
                  HasSubstr("cameras:           " + description.cameras[0] + " (default)"))
          << id;
      for (const std::string& camera : description.cameras) {
        EXPECT_THAT(result.output, HasSubstr(camera)) << id;
      }
    }
    ASSERT_TRUE(description.max_episode_steps.has_value()) << id;
    EXPECT_THAT(
        result.output,
        HasSubstr("max_episode_steps: " + std::to_string(*description.max_episode_steps) + "\n"));
  }
  const std::string cartpole = run("info CartPoleSwingup-v0", broken_gl).output;
  EXPECT_THAT(cartpole,
              ::testing::ContainsRegex("\n  pixels +uint8 +\\(84, 84, 3\\) +\\[0, 255\\]\n"));
  EXPECT_THAT(cartpole,
              ::testing::ContainsRegex("\n  joint_pos +float32 +\\(2,\\) +\\[-inf, inf\\]\n"));
  EXPECT_THAT(run("info GridWorld-v0").output,
              ::testing::ContainsRegex("\n  \\(all\\) +int64 +\\(\\) +\\{0, \\.\\.\\., 15\\}\n"));
  // The limit follows the kwargs: 1000 control steps at action_repeat 4 are 250 env steps.
  EXPECT_THAT(run("info CartPoleSwingup-v0 --set action_repeat=4", broken_gl).output,
              HasSubstr("max_episode_steps: 250\n"));
  EXPECT_THAT(run("info GridWorld-v0 --set max_episode_steps=7").output,
              HasSubstr("max_episode_steps: 7\n"));
}

// Each config row's cells start where the header's do, after at least two spaces: a long default
// ("pixels+state") no longer runs into its description.
TEST(PixelgymCliTest, InfoConfigColumnsLineUpWithoutColliding) {
  for (const std::string id : {"CartPoleSwingup-v0", "GridWorld-v0", "ArmReach-v0"}) {
    const CliRun result = run("info " + id);
    ASSERT_EQ(result.exit_code, 0) << result.output;
    std::istringstream lines(result.output.substr(result.output.find("config (--set")));
    std::string line;
    std::getline(lines, line);
    std::getline(lines, line);  // the header
    ASSERT_THAT(line, StartsWith("  key ")) << result.output;
    std::vector<std::size_t> starts;
    for (const char* column : {"type", "default", "description"})
      starts.push_back(line.find(column));
    int rows = 0;
    while (std::getline(lines, line) && line.rfind("  ", 0) == 0) {
      ++rows;
      for (const std::size_t start : starts) {
        ASSERT_GT(line.size(), start) << line;
        EXPECT_NE(line[start], ' ') << id << ": \"" << line << "\"";
        EXPECT_EQ(line.substr(start - 2, 2), "  ") << id << ": \"" << line << "\"";
      }
    }
    EXPECT_EQ(rows, static_cast<int>(default_registry().spec(id)->params.size()) + 1) << id;
  }
  EXPECT_THAT(run("info CartPoleSwingup-v0").output,
              HasSubstr("\"pixels+state\"  \"pixels+state\" (Dict), \"pixels\" (Dict of the "
                        "image), \"rgb\" (the image Box itself, for CnnPolicy) or \"state\""));
}

// --- check ---

TEST(PixelgymCliTest, CheckGridWorldPasses) {
  const CliRun result = run("check GridWorld-v0 --seed 3");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("all 12 checks passed"));
}

TEST(PixelgymCliTest, UnknownIdIsAUsageErrorThatSuggests) {
  for (const char* command : {"check", "info", "rollout", "bench"}) {
    const CliRun result = run(std::string(command) + " GridWorld-v9");
    EXPECT_EQ(result.exit_code, 2) << command << ": " << result.output;
    EXPECT_THAT(result.output,
                HasSubstr("unknown env id \"GridWorld-v9\"; did you mean GridWorld-v0"));
    EXPECT_THAT(result.output, HasSubstr("\nRun 'pixelgym " + std::string(command) +
                                         " --help' for the options.\n"));
  }
}

// --- usage errors: exit 2, a message naming the problem, one line naming the usage's place ---

// The number of lines of `text`.
std::size_t lines(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n'));
}

struct UsageCase {
  std::string arguments;
  std::string message;
};

TEST(PixelgymCliTest, UsageErrorsExitTwoWithAClearMessage) {
  const std::string out = fresh_output("usage.png");
  const std::string arm = asset("arm/arm.urdf");
  const std::string max_int = "2147483647";
  const std::vector<UsageCase> cases = {
      {"frobnicate", "unknown subcommand \"frobnicate\""},
      {"", "A subcommand is required"},
      {"check", "id is required"},
      {"check GridWorld-v0 --bogus", "--bogus"},
      {"snapshot GridWorld-v0 --seed x --out " + out,
       "--seed: must be an integer from 0 to 18446744073709551615, got \"x\""},
      {"rollout GridWorld-v0 --seed -1",
       "--seed: must be an integer from 0 to 18446744073709551615, got \"-1\""},
      {"check GridWorld-v0 --seed 18446744073709551616", "got \"18446744073709551616\""},
      {"rollout GridWorld-v0 --episodes 0",
       "--episodes: must be an integer from 1 to " + max_int + ", got \"0\""},
      {"check GridWorld-v0 --steps 0", "--steps: must be an integer from 1 to " + max_int},
      {"bench GridWorld-v0 --steps 1.5", "--steps: must be an integer from 1 to " + max_int},
      {"snapshot GridWorld-v0 --steps -1 --out " + out, "--steps: must be an integer from 0 to"},
      {"view " + arm + " --out " + out + " --width 0",
       "--width: must be an integer from 1 to 8192"},
      {"view " + arm + " --out " + out + " --height 9000",
       "--height: must be an integer from 1 to 8192"},
      {"view " + arm + " --out " + out + " --camera nowhere", "--camera"},
      {"view " + arm, "--out is required"},
      {"snapshot GridWorld-v0 --out a.jpg",
       "writes PNG only: the file name must end in .png, got \"a.jpg\""},
      {"rollout GridWorld-v0 --snapshot last.jpeg", "must end in .png, got \"last.jpeg\""},
      {"view " + arm + " --out arm.bmp", "must end in .png, got \"arm.bmp\""},
      {"check GridWorld-v0 --set novalue", "--set expects key=value, got \"novalue\""},
      {"info GridWorld-v0 --set colour=red", "unknown kwarg \"colour\""},
      {"info GridWorld-v0 --set render_width=wide", "cannot read \"wide\" as an int"},
      // Spaces around a key or a number are refused alike, before or after.
      {"info GridWorld-v0 --set 'render_width= 64'",
       "--set render_width: \" 64\" has spaces around it; write render_width=64"},
      {"info GridWorld-v0 --set 'render_width=64 '",
       "--set render_width: \"64 \" has spaces around it; write render_width=64"},
      {"info GridWorld-v0 --set ' render_width=64'",
       "the key has spaces around it; write render_width=64"},
      {"snapshot GridWorld-v0 --observation --out " + out, "try --set obs_mode=pixels"},
      {"help nope", "help: unknown subcommand \"nope\""},
  };
  for (const UsageCase& c : cases) {
    const CliRun result = run(c.arguments);
    EXPECT_EQ(result.exit_code, 2) << c.arguments << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr(c.message)) << c.arguments;
    EXPECT_THAT(result.output, HasSubstr("Run 'pixelgym")) << c.arguments;
    EXPECT_THAT(result.output, Not(HasSubstr("Usage:"))) << c.arguments;
    EXPECT_THAT(result.output, Not(HasSubstr("not in range"))) << c.arguments;
  }
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists("a.jpg"));
}

// A usage error is the error and one line pointing to the help, not the help itself (40 lines
// for train): the message is what the user reads.
TEST(PixelgymCliTest, AUsageErrorIsTheErrorAndOneLineToTheHelp) {
  const CliRun train = run("train CartPoleSwingup-v0 --threads 0");
  EXPECT_EQ(train.exit_code, 2) << train.output;
  EXPECT_THAT(train.output, StartsWith("pixelgym: --threads: must be an integer from 1 to "));
  EXPECT_THAT(train.output,
              ::testing::EndsWith("\nRun 'pixelgym train --help' for the options.\n"));
  EXPECT_EQ(lines(train.output), 2U) << train.output;
  // CLI11's own "Could not convert: --steps = x" names no expectation: said as the others are.
  const CliRun steps = run("train CartPoleSwingup-v0 --steps 1.5");
  EXPECT_EQ(steps.exit_code, 2) << steps.output;
  EXPECT_EQ(steps.output,
            "pixelgym: --steps: expected an integer, got \"1.5\"\n"
            "Run 'pixelgym train --help' for the options.\n");
  const CliRun none = run("");
  EXPECT_EQ(none.exit_code, 2) << none.output;
  EXPECT_THAT(none.output, HasSubstr("\nRun 'pixelgym --help' for the subcommands.\n"));
  EXPECT_EQ(lines(none.output), 2U) << none.output;
  const CliRun kwarg = run("snapshot GridWorld-v0 --set colour=red --out x.png");
  EXPECT_EQ(kwarg.exit_code, 2) << kwarg.output;
  EXPECT_EQ(lines(kwarg.output), 2U) << kwarg.output;
  EXPECT_THAT(kwarg.output, HasSubstr("\nRun 'pixelgym snapshot --help' for the options.\n"));
}

// Each case exits 2 with its message, in two lines: the error and the one to the help.
void expect_two_line_usage_errors(const std::vector<UsageCase>& cases) {
  for (const UsageCase& c : cases) {
    const CliRun result = run(c.arguments);
    EXPECT_EQ(result.exit_code, 2) << c.arguments << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr(c.message)) << c.arguments;
    EXPECT_EQ(lines(result.output), 2U) << c.arguments << ": " << result.output;
  }
}

// Every name a user types is answered with the name it is a typo of, or the word's subcommand:
// kwargs, wrappers and their parameters, subcommands, algorithms.
TEST(PixelgymCliTest, MistypedNamesAreAnsweredWithDidYouMean) {
  const std::vector<UsageCase> cases = {
      {"info CartPoleSwingup-v0 --set widht=64",
       "CartPoleSwingup-v0: unknown kwarg \"widht\"; did you mean width? valid kwargs: "},
      {"info CartPoleSwingup-v0 --wrap grayscal",
       "unknown wrapper \"grayscal\"; did you mean grayscale? the wrappers are: "},
      {"info CartPoleSwingup-v1 --wrap greyscal",
       "did you mean greyscale? the wrappers are: resize, grayscale (also greyscale, grey, "
       "gray), "},
      {"info CartPoleSwingup-v1 --set obs_mode=rbg", "got \"rbg\"; did you mean rgb?\n"},
      {"info CartPoleSwingup-v0 --wrap frame_stack=3,paddin=zero",
       "unknown parameter \"paddin\"; did you mean padding?"},
      {"describe CartPoleSwingup-v0", "unknown subcommand \"describe\"; did you mean info?"},
      {"lsit", "unknown subcommand \"lsit\"; did you mean list?"},
      {"test GridWorld-v0", "unknown subcommand \"test\"; did you mean check?"},
      {"video CartPoleSwingup-v0", "unknown subcommand \"video\"; did you mean record?"},
      {"help describe", "help: unknown subcommand \"describe\"; did you mean info?"},
      {"train CartPoleSwingup-v0 --algo drqv3",
       "--algo: unknown algorithm \"drqv3\"; did you mean drqv2 or drq? (the algorithms: ppo, "
       "drqv2, drq)"},
      {"info CartPoleSwingup-v0 --wrap resize=64,48",
       "resize's size: expected HEIGHTxWIDTH (e.g. 64x64) or N for NxN, as resize=64x48"},
  };
  expect_two_line_usage_errors(cases);
  EXPECT_THAT(run("frobnicate").output, Not(HasSubstr("did you mean")));
  EXPECT_THAT(run("train CartPoleSwingup-v0 --algo sac").output,
              HasSubstr("unknown algorithm \"sac\" (the algorithms: ppo, drqv2, drq)"));
}

// CLI11's range and unknown-option messages said as the others are: the option, what it expects
// and what it got; an unknown option is answered with the one it is a typo of.
TEST(PixelgymCliTest, OutOfRangeAndUnknownOptionsNameWhatWasExpected) {
  const std::vector<UsageCase> cases = {
      {"train CartPoleSwingup-v1 --minutes abc",
       "pixelgym: --minutes: expected a number from 0 to 1e9, got \"abc\"\n"},
      {"train CartPoleSwingup-v1 --nproc 0",
       "pixelgym: --nproc: expected an integer from 1 to 1024, got \"0\"\n"},
      {"train CartPoleSwingup-v1 --eval-every=-5",
       "pixelgym: --eval-every: expected an integer from 0 to 1125899906842624, got \"-5\"\n"},
      {"eval runs/x --episodes 0",
       "pixelgym: --episodes: expected an integer from 1 to 1048576, got \"0\"\n"},
      {"compare runs/x --out x.png --width 3",
       "pixelgym: --width: expected an integer from 400 to 8000, got \"3\"\n"},
      {"train CartPoleSwingup-v1 --minute 3", "; --minute: did you mean --minutes?\n"},
      {"tets", "pixelgym: unknown subcommand \"tets\" (subcommands: "},
      {"info cartpoleswingup",
       "did you mean CartPoleSwingup-v1 or CartPoleSwingup-v0? (`pixelgym list`"},
  };
  expect_two_line_usage_errors(cases);
}

// Help says the defaults that are not a constant in words, not "=0", and names ids that exist.
TEST(PixelgymCliTest, HelpShowsTheTrueDefaultsAndCurrentIds) {
  const std::string train = run("train --help").output;
  EXPECT_THAT(train, Not(HasSubstr("1125899906842624]=0"))) << train;  // --eval-every
  EXPECT_THAT(train, HasSubstr("default: a tenth of --steps"));
  EXPECT_THAT(train, HasSubstr("(0, the default: no time limit)"));
  EXPECT_THAT(train, Not(HasSubstr("ppo.h")));
  EXPECT_THAT(train, HasSubstr("--print-config shows every field"));
  const std::string eval = run("eval --help").output;
  EXPECT_THAT(eval, HasSubstr("--seed UINT64 "));
  EXPECT_THAT(eval, Not(HasSubstr("--seed UINT64=0")));
  for (const char* command : {"train", "record", "bench"}) {
    const std::string help = run(std::string(command) + " --help").output;
    EXPECT_THAT(help, Not(HasSubstr("-v0 (`pixelgym list`"))) << command;
    EXPECT_THAT(help, HasSubstr("-v1 (`pixelgym list`")) << command;
  }
}

// The docs write "grey" (and "greyscale"): --wrap takes those words for grayscale, and
// `pixelgym wrappers` lists them.
TEST(PixelgymCliTest, WrapTakesTheDocsWordsForTheWrappers) {
  for (const char* alias : {"greyscale", "grey", "gray"}) {
    const CliRun result =
        run(std::string("info CartPoleSwingup-v0 --set obs_mode=pixels --wrap ") + alias);
    EXPECT_EQ(result.exit_code, 0) << alias << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("'pixels': Box(0.0, 255.0, (84, 84), uint8)")) << alias;
  }
  EXPECT_THAT(run("wrappers").output, HasSubstr("(also: greyscale, grey, gray)"));
}

TEST(PixelgymCliTest, UnknownKwargListsTheValidOnes) {
  const CliRun unknown = run("info GridWorld-v0 --set colour=red");
  EXPECT_EQ(unknown.exit_code, 2);
  EXPECT_THAT(unknown.output, HasSubstr("render_width (int, default 256)"));
}

// --- --version, help ---

TEST(PixelgymCliTest, VersionPrintsTheProjectVersion) {
  const CliRun result = run("--version");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, std::string("pixelgym ") + PIXELGYM_VERSION + "\n");
}

TEST(PixelgymCliTest, HelpListsEverySubcommandAndExplainsEach) {
  const CliRun help = run("help");
  ASSERT_EQ(help.exit_code, 0) << help.output;
  EXPECT_THAT(help.output, HasSubstr("Usage: pixelgym [OPTIONS] SUBCOMMAND"));
  const std::vector<std::string> subcommands = {
      "list",  "wrappers", "info",   "check",   "snapshot", "rollout", "bench", "record",
      "train", "eval",     "export", "compare", "inspect",  "view",    "help"};
  for (const std::string& name : subcommands) {
    EXPECT_THAT(help.output, HasSubstr("\n  " + name + " ")) << name;
    const CliRun one = run("help " + name);
    EXPECT_EQ(one.exit_code, 0) << name << ": " << one.output;
    EXPECT_THAT(one.output, HasSubstr("Usage: pixelgym " + name)) << name;
    EXPECT_EQ(one.output, run(name + " --help").output) << name;
  }
  EXPECT_EQ(run("--help").output, help.output);
}

// Each subcommand keeps its own options and defaults (one shared variable once gave snapshot
// bench's 2000 steps).
TEST(PixelgymCliTest, EachSubcommandShowsItsOwnDefaults) {
  EXPECT_THAT(run("check --help").output, HasSubstr("=100"));
  EXPECT_THAT(run("snapshot --help").output, HasSubstr("=0"));
  EXPECT_THAT(run("bench --help").output, HasSubstr("=2000"));
  EXPECT_THAT(run("rollout --help").output, HasSubstr("--episodes INT:>= 1=5"));
  for (const char* command : {"check", "snapshot", "rollout", "bench"}) {
    EXPECT_THAT(run(std::string(command) + " --help").output, HasSubstr("--seed UINT64=0"))
        << command;
  }
}

// --- snapshot: the PNG holds what the library gives for the same seed ---

TEST(PixelgymCliTest, SnapshotRenderIsTheEnvsRenderForTheSeed) {
  const std::string out = fresh_output("gridworld_small.png");
  const CliRun result = run("snapshot GridWorld-v0 --seed 4 --steps 7 --out " + out +
                            " --set render_width=96 --set render_height=64");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("(96x64 render(), GridWorld-v0, seed 4, 7 steps)"));
  const render::Image image = render::read_png(out);
  EXPECT_EQ(image.width, 96);
  EXPECT_EQ(image.height, 64);

  ApiRollout api("GridWorld-v0", {{"render_width", 96}, {"render_height", 64}}, 4);
  for (int t = 0; t < 7; ++t) {
    const StepResult step = api.step();
    if (step.terminated || step.truncated) api.env->reset();
  }
  EXPECT_EQ(image.pixels, bytes(api.env->render()));

  ApiRollout other("GridWorld-v0", {{"render_width", 96}, {"render_height", 64}}, 4);
  other.step();
  EXPECT_NE(image.pixels, bytes(other.env->render()));  // the test can tell frames apart
}

TEST(PixelgymCliTest, SnapshotObservationIsWhatTheAgentSees) {
  const std::string out = fresh_output("observation.png");
  const CliRun result =
      run("snapshot CartPoleSwingup-v0 --seed 3 --steps 4 --observation --out " + out);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const render::Image image = render::read_png(out);
  EXPECT_EQ(image.width, 84);
  EXPECT_EQ(image.height, 84);

  ApiRollout api("CartPoleSwingup-v0", {}, 3);
  for (int t = 0; t < 4; ++t) api.step();
  EXPECT_EQ(image.pixels, bytes(api.obs.dict().at("pixels").array()));
  ApiRollout after_reset("CartPoleSwingup-v0", {}, 3);
  EXPECT_NE(image.pixels, bytes(after_reset.obs.dict().at("pixels").array()));
}

// --seed is 0 unless given; snapshot's --steps is 0 (the frame after reset).
TEST(PixelgymCliTest, SnapshotDefaultsToSeedZeroAndTheFrameAfterReset) {
  const std::string plain = fresh_output("reset_default.png");
  const CliRun result = run("snapshot GridWorld-v0 --out " + plain);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("seed 0, 0 steps)"));
  ApiRollout api("GridWorld-v0", {}, 0);
  EXPECT_EQ(render::read_png(plain).pixels, bytes(api.env->render()));

  const std::string seeded = fresh_output("seed_default.png");
  ASSERT_EQ(run("snapshot CartPoleSwingup-v0 --steps 5 --observation --out " + seeded).exit_code,
            0);
  ApiRollout zero("CartPoleSwingup-v0", {}, 0);
  for (int t = 0; t < 5; ++t) zero.step();
  EXPECT_EQ(render::read_png(seeded).pixels, bytes(zero.obs.dict().at("pixels").array()));
}

TEST(PixelgymCliTest, SnapshotToUnwritablePathFailsClearly) {
  const CliRun result = run("snapshot GridWorld-v0 --seed 0 --out /proc/pixelgym/x.png");
  EXPECT_EQ(result.exit_code, 1);
  EXPECT_THAT(result.output, HasSubstr("/proc/pixelgym"));
}

// --- rollout: the returns the library gives for the same seed ---

std::string expected_rollout(const std::string& id, std::uint64_t seed, int episodes) {
  ApiRollout api(id, {}, seed);
  std::ostringstream out;
  double total = 0.0;
  for (int episode = 0; episode < episodes; ++episode) {
    if (episode > 0) api.env->reset();
    double episode_return = 0.0;
    int length = 0;
    StepResult step;
    do {
      step = api.step();
      episode_return += step.reward;
      ++length;
    } while (!step.terminated && !step.truncated);
    total += episode_return;
    out << "episode " << episode << ": return=" << episode_return << " length=" << length
        << (step.terminated ? " terminated" : " truncated") << "\n";
  }
  out << "mean_return=" << total / episodes << " episodes=" << episodes << "\n";
  return out.str();
}

TEST(PixelgymCliTest, RolloutPrintsTheReturnsOfTheSeededRandomPolicy) {
  const CliRun result = run("rollout GridWorld-v0 --episodes 3 --seed 1");
  EXPECT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, expected_rollout("GridWorld-v0", 1, 3));
  EXPECT_NE(result.output, expected_rollout("GridWorld-v0", 2, 3));
  EXPECT_EQ(run("rollout GridWorld-v0").output, expected_rollout("GridWorld-v0", 0, 5));
}

TEST(PixelgymCliTest, RolloutSnapshotIsTheLastEpisodesFinalFrame) {
  const std::string out = fresh_output("rollout_last.png");
  const CliRun result = run("rollout GridWorld-v0 --episodes 2 --seed 5 --snapshot " + out);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("wrote " + out));
  ApiRollout api("GridWorld-v0", {}, 5);
  for (int episode = 0; episode < 2; ++episode) {
    if (episode > 0) api.env->reset();
    for (StepResult step = api.step(); !step.terminated && !step.truncated;) step = api.step();
  }
  EXPECT_EQ(render::read_png(out).pixels, bytes(api.env->render()));
}

TEST(PixelgymCliTest, BenchPrintsStepsPerSecondLast) {
  const CliRun result = run("bench GridWorld-v0 --steps 50");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("GridWorld-v0: 50 steps ("));
  const std::size_t at = result.output.rfind("steps_per_s=");
  ASSERT_NE(at, std::string::npos) << result.output;
  EXPECT_EQ(result.output.find('\n', at), result.output.size() - 1);
  EXPECT_GT(std::stol(result.output.substr(at + 12)), 0);
}

TEST(PixelgymCliTest, BenchWithNumEnvsStepsAVectorEnvAndCountsEveryEnvStep) {
  const std::string small = " --set width=16 --set height=16 --steps 30";
  const CliRun pool = run("bench CartPoleSwingup-v0 --num-envs 3 --threads 2" + small);
  ASSERT_EQ(pool.exit_code, 0) << pool.output;
  EXPECT_THAT(pool.output, HasSubstr("CartPoleSwingup-v0: 30 env steps (10 batches of 3 envs"));
  EXPECT_THAT(pool.output, HasSubstr("AsyncVectorEnv, 2 threads"));
  const std::size_t at = pool.output.rfind("steps_per_s=");
  ASSERT_NE(at, std::string::npos) << pool.output;
  EXPECT_EQ(pool.output.find('\n', at), pool.output.size() - 1);
  EXPECT_GT(std::stol(pool.output.substr(at + 12)), 0);
  // --threads 0 is the sync loop; more threads than envs are clamped to one per env.
  EXPECT_THAT(run("bench CartPoleSwingup-v0 --num-envs 3 --threads 0" + small).output,
              HasSubstr("SyncVectorEnv, one thread"));
  EXPECT_THAT(run("bench CartPoleSwingup-v0 --num-envs 3 --threads 8" + small).output,
              HasSubstr("AsyncVectorEnv, 3 threads"));
  // Threads without a vector env would be ignored: refused instead.
  for (const char* threads : {" --threads 2", " --threads 0"}) {
    const CliRun alone = run(std::string("bench CartPoleSwingup-v0") + threads + small);
    EXPECT_EQ(alone.exit_code, 2) << threads << ": " << alone.output;
    EXPECT_THAT(alone.output, HasSubstr("give --num-envs N with it"));
  }
}

// --- --wrap: wrapper stacks from text ---

TEST(PixelgymCliTest, WrappersListsEverySpecForm) {
  const CliRun result = run("wrappers");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  for (const char* form : {"resize=HxW[,key=pixels]", "grayscale[=keep_dim=false][,key=pixels]",
                           "channel_first[=key=pixels]", "time_limit=<max_episode_steps>"}) {
    EXPECT_THAT(result.output, HasSubstr(form)) << form;
  }
}

TEST(PixelgymCliTest, EverySubcommandThatMakesAnEnvTakesWrap) {
  for (const char* command : {"info", "check", "snapshot", "rollout", "bench", "record"}) {
    EXPECT_THAT(run(std::string(command) + " --help").output, HasSubstr("--wrap SPEC")) << command;
  }
}

TEST(PixelgymCliTest, InfoWrapPrintsTheWrappedSpaces) {
  const CliRun result = run(
      "info CartPoleSwingup-v0 --set obs_mode=pixels+state --wrap resize=64x48 --wrap grayscale "
      "--wrap time_limit=50");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("wrapped:           resize=64x48\n"
                                       "wrapped:           grayscale\n"));
  EXPECT_THAT(result.output, HasSubstr("'pixels': Box(0.0, 255.0, (64, 48), uint8)"));
  EXPECT_THAT(result.output, HasSubstr("  pixels     uint8    (64, 48)  [0, 255]"));
  EXPECT_THAT(result.output, HasSubstr("max_episode_steps: 50\n"));
  // The kwarg's default stays the env's own.
  EXPECT_THAT(result.output, HasSubstr("max_episode_steps  int"));
  EXPECT_THAT(result.output, Not(HasSubstr("max_episode_steps  int     50")));
}

TEST(PixelgymCliTest, SnapshotObservationShowsTheWrappedImage) {
  const std::string out = fresh_output("wrapped_observation.png");
  const CliRun result = run("snapshot CartPoleSwingup-v0 --observation --seed 3 --out " + out +
                            " --wrap resize=32x24 --wrap grayscale");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("24x32 observation"));
  const auto env =
      wrappers::apply_wrappers(make("CartPoleSwingup-v0", {}), {"resize=32x24", "grayscale"});
  const Array gray = env->reset(3).obs.dict().at("pixels").array();
  ASSERT_EQ(gray.shape(), (Shape{32, 24}));
  std::vector<std::uint8_t> grey_rgb;
  for (std::int64_t i = 0; i < gray.size(); ++i)
    grey_rgb.insert(grey_rgb.end(), 3, gray.data<std::uint8_t>()[i]);
  const render::Image png = render::read_png(out);
  EXPECT_EQ(png.width, 24);
  EXPECT_EQ(png.height, 32);
  EXPECT_EQ(png.pixels, grey_rgb);
}

TEST(PixelgymCliTest, SnapshotObservationLaysPlanesSideBySide) {
  const std::string out = fresh_output("channel_first_observation.png");
  const CliRun result = run("snapshot CartPoleSwingup-v0 --observation --out " + out +
                            " --wrap resize=20x16 --wrap channel_first");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const render::Image png = render::read_png(out);
  EXPECT_EQ(png.width, 48);  // red, green and blue planes, each 16 wide
  EXPECT_EQ(png.height, 20);
}

TEST(PixelgymCliTest, RolloutAppliesTheWrappersInOrder) {
  const CliRun result =
      run("rollout CartPoleSwingup-v0 --episodes 2 --wrap time_limit=7 --wrap resize=16");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("episode 0: return="));
  EXPECT_THAT(result.output, HasSubstr(" length=7 truncated\nepisode 1:"));
}

TEST(PixelgymCliTest, CheckAndBenchRunWrapped) {
  const CliRun check =
      run("check CartPoleSwingup-v0 --steps 10 --wrap resize=32x32 --wrap grayscale");
  EXPECT_EQ(check.exit_code, 0) << check.output;
  EXPECT_THAT(check.output, HasSubstr("checks passed"));
  const CliRun bench =
      run("bench CartPoleSwingup-v0 --steps 20 --wrap resize=64x64 --wrap grayscale");
  EXPECT_EQ(bench.exit_code, 0) << bench.output;
  EXPECT_THAT(bench.output, HasSubstr("steps_per_s="));
}

TEST(PixelgymCliTest, BadWrapSpecIsAUsageErrorNamingWrapperArgumentAndExpectation) {
  const CliRun syntax = run("bench CartPoleSwingup-v0 --wrap resize=64y64");
  EXPECT_EQ(syntax.exit_code, 2) << syntax.output;
  EXPECT_THAT(syntax.output,
              HasSubstr("wrapper spec \"resize=64y64\": resize's size: expected HEIGHTxWIDTH"));
  const CliRun unknown = run("info CartPoleSwingup-v0 --wrap blur=3");
  EXPECT_EQ(unknown.exit_code, 2) << unknown.output;
  EXPECT_THAT(unknown.output, HasSubstr("unknown wrapper \"blur\"; the wrappers are: resize"));
  const CliRun not_an_image = run("check GridWorld-v0 --wrap grayscale");
  EXPECT_EQ(not_an_image.exit_code, 2) << not_an_image.output;
  EXPECT_THAT(not_an_image.output, HasSubstr("GrayscaleObservation"));
  const CliRun range = run("rollout CartPoleSwingup-v0 --wrap resize=0x8");
  EXPECT_EQ(range.exit_code, 2) << range.output;
  EXPECT_THAT(range.output, HasSubstr("wrapper spec \"resize=0x8\": ResizeObservation"));
}

// --- inspect ---

const std::vector<std::string> kAssetUrdfs = {
    "acrobot/acrobot.urdf",         "arm/arm.urdf",           "cheetah/cheetah.urdf",
    "ball_in_cup/ball_in_cup.urdf", "cartpole/cartpole.urdf", "finger/finger.urdf",
    "cartpole/cartpole_v1.urdf",    "objects/cube.urdf",      "objects/table.urdf",
    "objects/target.urdf",          "pendulum/pendulum.urdf", "reacher/reacher.urdf",
    "reacher/reacher_v1.urdf",      "walker/walker.urdf"};

TEST(PixelgymCliTest, InspectWorksOnEveryAsset) {
  std::set<std::string> found;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(asset(""))) {
    if (entry.path().extension() == ".urdf") {
      found.insert(std::filesystem::relative(entry.path(), asset("")).string());
    }
  }
  EXPECT_EQ(found, std::set<std::string>(kAssetUrdfs.begin(), kAssetUrdfs.end()));
  for (const std::string& urdf : kAssetUrdfs) {
    const CliRun result = run("inspect " + asset(urdf));
    EXPECT_EQ(result.exit_code, 0) << urdf << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("simulates:")) << urdf;
  }
  const CliRun arm = run("inspect " + asset("arm/arm.urdf"));
  EXPECT_THAT(arm.output, HasSubstr("link3.obj   1152 triangles"));
  EXPECT_THAT(arm.output, HasSubstr("limits [-2.090, 2.090] rad"));
  EXPECT_THAT(arm.output, HasSubstr("total mass 23.200 kg"));
  // dm_control's cheetah: 14 kg and its joint springs (<dynamics stiffness>).
  const CliRun cheetah = run("inspect " + asset("cheetah/cheetah.urdf"));
  EXPECT_THAT(cheetah.output, HasSubstr("total mass 14.002 kg"));
  EXPECT_THAT(cheetah.output, HasSubstr("damping 6.000   stiffness 240.000"));
}

TEST(PixelgymCliTest, InspectCountsAFloatingBasesSixDegreesAndSaysOneInTheSingular) {
  const CliRun cube = run("inspect --floating-base " + asset("objects/cube.urdf"));
  EXPECT_EQ(cube.exit_code, 0) << cube.output;
  EXPECT_THAT(cube.output,
              HasSubstr("simulates: 6 degrees of freedom (0 joints + 6 of the floating base), "
                        "floating base"));
  const CliRun fixed = run("inspect " + asset("objects/cube.urdf"));
  EXPECT_THAT(fixed.output, HasSubstr("simulates: 0 degrees of freedom"));
  const CliRun pendulum = run("inspect " + asset("pendulum/pendulum.urdf"));
  EXPECT_THAT(pendulum.output, HasSubstr("simulates: 1 degree of freedom (1 joint), fixed base"));
  EXPECT_THAT(pendulum.output, ::testing::Not(HasSubstr("1 degrees")));
}

TEST(PixelgymCliTest, InspectRefusesEveryBadFileNamingTheProblem) {
  const std::string dir = std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/urdf/";
  const std::vector<std::string> bad = {"bad_inertia",
                                        "detached_cycle",
                                        "floating_joint",
                                        "infinite_origin",
                                        "joint_cycle",
                                        "malformed_xml",
                                        "mesh_without_triangles",
                                        "missing_mesh",
                                        "nan_box_size",
                                        "negative_mass",
                                        "negative_radius",
                                        "negative_root_mass",
                                        "no_links",
                                        "planar_joint",
                                        "reversed_limits",
                                        "two_parents",
                                        "two_roots",
                                        "unknown_link",
                                        "unreadable_mesh",
                                        "unresolvable_package",
                                        "unsupported_mesh_format",
                                        "zero_mass"};
  for (const std::string& name : bad) {
    const std::string path = dir + name + ".urdf";
    ASSERT_TRUE(std::filesystem::exists(path)) << path;
    const CliRun result = run("inspect " + path);
    EXPECT_EQ(result.exit_code, 1) << path << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("pixelgym: error: URDF " + path + ": ")) << name;
  }
  EXPECT_EQ(run("inspect " + dir + "minimal_valid.urdf").exit_code, 0);
}

// Issue 42: hostile URDFs made inspect, view and check crash (a stack overflow) or hang (a FIFO)
// or fill memory (/dev/zero). Each is refused with a message naming the file. `timeout` turns a
// hang into a failure.
TEST(PixelgymCliTest, HostileUrdfFilesAreRefusedNamingTheFile) {
  const std::filesystem::path folder =
      std::filesystem::path(PIXELGYM_TEST_OUTPUT_DIR) / "cli" / "hostile_urdf";
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  std::string nest;
  for (int i = 0; i < 50000; ++i) nest += "<x>";
  for (int i = 0; i < 50000; ++i) nest += "</x>";
  const std::string deep = (folder / "unknown_node.urdf").string();
  std::ofstream(deep) << "<robot name=\"r\"><link name=\"a\"/><1 \"> " << nest << " \"></robot>";
  const std::string fifo = (folder / "fifo.urdf").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string zero = (folder / "zero.urdf").string();
  std::filesystem::create_symlink("/dev/zero", zero);
  const std::vector<std::pair<std::string, std::string>> files = {
      {deep, "elements nested more than 100 deep"},
      {fifo, "is a FIFO, not a regular file"},
      {zero, "is a symbolic link to /dev/zero, which is a character device, not a regular file"}};
  for (const auto& [path, problem] : files) {
    const std::string cli = "timeout 20 " + std::string(PIXELGYM_CLI) + " ";
    for (const std::string& command :
         {"inspect " + path, "view " + path + " --out " + fresh_output("hostile.png"),
          "check UrdfReach-v0 --steps 1 --set urdf=" + path}) {
      const CliRun result = testing::run_program(cli + command);
      EXPECT_EQ(result.exit_code, 1) << command << ": " << result.output;
      EXPECT_THAT(result.output, HasSubstr("URDF " + path + ": " + problem)) << command;
    }
  }
  std::filesystem::remove_all(folder);
}

// --- view ---

// The share of pixels of `image` that differ (by more than 24 summed over R, G, B) from the empty
// scene — floor and sky — seen through the camera `view` frames `urdf` with: measured from the
// PNG, not taken from the tool's own figure. Mirrors run_view's placement (lifted onto the floor)
// and its "iso" viewpoint; shadows off.
double robot_share(const std::string& urdf, const render::Image& image) {
  const auto model = engine::default_model_cache().load_urdf(urdf);
  engine::RobotOptions placement;
  Eigen::AlignedBox3f bounds;
  for (int attempt = 0; attempt < 2; ++attempt) {
    engine::WorldConfig config;
    config.ground_plane = false;
    engine::World world(config);
    world.add_robot(model, placement);
    bounds = WorldScene(world).bounds();
    placement.X_world_base.translation().z() = std::max(0.0F, -bounds.min().z());
  }
  engine::WorldConfig config;
  config.ground_plane = false;
  engine::World world(config);
  WorldScene empty(world);
  empty.scene().shadows = false;
  const render::Camera camera = frame_box(bounds, -50.0F, 25.0F, image.width, image.height);
  std::vector<std::uint8_t> background(image.pixels.size());
  render::Renderer().render(empty.scene(), camera,
                            {camera.width, camera.height, background.data()});
  int differ = 0;
  for (std::size_t i = 0; i < background.size(); i += 3) {
    int distance = 0;
    for (std::size_t c = 0; c < 3; ++c)
      distance += std::abs(image.pixels[i + c] - background[i + c]);
    differ += distance > 24 ? 1 : 0;
  }
  return static_cast<double>(differ) / static_cast<double>(background.size() / 3);
}

TEST(PixelgymCliTest, ViewRendersEveryAssetRobotVisibly) {
  for (const std::string& urdf : kAssetUrdfs) {
    const std::string out =
        fresh_output("view_" + std::filesystem::path(urdf).stem().string() + ".png");
    const CliRun result = run("view " + asset(urdf) + " --out " + out +
                              " --width 160 --height 120 --msaa 0 --no-shadows");
    ASSERT_EQ(result.exit_code, 0) << urdf << ": " << result.output;
    const render::Image image = render::read_png(out);
    EXPECT_EQ(image.width, 160);
    EXPECT_EQ(image.height, 120);
    // Framed automatically: the robot fills a good part of the picture, as measured here and as
    // the tool says.
    const double measured = 100.0 * robot_share(asset(urdf), image);
    EXPECT_GT(measured, 1.5) << urdf;
    const std::size_t at = result.output.find("robot covers ");
    ASSERT_NE(at, std::string::npos) << result.output;
    EXPECT_NEAR(std::stod(result.output.substr(at + 13)), measured, 1.0) << urdf;
  }
  EXPECT_THAT(
      run("view " + asset("objects/cube.urdf") + " --out " + fresh_output("cube.png")).output,
      HasSubstr("1 visual shape,"));
}

// --msaa accepts exactly what the OpenGL offers (help lists it) and refuses the next step up.
// The sample counts `view --help` lists for --msaa: what this machine's OpenGL offers.
std::vector<int> offered_msaa() {
  const std::string help = run("view --help").output;
  const std::size_t open = help.find("--msaa INT:{");
  EXPECT_NE(open, std::string::npos) << help;
  if (open == std::string::npos) return {};
  const std::size_t close = help.find('}', open);
  std::vector<int> offered;
  std::istringstream list(help.substr(open + 12, close - open - 12));
  for (std::string item; std::getline(list, item, ',');) offered.push_back(std::stoi(item));
  return offered;
}

TEST(PixelgymCliTest, ViewOffersTheMsaaSamplesTheOpenGlHas) {
  const std::vector<int> offered = offered_msaa();
  ASSERT_GE(offered.size(), 2U);  // 0 and at least 2
  EXPECT_EQ(offered.front(), 0);
  const std::string cube = asset("objects/cube.urdf");
  for (const int samples : offered) {
    const std::string out = fresh_output("msaa_" + std::to_string(samples) + ".png");
    const CliRun result = run("view " + cube + " --out " + out + " --width 32 --height 32 --msaa " +
                              std::to_string(samples));
    EXPECT_EQ(result.exit_code, 0) << samples << ": " << result.output;
    EXPECT_TRUE(std::filesystem::exists(out)) << samples;
  }
  for (const int samples : {offered.back() * 2, 3, -1}) {
    const CliRun result = run("view " + cube + " --out x.png --msaa " + std::to_string(samples));
    EXPECT_EQ(result.exit_code, 2) << samples << ": " << result.output;
    EXPECT_THAT(result.output, HasSubstr("offers 0, 2")) << samples;
  }
}

// The msaa kwarg takes what the OpenGL offers (0, 2 and 4 on llvmpipe; 8 too on a GPU): more is
// a usage error at make, naming what it offers, not a failure at the first frame.
TEST(PixelgymCliTest, MsaaKwargTakesWhatTheOpenGlOffers) {
  const std::vector<int> offered = offered_msaa();
  ASSERT_GE(offered.size(), 2U);
  std::string list;
  for (const int samples : offered) list += (list.empty() ? "" : ", ") + std::to_string(samples);
  for (const int samples : {2, 4, 8}) {
    const std::string out = fresh_output("kwarg_msaa_" + std::to_string(samples) + ".png");
    const CliRun result =
        run("snapshot CartPoleSwingup-v0 --set obs_mode=pixels --set width=32 --set height=32 "
            "--observation --set msaa=" +
            std::to_string(samples) + " --out " + out);
    if (std::find(offered.begin(), offered.end(), samples) != offered.end()) {
      EXPECT_EQ(result.exit_code, 0) << samples << ": " << result.output;
      EXPECT_TRUE(std::filesystem::exists(out)) << samples;
    } else {
      EXPECT_EQ(result.exit_code, 2) << samples << ": " << result.output;
      EXPECT_THAT(result.output, HasSubstr("CartPoleSwingup-v0: msaa=" + std::to_string(samples) +
                                           " is more than this OpenGL offers ("))
          << samples;
      EXPECT_THAT(result.output, HasSubstr("): it takes msaa " + list + "\n")) << samples;
      EXPECT_FALSE(std::filesystem::exists(out)) << samples;
    }
  }
}

TEST(PixelgymCliTest, ViewFailuresOfTheRunExitOne) {
  const std::string out = fresh_output("bad.png");
  const CliRun missing = run("view /nonexistent/robot.urdf --out " + out);
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_THAT(missing.output, HasSubstr("/nonexistent/robot.urdf"));
  const CliRun unwritable = run("view " + asset("arm/arm.urdf") + " --out /proc/pixelgym/arm.png");
  EXPECT_EQ(unwritable.exit_code, 1);
  EXPECT_THAT(unwritable.output, HasSubstr("/proc/pixelgym"));
  EXPECT_FALSE(std::filesystem::exists(out));
}

}  // namespace
}  // namespace pixelgym
