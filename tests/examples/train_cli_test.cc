// `pixelgym train` and `pixelgym eval` as a user runs them: a short pixel run writes a complete
// run folder, a run killed with SIGKILL resumes from its last checkpoint, and a truncated or
// corrupt checkpoint is refused, never loaded. Tiny settings (32x32 pixels, 2 envs, 16-step
// rollouts) keep it to seconds; learning itself is measured in bench/, not here.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "examples/trainer/drqv2/drqv2.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/testing/mlp_policy.h"
#include "pixelgym/trainer/checkpoint_file.h"
#include "pixelgym/trainer/progress_csv.h"
#include "pixelgym/trainer/recipes.h"
#include "pixelgym/trainer/training_run.h"
#include "tests/envs/tasks/scripted.h"
#include "tests/examples/cli_run.h"

namespace pixelgym::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// A fresh folder for one test.
fs::path fresh_folder(const std::string& name) {
  const fs::path folder =
      fs::temp_directory_path() / ("pixelgym_train_cli_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(folder);
  fs::create_directories(folder);
  return folder;
}

constexpr const char* kTinyConfig =
    R"({"num_steps": 16, "num_minibatches": 2, "update_epochs": 1})";

// The settings every run here uses, then `more`; `config` is the PPO config's JSON and
// `obs_mode` the env's.
std::string train_arguments(const fs::path& folder, const std::string& more,
                            const std::string& config = kTinyConfig,
                            const std::string& obs_mode = "pixels") {
  const fs::path config_file = folder / "tiny.json";
  std::ofstream(config_file) << config;
  return "train CartPoleBalance-v0 --set obs_mode=" + obs_mode +
         " --set width=32 --set height=32 --set max_episode_steps=24 --wrap frame_stack=2 "
         "--num-envs 2 --threads 2 --config " +
         config_file.string() + " --eval-episodes 1 --quiet " + more;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(TrainCliTest, AShortRunWritesACompleteRunFolder) {
  const fs::path folder = fresh_folder("complete");
  const fs::path run = folder / "run";
  const CliRun trained =
      run_cli(train_arguments(folder, "--steps 320 --checkpoint-every 4 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  EXPECT_NE(trained.output.find("evaluation: return"), std::string::npos) << trained.output;

  const json config = json::parse(read_text(run / "config.json"));
  EXPECT_EQ(config.at("env_id"), "CartPoleBalance-v0");
  EXPECT_EQ(config.at("wrap"), json::array({"frame_stack=2"}));
  EXPECT_EQ(config.at("ppo").at("num_steps"), 16);
  EXPECT_TRUE(config.contains("code_version"));
  // LibTorch's threads default to one per core this process may run on (not OpenMP's default,
  // which was 1 on a 2-core VM), and config.json records the count.
  if (std::getenv("OMP_NUM_THREADS") == nullptr) {
    cpu_set_t cpus;
    CPU_ZERO(&cpus);
    ASSERT_EQ(sched_getaffinity(0, sizeof(cpus), &cpus), 0);
    EXPECT_EQ(config.at("torch_threads"), CPU_COUNT(&cpus));
  }

  // 320 steps of 2 envs x 16: 10 updates, one row each.
  const trainer::ProgressTable progress = trainer::read_progress_csv(run / "progress.csv");
  ASSERT_EQ(progress.rows.size(), 10U);
  EXPECT_EQ(progress.column("steps").front(), 32.0);
  EXPECT_EQ(progress.column("steps").back(), 320.0);
  EXPECT_GT(progress.column("fps").back(), 0.0);
  EXPECT_TRUE(std::isfinite(progress.column("entropy").back()));

  // Checkpoints after updates 4 and 8 (every 4) and at the end (10), all loadable.
  for (const char* name : {"ckpt-000004.pgck", "ckpt-000008.pgck", "ckpt-000010.pgck"}) {
    const trainer::CheckpointBlobs blobs = trainer::read_checkpoint(run / name);
    EXPECT_EQ(blobs.count("model"), 1U) << name;
    EXPECT_EQ(blobs.count("optimizer"), 1U) << name;
  }
  const std::string png = read_text(run / "curve.png");
  ASSERT_GT(png.size(), 8U);
  EXPECT_EQ(png.substr(1, 3), "PNG");
  EXPECT_GT(fs::file_size(run / "final.mp4"), 0U);
  const json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary.at("env_steps"), 320);
  EXPECT_EQ(summary.at("evaluation").at("episodes"), 1);

  // The run evaluates again from its folder, the same as at the end of training: by default
  // with the final evaluation's episodes and seed (summary.json's), and says so.
  const CliRun evaluated = run_cli("eval " + run.string());
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  EXPECT_THAT(evaluated.output,
              ::testing::HasSubstr(", 1 episodes from seed 1000000 (as summary.json)"));
  std::ostringstream expected;
  expected << "return_mean=" << summary.at("evaluation").at("return_mean").get<double>();
  EXPECT_NE(evaluated.output.find(expected.str()), std::string::npos) << evaluated.output;
  // And the share of action elements the policy put outside the bounds, the same both times.
  const double clipped = summary.at("evaluation").at("clipped_action_fraction").get<double>();
  EXPECT_GE(clipped, 0.0);
  EXPECT_LE(clipped, 1.0);
  std::ostringstream expected_clipped;
  expected_clipped << "clipped_action_fraction=" << clipped << "\n";
  EXPECT_NE(evaluated.output.find(expected_clipped.str()), std::string::npos) << evaluated.output;
  // Played elsewhere: with other kwargs over the run's, or in another env of the same spaces (a
  // -distracting variant); an env of other spaces is refused, naming both.
  const CliRun varied = run_cli("eval " + run.string() + " --episodes 1 --set variation=0.5");
  ASSERT_EQ(varied.exit_code, 0) << varied.output;
  EXPECT_THAT(varied.output, ::testing::HasSubstr(": CartPoleBalance-v0, 1 episodes"));
  const CliRun distracting =
      run_cli("eval " + run.string() + " --episodes 1 --env CartPoleSwingup-distracting-v1");
  ASSERT_EQ(distracting.exit_code, 0) << distracting.output;
  EXPECT_THAT(distracting.output,
              ::testing::HasSubstr(": CartPoleSwingup-distracting-v1, 1 episodes"));
  const CliRun other = run_cli("eval " + run.string() + " --episodes 1 --env CheetahRun-v0");
  EXPECT_NE(other.exit_code, 0);
  EXPECT_THAT(other.output,
              ::testing::HasSubstr("CheetahRun-v0's action space Box(-1.0, 1.0, (6,), float32) is "
                                   "not the run's (CartPoleBalance-v0: Box(-1.0, 1.0, (1,)"));
  // A checkpoint file carries its run's settings: copied away from its folder, it evaluates
  // the same.
  const fs::path away = folder / "away";
  fs::create_directories(away);
  fs::copy_file(run / "ckpt-000010.pgck", away / "final.pgck");
  const CliRun alone =
      run_cli("eval " + (away / "final.pgck").string() + " --episodes 1 --seed 1000000");
  ASSERT_EQ(alone.exit_code, 0) << alone.output;
  EXPECT_NE(alone.output.find(expected.str()), std::string::npos) << alone.output;
  // A checkpoint without the settings (written before they were kept) needs its folder's
  // config.json: away from it, it is refused by name; beside it, it evaluates the same.
  trainer::CheckpointBlobs older = trainer::read_checkpoint(run / "ckpt-000010.pgck");
  older.erase("config");
  trainer::write_checkpoint(away / "older.pgck", older);
  const CliRun lost = run_cli("eval " + (away / "older.pgck").string() + " --episodes 1");
  EXPECT_EQ(lost.exit_code, 1) << lost.output;
  EXPECT_NE(lost.output.find("does not carry its run's settings, and there is no config.json in " +
                             away.string()),
            std::string::npos)
      << lost.output;
  trainer::write_checkpoint(run / "older.pgck", older);
  const CliRun beside =
      run_cli("eval " + (run / "older.pgck").string() + " --episodes 1 --seed 1000000");
  ASSERT_EQ(beside.exit_code, 0) << beside.output;
  EXPECT_NE(beside.output.find(expected.str()), std::string::npos) << beside.output;
  fs::remove(run / "older.pgck");
  // A video is written as H.264 .mp4 only: any other name is refused before the work, and
  // nothing is written.
  const CliRun avi =
      run_cli("eval " + run.string() + " --episodes 1 --video " + (folder / "clip.avi").string());
  EXPECT_EQ(avi.exit_code, 2) << avi.output;
  EXPECT_NE(avi.output.find("expected a FILE.mp4, got"), std::string::npos) << avi.output;
  EXPECT_FALSE(fs::exists(folder / "clip.mp4"));
  EXPECT_FALSE(fs::exists(folder / "clip.avi"));
  // So is a path that cannot take the video, before the episodes (a folder named clip.mp4 was
  // found by the rename, after them, and no return was printed).
  fs::create_directories(folder / "folder.mp4");
  const CliRun into_folder =
      run_cli("eval " + run.string() + " --episodes 1 --video " + (folder / "folder.mp4").string());
  EXPECT_EQ(into_folder.exit_code, 2) << into_folder.output;
  EXPECT_THAT(into_folder.output, ::testing::HasSubstr("is a folder; name a video file"));
  EXPECT_THAT(into_folder.output, ::testing::Not(::testing::HasSubstr("episode 0")));
  fs::remove(folder / "folder.mp4");
  // A second run into the same folder is refused; the run is left as it was.
  const CliRun again = run_cli(train_arguments(folder, "--steps 32 --out " + run.string()));
  EXPECT_EQ(again.exit_code, 1) << again.output;
  EXPECT_EQ(trainer::read_progress_csv(run / "progress.csv").rows.size(), 10U);
  fs::remove_all(folder);
}

// Runs `pixelgym ARGUMENTS` (output to {folder}/log.txt) and kills it with SIGKILL as soon as
// `file` exists (within 120 s). Returns whether it was killed (not ended by itself first).
bool run_cli_until(const fs::path& folder, const std::string& arguments, const fs::path& file) {
  const std::string command =
      std::string(PIXELGYM_CLI) + " " + arguments + " > " + (folder / "log.txt").string() + " 2>&1";
  const pid_t child = fork();
  if (child < 0) return false;
  if (child == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(file) && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFSIGNALED(status);
}

TEST(TrainCliTest, TorchThreadsAreRecordedAndKeptOnResume) {
  const fs::path folder = fresh_folder("torch_threads");
  const fs::path run = folder / "run";
  const CliRun first = run_cli(train_arguments(
      folder, "--steps 32 --torch-threads 1 --checkpoint-every 1 --out " + run.string()));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  EXPECT_EQ(json::parse(read_text(run / "config.json")).at("torch_threads"), 1);
  // --resume reads the count back from config.json (results depend on it).
  const CliRun resumed = run_cli("train --resume " + run.string() + " --steps 64 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("torch_threads=1 (as the run began)"), std::string::npos)
      << resumed.output;
  fs::remove_all(folder);
}

// The checkpoint files of a run folder, lowest update first.
std::vector<std::string> checkpoint_names(const fs::path& run) {
  std::vector<std::string> names;
  for (const fs::path& path : trainer::list_checkpoints(run)) names.push_back(path.filename());
  return names;
}

TEST(TrainCliTest, OnlyTheNewestCheckpointsAreKept) {
  const fs::path folder = fresh_folder("keep");
  const fs::path run = folder / "run";
  // 7 updates, a checkpoint after each: the default keeps the newest 3.
  const CliRun trained =
      run_cli(train_arguments(folder, "--steps 224 --checkpoint-every 1 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  EXPECT_EQ(checkpoint_names(run),
            (std::vector<std::string>{"ckpt-000005.pgck", "ckpt-000006.pgck", "ckpt-000007.pgck"}));
  EXPECT_EQ(json::parse(read_text(run / "config.json")).at("keep_checkpoints"), 3);
  // The resumed run keeps the run's setting: 2 more updates, still the newest 3.
  const CliRun resumed = run_cli("train --resume " + run.string() + " --steps 288 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_EQ(checkpoint_names(run),
            (std::vector<std::string>{"ckpt-000007.pgck", "ckpt-000008.pgck", "ckpt-000009.pgck"}));
  fs::remove_all(folder);
}

TEST(TrainCliTest, ResumeRefusesSettingsThatDifferFromTheRunsAndAcceptsTheSame) {
  const fs::path folder = fresh_folder("resume_flags");
  const fs::path run = folder / "run";
  const CliRun first = run_cli(train_arguments(folder, "--steps 32 --out " + run.string()));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  // The run has --threads 2 and --keep-checkpoints 3 (the default); asking for others is an
  // error naming each, and nothing is trained.
  const CliRun refused = run_cli("train --resume " + run.string() +
                                 " --steps 64 --threads 1 --keep-checkpoints 0 --seed 0 --quiet");
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_NE(refused.output.find("these differ from them: --threads 1 (the run's: 2), "
                                "--keep-checkpoints 0 (the run's: 3) (only --steps and "
                                "--minutes may change)"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(trainer::read_progress_csv(run / "progress.csv").rows.size(), 1U);
  // The run's own values (and --seed 0, its seed) are accepted.
  const CliRun resumed = run_cli("train --resume " + run.string() +
                                 " --steps 64 --threads 2 --keep-checkpoints 3 --seed 0 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_EQ(trainer::read_progress_csv(run / "progress.csv").rows.size(), 2U);
  fs::remove_all(folder);
}

TEST(TrainCliTest, ARunKilledMidTrainingResumesFromItsLastCheckpoint) {
  const fs::path folder = fresh_folder("killed");
  const fs::path run = folder / "run";
  // A long run, killed with SIGKILL once its second checkpoint exists.
  const bool killed = run_cli_until(
      folder,
      train_arguments(
          folder, "--steps 100000 --checkpoint-every 2 --keep-checkpoints 0 --out " + run.string()),
      run / "ckpt-000004.pgck");
  ASSERT_TRUE(fs::exists(run / "ckpt-000004.pgck")) << read_text(folder / "log.txt");
  ASSERT_TRUE(killed);

  const trainer::CheckpointSearch latest = trainer::find_latest_checkpoint(run);
  ASSERT_TRUE(latest.latest.has_value());
  const std::int64_t resumed_update = latest.latest->update;
  EXPECT_GE(resumed_update, 4);
  const CliRun resumed =
      run_cli("train --resume " + run.string() + " --steps " +
              std::to_string((resumed_update + 2) * 32) + " --quiet --checkpoint-every 2");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("resuming " + run.string() + " from ckpt-" +
                                std::string(resumed_update < 10 ? "00000" : "0000") +
                                std::to_string(resumed_update)),
            std::string::npos)
      << resumed.output;
  // ... and continues from its step count, doing only the 2 updates left.
  EXPECT_NE(resumed.output.find("(" + std::to_string(resumed_update * 32) + " env steps, " +
                                std::to_string(resumed_update) + " updates)"),
            std::string::npos)
      << resumed.output;
  const json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary.at("updates"), resumed_update + 2);
  // Rows logged after that checkpoint were dropped and logged again: one row per update, in
  // order, to the end.
  const trainer::ProgressTable progress = trainer::read_progress_csv(run / "progress.csv");
  ASSERT_EQ(progress.rows.size(), static_cast<std::size_t>(resumed_update + 2));
  const std::vector<double> steps = progress.column("steps");
  for (std::size_t i = 0; i < steps.size(); ++i) {
    EXPECT_EQ(steps[i], static_cast<double>(i + 1) * 32) << "row " << i;
  }
  fs::remove_all(folder);
}

// A run killed before its first checkpoint has nothing to resume from: --resume starts it afresh
// with its settings (it was refused, "no valid checkpoint there", and so was --out, "already
// holds a run", leaving the folder with no way forward).
TEST(TrainCliTest, ARunKilledBeforeItsFirstCheckpointResumesAfresh) {
  const fs::path folder = fresh_folder("killed_early");
  const fs::path run = folder / "run";
  const bool killed = run_cli_until(
      folder,
      train_arguments(folder, "--steps 100000 --checkpoint-every 1000 --out " + run.string()),
      run / "progress.csv");
  ASSERT_TRUE(killed) << read_text(folder / "log.txt");
  ASSERT_TRUE(trainer::list_checkpoints(run).empty());
  const CliRun again = run_cli(train_arguments(folder, "--steps 64 --out " + run.string()));
  EXPECT_NE(again.exit_code, 0);
  EXPECT_THAT(again.output, ::testing::HasSubstr("already holds a run (config.json); resume it"));

  const CliRun resumed = run_cli("train --resume " + run.string() + " --steps 64");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_THAT(resumed.output,
              ::testing::HasSubstr(run.string() + " stopped before its first checkpoint: "
                                                  "starting it afresh"));
  const json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary.at("env_steps"), 64);
  const trainer::ProgressTable progress = trainer::read_progress_csv(run / "progress.csv");
  EXPECT_EQ(progress.column("steps"), (std::vector<double>{32, 64}));
  EXPECT_FALSE(trainer::list_checkpoints(run).empty());
  fs::remove_all(folder);
}

// A run killed with SIGKILL and resumed is the run that was not: the same parameters,
// optimizer state, generator state and losses, update for update. The checkpoint carries the
// envs (as the actions that led to their state, replayed on resume), so the resumed run
// continues the episodes in progress (24-step episodes end inside the 16-step rollouts) and
// draws what the straight run draws. (Both runs have the same --steps: the learning rate anneals
// over it.)
TEST(TrainCliTest, AResumedRunIsTheRunThatDidNotStop) {
  const fs::path folder = fresh_folder("equivalent");
  const fs::path straight = folder / "straight";
  const fs::path split = folder / "split";
  // Every checkpoint kept: they are compared one by one below.
  const std::string settings = "--steps 320 --checkpoint-every 2 --keep-checkpoints 0 --out ";
  // With everything that carries state across updates: the random shifts' generator
  // (augmentation), the running statistics of the state keys (observation normalization, on by
  // default) and of the returns (reward normalization, on by default).
  const std::string config =
      R"({"num_steps": 16, "num_minibatches": 2, "update_epochs": 1, "augment": true})";
  const std::string obs_mode = "pixels+state";
  const CliRun trained =
      run_cli(train_arguments(folder, settings + straight.string(), config, obs_mode));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  ASSERT_TRUE(run_cli_until(folder,
                            train_arguments(folder, settings + split.string(), config, obs_mode),
                            split / "ckpt-000004.pgck"))
      << read_text(folder / "log.txt");
  const trainer::CheckpointSearch latest = trainer::find_latest_checkpoint(split);
  ASSERT_TRUE(latest.latest.has_value());
  const std::int64_t from = latest.latest->update;
  ASSERT_LT(from, 10) << "the run ended before it was killed";
  const CliRun resumed =
      run_cli("train --resume " + split.string() + " --steps 320 --quiet --checkpoint-every 2");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("replayed the " + std::to_string(from * 32) +
                                " env steps of the checkpoint"),
            std::string::npos)
      << resumed.output;

  for (std::int64_t update = 2; update <= 10; update += 2) {
    const std::string name = trainer::checkpoint_file_name(update);
    const trainer::CheckpointBlobs a = trainer::read_checkpoint(straight / name);
    const trainer::CheckpointBlobs b = trainer::read_checkpoint(split / name);
    // Not "optimizer": LibTorch keys the saved Adam state by each tensor's address, so its bytes
    // differ between processes. Its content is compared through the models: any difference in
    // it changes the parameters of the updates after the resume.
    for (const char* blob : {"model", "rng_sampling", "rng_augmentation", "env_actions"}) {
      ASSERT_EQ(a.count(blob), 1U) << name << " " << blob;
      EXPECT_TRUE(a.at(blob) == b.at(blob)) << name << ": \"" << blob << "\" differs";
    }
    // The model holds the observation statistics; the returns' statistics are in "meta" (beside
    // the wall time, which differs).
    const json meta_a = json::parse(a.at("meta"));
    const json meta_b = json::parse(b.at("meta"));
    EXPECT_EQ(meta_a.at("reward_scaling"), meta_b.at("reward_scaling")) << name;
    EXPECT_EQ(meta_a.at("recent_returns"), meta_b.at("recent_returns")) << name;
  }
  const trainer::ProgressTable a = trainer::read_progress_csv(straight / "progress.csv");
  const trainer::ProgressTable b = trainer::read_progress_csv(split / "progress.csv");
  for (const char* column :
       {"steps", "episode_return_mean", "policy_loss", "value_loss", "entropy", "approx_kl"}) {
    const std::vector<double> x = a.column(column);
    const std::vector<double> y = b.column(column);
    ASSERT_EQ(x.size(), 10U) << column;
    ASSERT_EQ(y.size(), 10U) << column;
    for (std::size_t row = 0; row < x.size(); ++row) {
      // Bit for bit (NaN, the mean before any episode ended, equals NaN here).
      EXPECT_TRUE(x[row] == y[row] || (std::isnan(x[row]) && std::isnan(y[row])))
          << column << ", row " << row << ": " << x[row] << " vs " << y[row];
    }
  }
  fs::remove_all(folder);
}

// --minutes bounds a run's whole wall time. A resume without it has what is left (here
// nothing: it says so and leaves the run as it is); --minutes M given to a resume adds M (and
// always allows one update), and later resumes keep that budget. Each resume is recorded in
// config.json with its budget.
TEST(TrainCliTest, AResumedRunKeepsItsTimeBudgetUnlessGivenMore) {
  const fs::path folder = fresh_folder("minutes");
  const fs::path run = folder / "run";
  const auto rows = [&] { return trainer::read_progress_csv(run / "progress.csv").rows.size(); };
  // 0.6 ms: the run stops by time within its one update, at the shortest rollout an update
  // takes (one step of the 2 envs: a transition for each of the 2 minibatches).
  const CliRun trained =
      run_cli(train_arguments(folder, "--steps 320 --minutes 0.00001 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  ASSERT_EQ(rows(), 1U);
  const std::string files_before = read_text(run / "ckpt-000001.pgck") +
                                   read_text(run / "summary.json") + read_text(run / "final.mp4") +
                                   read_text(run / "config.json");
  const CliRun spent = run_cli("train --resume " + run.string() + " --quiet");
  ASSERT_EQ(spent.exit_code, 0) << spent.output;
  EXPECT_NE(spent.output.find("nothing to do, the run has spent its time"), std::string::npos)
      << spent.output;
  EXPECT_NE(spent.output.find("give --minutes M to train M more"), std::string::npos)
      << spent.output;
  EXPECT_EQ(rows(), 1U);
  EXPECT_TRUE(read_text(run / "ckpt-000001.pgck") + read_text(run / "summary.json") +
                  read_text(run / "final.mp4") + read_text(run / "config.json") ==
              files_before)
      << "a resume with nothing to do changed the run";

  const CliRun more = run_cli("train --resume " + run.string() + " --quiet --minutes 0.00001");
  ASSERT_EQ(more.exit_code, 0) << more.output;
  EXPECT_EQ(rows(), 2U) << more.output;
  const json config = json::parse(read_text(run / "config.json"));
  ASSERT_EQ(config.at("resumes").size(), 1U);
  const json& resume = config.at("resumes")[0];
  EXPECT_EQ(resume.at("steps"), 2);
  EXPECT_EQ(resume.at("total_env_steps"), 320);
  EXPECT_EQ(resume.at("minutes_given"), 0.00001);
  EXPECT_GT(resume.at("minutes").get<double>(), 0.00001);  // the wall time so far + 0.00001
  EXPECT_EQ(more.output.find("warning: the replayed envs"), std::string::npos) << more.output;
  // That budget holds for the next resume: spent too.
  const CliRun again = run_cli("train --resume " + run.string() + " --quiet");
  EXPECT_EQ(again.exit_code, 0) << again.output;
  EXPECT_NE(again.output.find("nothing to do, the run has spent its time"), std::string::npos)
      << again.output;
  EXPECT_EQ(rows(), 2U);
  // A run stopped between its last checkpoint and its evaluation (no summary of it) goes on to
  // evaluate, and trains no more.
  fs::remove(run / "summary.json");
  fs::remove(run / "final.mp4");
  const CliRun unfinished = run_cli("train --resume " + run.string() + " --quiet");
  ASSERT_EQ(unfinished.exit_code, 0) << unfinished.output;
  EXPECT_EQ(rows(), 2U);
  const json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary.at("env_steps"), 4);
  // The budget holds no recorded episode: no video, and summary.json says why.
  EXPECT_FALSE(fs::exists(run / "final.mp4"));
  EXPECT_TRUE(summary.at("video").is_null());
  EXPECT_THAT(summary.at("time_budget").at("final_evaluation").get<std::string>(),
              ::testing::HasSubstr("no final.mp4"));
  EXPECT_EQ(summary.at("evaluation").at("episodes"), 1);
  // Budgets that cannot be: --steps no more than done, negative minutes.
  const CliRun fewer = run_cli("train --resume " + run.string() + " --quiet --steps 4");
  EXPECT_EQ(fewer.exit_code, 2) << fewer.output;
  EXPECT_NE(fewer.output.find("the run has 4 env steps done; give more to train on"),
            std::string::npos)
      << fewer.output;
  const CliRun negative = run_cli("train --resume " + run.string() + " --quiet --minutes -1");
  EXPECT_EQ(negative.exit_code, 2) << negative.output;
  EXPECT_EQ(rows(), 2U);

  // A checkpoint whose envs the replay does not reproduce (here: its digest altered, as after
  // a change of code or library) resumes with a warning saying so.
  const trainer::CheckpointSearch latest = trainer::find_latest_checkpoint(run);
  ASSERT_TRUE(latest.latest.has_value());
  trainer::CheckpointBlobs blobs = latest.latest->blobs;
  json meta = json::parse(blobs.at("meta"));
  meta["env_digest"] = meta.at("env_digest").get<std::uint64_t>() + 1;
  blobs["meta"] = meta.dump();
  trainer::write_checkpoint(latest.latest->path, blobs);
  const CliRun changed = run_cli("train --resume " + run.string() + " --quiet --minutes 0.00001");
  ASSERT_EQ(changed.exit_code, 0) << changed.output;
  EXPECT_NE(changed.output.find("warning: the replayed envs are not where the checkpoint's were"),
            std::string::npos)
      << changed.output;
  EXPECT_EQ(rows(), 3U);
  fs::remove_all(folder);
}

TEST(TrainCliTest, TruncatedAndCorruptCheckpointsAreRefused) {
  const fs::path folder = fresh_folder("corrupt");
  const fs::path run = folder / "run";
  const CliRun trained =
      run_cli(train_arguments(folder, "--steps 64 --checkpoint-every 1 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  const fs::path second = run / "ckpt-000002.pgck";
  const std::string bytes = read_text(second);

  // Truncated: eval of the file refuses it; of the folder, skips it for the one before.
  fs::resize_file(second, bytes.size() / 2);
  CliRun evaluated = run_cli("eval " + second.string() + " --episodes 1");
  EXPECT_EQ(evaluated.exit_code, 1) << evaluated.output;
  EXPECT_NE(evaluated.output.find("truncated"), std::string::npos) << evaluated.output;
  EXPECT_NE(evaluated.output.find("refusing to load it"), std::string::npos) << evaluated.output;
  evaluated = run_cli("eval " + run.string() + " --episodes 1");
  EXPECT_EQ(evaluated.exit_code, 0) << evaluated.output;
  EXPECT_NE(evaluated.output.find("skipping " + second.string()), std::string::npos)
      << evaluated.output;
  EXPECT_NE(evaluated.output.find("ckpt-000001.pgck: CartPoleBalance-v0"), std::string::npos)
      << evaluated.output;

  // Corrupt (one byte flipped in the middle, size intact): refused as well.
  std::string flipped = bytes;
  flipped[flipped.size() / 2] = static_cast<char>(flipped[flipped.size() / 2] ^ 0x10);
  std::ofstream(second, std::ios::binary | std::ios::trunc) << flipped;
  evaluated = run_cli("eval " + second.string() + " --episodes 1");
  EXPECT_EQ(evaluated.exit_code, 1) << evaluated.output;
  EXPECT_NE(evaluated.output.find("checksum"), std::string::npos) << evaluated.output;
  // --resume takes the valid one before it.
  const CliRun resumed = run_cli("train --resume " + run.string() + " --steps 96 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("skipping " + second.string()), std::string::npos)
      << resumed.output;
  EXPECT_NE(resumed.output.find("from ckpt-000001.pgck"), std::string::npos) << resumed.output;
  fs::remove_all(folder);
}

// A config.json edited after the run started is refused on resume, naming each setting that
// differs from the checkpoint's (it was recorded while the checkpoint's network went on), and a
// corrupt one is named as not valid JSON (it was "no member names an algorithm").
TEST(TrainCliTest, AResumeRefusesAConfigEditedAfterTheRunStarted) {
  const fs::path folder = fresh_folder("edited");
  const fs::path run = folder / "run";
  const CliRun trained = run_cli(train_arguments(folder, "--steps 32 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  const std::string original = read_text(run / "config.json");
  const auto resume = [&] {
    return run_cli("train --resume " + run.string() + " --steps 64 --quiet");
  };
  json edited = json::parse(original);
  edited["ppo"]["policy"]["trunk_hidden"] = 128;
  edited["ppo"]["num_minibatches"] = 4;
  edited["env_id"] = "CartPoleSwingup-v0";
  std::ofstream(run / "config.json", std::ios::trunc) << edited.dump(2);
  CliRun refused = resume();
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  for (const char* named :
       {"config.json differs from the settings ckpt-000001.pgck was trained with",
        "env_id: config.json has \"CartPoleSwingup-v0\", the checkpoint \"CartPoleBalance-v0\"",
        "ppo.num_minibatches: config.json has 4, the checkpoint 2", "ppo.policy: config.json has",
        "\"trunk_hidden\":128"}) {
    EXPECT_NE(refused.output.find(named), std::string::npos) << named << "\n" << refused.output;
  }
  EXPECT_EQ(trainer::read_progress_csv(run / "progress.csv").rows.size(), 1U);

  std::ofstream(run / "config.json", std::ios::trunc) << original.substr(0, original.size() / 2);
  refused = resume();
  EXPECT_EQ(refused.exit_code, 1) << refused.output;
  EXPECT_NE(refused.output.find((run / "config.json").string() + ": not valid JSON"),
            std::string::npos)
      << refused.output;
  EXPECT_EQ(refused.output.find("no member names an algorithm"), std::string::npos)
      << refused.output;
  std::ofstream(run / "config.json", std::ios::trunc) << "[1, 2]";
  refused = resume();
  EXPECT_NE(refused.output.find("the file holds array, not an object"), std::string::npos)
      << refused.output;

  // Restored, it resumes.
  std::ofstream(run / "config.json", std::ios::trunc) << original;
  const CliRun resumed = resume();
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_EQ(trainer::read_progress_csv(run / "progress.csv").rows.size(), 2U);
  fs::remove_all(folder);
}

// Settings no machine can hold are refused before anything is allocated, naming the member, the
// estimate and the memory available (they allocated until the machine ran out, or ended in an
// allocator's trace); integer members are integers (2.9 was truncated, 1e30 undefined, -1 wrapped
// to 2^64 - 1, as was --seed -1).
TEST(TrainCliTest, SettingsTooLargeOrNotIntegersAreRefusedByName) {
  const fs::path folder = fresh_folder("hostile");
  const auto train = [&](const std::string& algo, const std::string& config) {
    std::ofstream(folder / "config.json", std::ios::trunc) << config;
    return run_cli("train CartPoleBalance-v1 --algo " + algo +
                   " --set obs_mode=pixels --set width=64 --set height=64 --wrap grayscale "
                   "--wrap frame_stack=3 --num-envs 1 --threads 1 --quiet --config " +
                   (folder / "config.json").string() + " --out " + (folder / "run").string());
  };
  const auto refused = [&](const CliRun& run, const std::vector<std::string>& named) {
    EXPECT_NE(run.exit_code, 0) << run.output;
    EXPECT_NE(run.exit_code, -1) << "a crash\n" << run.output;
    for (const std::string& text : named) {
      EXPECT_NE(run.output.find(text), std::string::npos) << text << "\n" << run.output;
    }
    EXPECT_FALSE(fs::exists(folder / "run")) << "a refused run left its folder";
  };
  const std::vector<std::string> memory = {"of memory, but ", " is available (", "Lower "};
  const auto with = [](std::vector<std::string> texts, const std::string& more) {
    texts.push_back(more);
    return texts;
  };
  refused(train("drqv2", R"({"batch_size": 1e9})"),
          with(memory, "the most is batch_size 1000000000: about"));
  refused(train("drqv2", R"({"hidden_dim": 1000000000})"),
          with(memory, "the most is hidden_dim 1000000000: about"));
  refused(train("drqv2", R"({"replay_capacity": 1e12})"),
          with(memory, "the most is replay_capacity 1000000000000: about"));
  refused(train("ppo", R"({"num_steps": 1000000000, "num_minibatches": 1})"),
          with(memory, "the most is num_steps 1000000000: about"));
  refused(train("drqv2", R"({"batch_size": 2.9})"),
          {"member \"batch_size\" must be an integer from", "got 2.9"});
  refused(train("drqv2", R"({"hidden_dim": 1e30})"),
          {"member \"hidden_dim\" must be an integer from", "got 1e+30"});
  refused(train("ppo", R"({"num_steps": 1.5})"), {"member \"num_steps\" must be an integer"});
  refused(train("ppo", R"({"seed": -1})"),
          {"member \"seed\" must be an integer from 0 to 18446744073709551615, got -1"});
  const CliRun seed =
      run_cli("train CartPoleBalance-v1 --seed -1 --out " + (folder / "run").string());
  EXPECT_EQ(seed.exit_code, 2) << seed.output;
  EXPECT_NE(seed.output.find("must be an integer from 0 to 18446744073709551615, got \"-1\""),
            std::string::npos)
      << seed.output;
  EXPECT_FALSE(fs::exists(folder / "run" / "config.json"));
  fs::remove_all(folder);
}

// A random-shift pad wider than the image (65 at 64x64) trains: it wrote out of bounds (SIGSEGV
// or "malloc(): corrupted top size").
TEST(TrainCliTest, DrqV2TrainsWithAShiftPadWiderThanTheImage) {
  const fs::path folder = fresh_folder("shift_pad");
  std::ofstream(folder / "config.json")
      << R"({"total_env_steps": 300, "iteration_env_steps": 100, "seed_env_steps": 100,
             "batch_size": 32, "shift_pad": 65})";
  const CliRun run = run_cli(
      "train CartPoleBalance-v1 --algo drqv2 --set obs_mode=pixels --set width=64 "
      "--set height=64 --wrap grayscale --wrap frame_stack=3 --num-envs 1 --threads 1 "
      "--eval-episodes 1 --set max_episode_steps=100 --quiet --config " +
      (folder / "config.json").string() + " --out " + (folder / "run").string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const trainer::ProgressTable progress = trainer::read_progress_csv(folder / "run/progress.csv");
  ASSERT_EQ(progress.rows.size(), 3U);
  EXPECT_TRUE(std::isfinite(progress.column("critic_loss").back()));
  fs::remove_all(folder);
}

// `train --list-settings` names every setting that --print-config shows for each algorithm, with
// the default a run would use, its range and a line of help; with --algo, that algorithm's alone.
TEST(TrainCliTest, ListSettingsShowsEverySettingOfEachAlgorithmWithItsDefault) {
  const CliRun listed = run_cli("train --list-settings");
  ASSERT_EQ(listed.exit_code, 0) << listed.output;
  for (const std::string algorithm : {"ppo", "drq", "drqv2"}) {
    const CliRun printed =
        run_cli("train CartPoleBalance-v1 --algo " + algorithm + " --print-config");
    ASSERT_EQ(printed.exit_code, 0) << printed.output;
    const json config = json::parse(printed.output).at(algorithm);
    const std::size_t section = listed.output.find(algorithm + " (--algo " + algorithm + ")");
    ASSERT_NE(section, std::string::npos) << listed.output;
    const std::size_t next = listed.output.find("\n" + std::string(1, '\n'), section);
    const std::string text = listed.output.substr(section, next - section);
    // Each setting, members of an object member as "policy.cnn".
    std::vector<std::pair<std::string, json>> settings;
    for (const auto& item : config.items()) {
      if (item.value().is_object()) {
        for (const auto& inner : item.value().items()) {
          settings.emplace_back(item.key() + "." + inner.key(), inner.value());
        }
      } else {
        settings.emplace_back(item.key(), item.value());
      }
    }
    ASSERT_GT(settings.size(), 15U) << algorithm;
    for (const auto& [name, value] : settings) {
      const std::string line = "\n  " + name + " = " + value.dump() + "  (";
      const std::size_t at = text.find(line);
      ASSERT_NE(at, std::string::npos) << algorithm << ": no line " << line << " in\n" << text;
      // The next line is its help, indented.
      const std::size_t help = text.find('\n', at + 1);
      EXPECT_EQ(text.compare(help, 7, "\n      "), 0)
          << algorithm << ": " << name << " has no help";
      EXPECT_GT(text.find('\n', help + 1) - help, 20U) << algorithm << ": " << name;
    }
  }
  const CliRun drq_only = run_cli("train --list-settings --algo drq");
  ASSERT_EQ(drq_only.exit_code, 0) << drq_only.output;
  EXPECT_NE(drq_only.output.find("init_temperature = 0.1"), std::string::npos) << drq_only.output;
  EXPECT_EQ(drq_only.output.find("noise_clip"), std::string::npos) << drq_only.output;
}

// The off-policy learner through the same run machinery: a run folder with its own columns and
// eval.csv, `eval` reading its checkpoint, a resume that refills the replay buffer from the
// env actions and continues as the run that did not stop, and its refusals.
TEST(TrainCliTest, DrqV2WritesARunThatEvalReadsAndResumesAsIfItHadNotStopped) {
  const fs::path folder = fresh_folder("drqv2");
  const std::string config =
      R"({"seed_env_steps": 24, "iteration_env_steps": 16, "batch_size": 8, "hidden_dim": 16,
          "feature_dim": 8, "replay_capacity": 400, "n_step": 2})";
  std::ofstream(folder / "drqv2.json") << config;
  const auto arguments = [&](const fs::path& run, std::int64_t steps) {
    // 96 env steps of 4 control steps each: 384 control steps.
    return "train CartPoleBalance-v1 --algo drqv2 --set obs_mode=pixels+state --set width=32 "
           "--set height=32 --set action_repeat=4 --set max_episode_steps=24 --wrap grayscale "
           "--wrap frame_stack=3 "
           "--threads 1 --config " +
           (folder / "drqv2.json").string() + " --steps " + std::to_string(steps) +
           " --checkpoint-every 2 --keep-checkpoints 0 --eval-every 32 --eval-every-episodes 1 "
           "--eval-max-share 1 "
           "--eval-episodes 1 --quiet --out " +
           run.string();
  };
  const fs::path straight = folder / "straight";
  const CliRun trained = run_cli(arguments(straight, 96));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  for (const char* file : {"config.json", "progress.csv", "eval.csv", "curve.png", "final.mp4",
                           "summary.json", "ckpt-000006.pgck"}) {
    EXPECT_TRUE(fs::exists(straight / file)) << file;
  }
  const json run_config = json::parse(read_text(straight / "config.json"));
  EXPECT_EQ(run_config.at("drqv2").at("batch_size"), 8);
  EXPECT_EQ(run_config.at("eval_every"), 32);
  const trainer::ProgressTable progress = trainer::read_progress_csv(straight / "progress.csv");
  ASSERT_EQ(progress.rows.size(), 6U);
  const std::vector<double> critic = progress.column("critic_loss");
  EXPECT_TRUE(std::isnan(critic[0])) << "an update during the seed steps";
  EXPECT_TRUE(std::isfinite(critic[5]));
  EXPECT_GT(progress.column("gradient_updates").back(), 0.0);
  const std::string evals = read_text(straight / "eval.csv");
  EXPECT_EQ(evals.rfind("steps,wall_time_s,return_mean,return_std,episodes,eval_s\n32,", 0), 0U)
      << evals;

  const CliRun evaluated = run_cli("eval " + straight.string() + " --episodes 1");
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  EXPECT_NE(evaluated.output.find("return_mean="), std::string::npos) << evaluated.output;

  // Stopped after 32 steps, resumed to 96: the same checkpoints as the straight run.
  const fs::path split = folder / "split";
  const CliRun first = run_cli(arguments(split, 32));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const CliRun resumed = run_cli("train --resume " + split.string() + " --steps 96 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("replayed the 32 env steps"), std::string::npos) << resumed.output;
  for (std::int64_t update = 4; update <= 6; update += 2) {
    const std::string name = trainer::checkpoint_file_name(update);
    const trainer::CheckpointBlobs a = trainer::read_checkpoint(straight / name);
    const trainer::CheckpointBlobs b = trainer::read_checkpoint(split / name);
    for (const char* blob :
         {"agent", "rng_augmentation", "rng_exploration", "rng_noise", "env_actions"}) {
      ASSERT_EQ(a.count(blob), 1U) << name << " " << blob;
      EXPECT_TRUE(a.at(blob) == b.at(blob)) << name << ": \"" << blob << "\" differs";
    }
    EXPECT_EQ(json::parse(a.at("meta")).at("drqv2"), json::parse(b.at("meta")).at("drqv2"));
  }
  // The evaluations during training: at the same steps, with the same returns.
  const auto evaluations = [](const fs::path& run) {
    std::vector<std::pair<std::int64_t, double>> rows;
    for (const trainer::EvalRow& row :
         trainer::parse_eval_csv(read_text(run / "eval.csv"), (run / "eval.csv").string())) {
      rows.emplace_back(row.steps, row.return_mean);
    }
    return rows;
  };
  EXPECT_EQ(evaluations(straight), evaluations(split));
  EXPECT_EQ(evaluations(split).size(), 3U);

  // compare draws both runs' evaluations (control steps: env steps x action_repeat 4).
  const CliRun compared = run_cli("compare " + straight.string() + "=straight " + split.string() +
                                  " --out " + (folder / "compare.png").string());
  ASSERT_EQ(compared.exit_code, 0) << compared.output;
  EXPECT_TRUE(fs::exists(folder / "compare.png"));
  EXPECT_NE(compared.output.find("\nstraight,384,"), std::string::npos) << compared.output;
  EXPECT_NE(compared.output.find("\nsplit,384,"), std::string::npos) << compared.output;
  const CliRun no_evals =
      run_cli("compare " + folder.string() + " --out " + (folder / "none.png").string());
  EXPECT_NE(no_evals.exit_code, 0);
  EXPECT_FALSE(fs::exists(folder / "none.png"));

  // Refusals: a Discrete action space (naming the env and the space), a bad config member.
  const CliRun discrete = run_cli(
      "train CartPoleBalanceDiscrete-v0 --algo drqv2 --set obs_mode=state --quiet --steps 16 "
      "--out " +
      (folder / "discrete").string());
  EXPECT_NE(discrete.exit_code, 0);
  EXPECT_NE(discrete.output.find("CartPoleBalanceDiscrete-v0"), std::string::npos)
      << discrete.output;
  EXPECT_NE(discrete.output.find("Discrete(3)"), std::string::npos) << discrete.output;
  std::ofstream(folder / "bad.json") << R"({"batch_size": 0})";
  const CliRun bad =
      run_cli("train CartPoleBalance-v1 --algo drqv2 --config " + (folder / "bad.json").string() +
              " --quiet --out " + (folder / "bad").string());
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("batch_size"), std::string::npos) << bad.output;
  fs::remove_all(folder);
}

// DrQ (SAC) on the same machinery: a resumed run restores the update counter that spaces the
// actor's and the target's updates, the temperature's optimizer and the sampling generator, and
// continues as the run that did not stop.
TEST(TrainCliTest, DrqResumesAsIfItHadNotStopped) {
  const fs::path folder = fresh_folder("drq");
  std::ofstream(folder / "drq.json")
      << R"({"seed_env_steps": 24, "iteration_env_steps": 16, "batch_size": 8, "hidden_dim": 16,
             "feature_dim": 8, "replay_capacity": 400, "actor_update_every": 7})";
  const auto arguments = [&](const fs::path& run, std::int64_t steps) {
    return "train CartPoleBalance-v1 --algo drq --set obs_mode=pixels+state --set width=32 "
           "--set height=32 --set action_repeat=4 --set max_episode_steps=24 --wrap grayscale "
           "--wrap frame_stack=3 --threads 1 --config " +
           (folder / "drq.json").string() + " --steps " + std::to_string(steps) +
           " --checkpoint-every 2 --keep-checkpoints 0 --eval-every 32 --eval-every-episodes 1 "
           "--eval-max-share 1 --eval-episodes 1 --quiet --out " +
           run.string();
  };
  const fs::path straight = folder / "straight";
  const CliRun trained = run_cli(arguments(straight, 96));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  const trainer::ProgressTable progress = trainer::read_progress_csv(straight / "progress.csv");
  ASSERT_EQ(progress.rows.size(), 6U);
  EXPECT_TRUE(std::isfinite(progress.column("alpha").back()));
  EXPECT_TRUE(std::isfinite(progress.column("policy_entropy").back()));
  const CliRun evaluated = run_cli("eval " + straight.string() + " --episodes 1");
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;

  // Stopped after 48 steps (about 25 updates: not a multiple of actor_update_every), resumed.
  const fs::path split = folder / "split";
  const CliRun first = run_cli(arguments(split, 48));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const CliRun resumed = run_cli("train --resume " + split.string() + " --steps 96 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  for (std::int64_t update = 4; update <= 6; update += 2) {
    const std::string name = trainer::checkpoint_file_name(update);
    const trainer::CheckpointBlobs a = trainer::read_checkpoint(straight / name);
    const trainer::CheckpointBlobs b = trainer::read_checkpoint(split / name);
    // The optimizers' blobs are not compared: LibTorch keys their state by the parameters'
    // addresses, which differ between processes. The agent (log_alpha included) is the result.
    ASSERT_EQ(a.count("alpha_optimizer"), 1U) << name;
    for (const char* blob :
         {"agent", "rng_augmentation", "rng_exploration", "rng_sampling", "env_actions"}) {
      ASSERT_EQ(a.count(blob), 1U) << name << " " << blob;
      EXPECT_TRUE(a.at(blob) == b.at(blob)) << name << ": \"" << blob << "\" differs";
    }
    EXPECT_EQ(json::parse(a.at("meta")).at("drq"), json::parse(b.at("meta")).at("drq"));
  }
}

// `pixelgym export` writes a drq policy trained from state as a policy file, and MlpPolicy runs it
// as the run's policy: the same returns as `pixelgym eval` (deterministic actions) episode by
// episode. A policy that reads pixels, a PPO run and a missing run are refused by name, and no
// file is written for them.
TEST(TrainCliTest, ExportWritesAPolicyFileThatActsAsTheRunsPolicy) {
  const fs::path folder = fresh_folder("export");
  const fs::path run = folder / "state";
  std::ofstream(folder / "drq.json") << R"({"seed_env_steps": 24, "iteration_env_steps": 16,
      "batch_size": 8, "hidden_dim": 16, "replay_capacity": 400})";
  const CliRun trained = run_cli(
      "train CartPoleSwingup-v1 --algo drq --set obs_mode=state --set action_repeat=2 "
      "--set max_episode_steps=40 --threads 1 --config " +
      (folder / "drq.json").string() + " --steps 160 --eval-episodes 1 --quiet --out " +
      run.string());
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  const fs::path file = folder / "swingup.policy.json";
  const CliRun exported = run_cli("export " + run.string() + " --out " + file.string());
  ASSERT_EQ(exported.exit_code, 0) << exported.output;
  EXPECT_NE(exported.output.find("wrote " + file.string() + " (CartPoleSwingup-v1, 3 layers"),
            std::string::npos)
      << exported.output;
  const MlpPolicy policy = MlpPolicy::load(file.string());
  EXPECT_EQ(policy.env_id(), "CartPoleSwingup-v1");
  EXPECT_EQ(policy.action_size(), 1);
  const CliRun evaluated = run_cli("eval " + run.string() + " --episodes 3 --seed 7");
  ASSERT_EQ(evaluated.exit_code, 0) << evaluated.output;
  std::unique_ptr<Env> env = make(policy.env_id(), policy.env_kwargs());
  // eval prints 6 significant digits; torch sums in float32 and MlpPolicy in double, so the
  // actions agree to about 1e-7.
  const auto tolerance = [](double expected) { return 1e-5 + 2e-5 * std::abs(expected); };
  bool other_policy_differs = false;  // the comparison can tell policies apart
  for (int e = 0; e < 3; ++e) {
    const std::string line = "episode " + std::to_string(e) + ": return=";
    const std::size_t at = evaluated.output.find(line);
    ASSERT_NE(at, std::string::npos) << evaluated.output;
    const double expected = std::stod(evaluated.output.substr(at + line.size()));
    const std::uint64_t seed = 7 + static_cast<std::uint64_t>(e);
    const double got =
        episode_return(*env, seed, [&](const Value& obs) { return Value(policy.act(obs)); });
    EXPECT_NEAR(got, expected, tolerance(expected)) << "episode " << e;
    const double still = episode_return(
        *env, seed, [](const Value&) { return Value(Array::from_vector<float>({1}, {0.0F})); });
    other_policy_differs = other_policy_differs || std::abs(still - expected) > tolerance(expected);
  }
  EXPECT_TRUE(other_policy_differs);

  const auto refused = [&](const std::string& source, const std::string& expected) {
    const fs::path out = folder / "refused.json";
    const CliRun result = run_cli("export " + source + " --out " + out.string());
    EXPECT_NE(result.exit_code, 0) << source;
    EXPECT_NE(result.output.find(expected), std::string::npos) << result.output;
    EXPECT_FALSE(fs::exists(out)) << source;
  };
  // A 32-step drq run on CartPoleSwingup-v1 with `settings` (kwargs and wrappers).
  const auto tiny_drq_run = [&](const std::string& name, const std::string& settings) {
    const fs::path out = folder / name;
    EXPECT_EQ(run_cli("train CartPoleSwingup-v1 --algo drq --set max_episode_steps=24 " + settings +
                      " --threads 1 --config " + (folder / "drq.json").string() +
                      " --steps 32 --eval-episodes 1 --quiet --out " + out.string())
                  .exit_code,
              0)
        << name;
    return out.string();
  };
  refused(tiny_drq_run("pixels",
                       "--set obs_mode=pixels --set width=32 --set height=32 "
                       "--wrap frame_stack=3"),
          "(drq on CartPoleSwingup-v1): expected a policy that reads vectors "
          "only, got one that reads the image \"pixels\"");
  const fs::path ppo = folder / "ppo";
  ASSERT_EQ(run_cli(train_arguments(folder, "--steps 32 --out " + ppo.string())).exit_code, 0);
  refused(ppo.string(),
          "(ppo on CartPoleBalance-v0): expected a policy that is an MLP over "
          "vector observations");
  refused(
      tiny_drq_run("wrapped", "--set obs_mode=state --wrap normalize_observation=key=joint_vel"),
      "expected a run on the bare env (a policy file names the env by its "
      "id and kwargs), got one wrapped in --wrap normalize_observation");
  refused((folder / "nothing").string(),
          "export: " + (folder / "nothing").string() + " does not exist");
  fs::remove_all(folder);
}

// --config takes a recipe's name, a file or inline JSON, and --set-algo one setting over it, each
// refused as a config file is (did you mean, expected vs given); --print-config shows the result
// and trains nothing; --list-configs shows the recipes.
TEST(TrainCliTest, RecipesByNameInlineJsonAndSetAlgo) {
  const fs::path folder = fresh_folder("recipes");
  const std::string out = " --out " + (folder / "run").string();
  const auto printed = [&](const std::string& arguments) {
    const CliRun result =
        run_cli("train CartPoleSwingup-v0 " + arguments + " --print-config" + out);
    EXPECT_EQ(result.exit_code, 0) << arguments << ": " << result.output;
    return json::parse(result.output, nullptr, false);
  };
  const json swingup = printed("--config swingup");
  ASSERT_FALSE(swingup.is_discarded());
  EXPECT_EQ(swingup.at("env_id"), "CartPoleSwingup-v0");
  EXPECT_EQ(swingup.at("ppo").at("gamma"), 0.95);
  EXPECT_EQ(swingup.at("ppo").at("num_envs"), 16);
  const json set = printed(
      "--config '{\"gamma\": 0.9, \"num_steps\": 32}' --set-algo num_steps=64 --set-algo "
      "policy.cnn=fine --num-envs 4");
  ASSERT_FALSE(set.is_discarded());
  EXPECT_EQ(set.at("ppo").at("gamma"), 0.9);
  EXPECT_EQ(set.at("ppo").at("num_steps"), 64);
  EXPECT_EQ(set.at("ppo").at("policy").at("cnn"), "fine");
  EXPECT_EQ(set.at("ppo").at("num_envs"), 4);  // the flag over the config
  const json drqv2 = printed("--algo drqv2 --config cartpole --set-algo encoder=fine");
  ASSERT_FALSE(drqv2.is_discarded());
  EXPECT_EQ(drqv2.at("drqv2").at("total_env_steps"), 12500);
  EXPECT_EQ(drqv2.at("drqv2").at("encoder"), "fine");
  EXPECT_FALSE(fs::exists(folder / "run")) << "--print-config wrote the run";

  const auto refused = [&](const std::string& arguments, const std::string& message) {
    const CliRun result = run_cli("train CartPoleSwingup-v0 " + arguments + out);
    EXPECT_EQ(result.exit_code, 2) << arguments << ": " << result.output;
    EXPECT_NE(result.output.find(message), std::string::npos) << arguments << ": " << result.output;
    EXPECT_NE(result.output.find("\nRun 'pixelgym train --help' for the options.\n"),
              std::string::npos)
        << result.output;
  };
  refused("--config swingupp", "ppo has no recipe named \"swingupp\"; did you mean swingup?");
  refused("--config cartpole", "(drqv2 has one: add --algo drqv2)");
  refused("--set-algo gama=0.9",
          "--set-algo gama=0.9: PpoConfig JSON: unknown member \"gama\"; did you mean gamma?");
  refused("--set-algo gamma=abc",
          "--set-algo gamma=abc: PpoConfig JSON: member \"gamma\" has the wrong type: expected a "
          "number, got string \"abc\"");
  refused("--set-algo policy.cnn=big", "--set-algo policy.cnn=big: ");
  refused("--config '{\"gama\": 0.9}'", "unknown member \"gama\"; did you mean gamma?");
  refused("--set-algo gamma", "--set-algo expects KEY=VALUE (e.g. gamma=0.95), got \"gamma\"");
  EXPECT_FALSE(fs::exists(folder / "run"));

  const CliRun listed = run_cli("train --list-configs");
  EXPECT_EQ(listed.exit_code, 0) << listed.output;
  EXPECT_NE(listed.output.find("ppo (--algo ppo), " PIXELGYM_SOURCE_DIR
                               "/examples/trainer/ppo/configs:\n"),
            std::string::npos)
      << listed.output;
  EXPECT_NE(listed.output.find("\n  swingup          {\"gamma\":0.95,"), std::string::npos)
      << listed.output;
  EXPECT_NE(listed.output.find("drqv2 (--algo drqv2)"), std::string::npos) << listed.output;
  EXPECT_NE(listed.output.find("\n  cartpole  {"), std::string::npos) << listed.output;
  const CliRun ppo_only = run_cli("train --list-configs --algo ppo");
  EXPECT_EQ(ppo_only.output.find("drqv2 (--algo drqv2)"), std::string::npos) << ppo_only.output;
  fs::remove_all(folder);
}

// Every recipe shipped with each algorithm is a valid config of it: --print-config shows the
// recipe's values in the settings a run would use.
TEST(TrainCliTest, EveryRecipeIsAValidConfigOfItsAlgorithm) {
  std::size_t recipes = 0;
  for (const std::string algorithm : {"ppo", "drq", "drqv2"}) {
    for (const std::string& name : pixelgym::trainer::recipe_names(algorithm)) {
      ++recipes;
      const CliRun printed = run_cli("train CartPoleBalance-v1 --algo " + algorithm + " --config " +
                                     name + " --print-config");
      ASSERT_EQ(printed.exit_code, 0) << algorithm << " " << name << ": " << printed.output;
      std::ifstream file(pixelgym::trainer::recipe_folder(algorithm) / (name + ".json"));
      const json recipe = json::parse(file);
      const json config = json::parse(printed.output).at(algorithm);
      for (const auto& item : recipe.items()) {
        if (!item.value().is_object()) {
          EXPECT_EQ(config.at(item.key()), item.value()) << algorithm << " " << name;
          continue;
        }
        for (const auto& inner : item.value().items()) {  // an object member's members
          EXPECT_EQ(config.at(item.key()).at(inner.key()), inner.value())
              << algorithm << " " << name << " " << item.key();
        }
      }
    }
  }
  EXPECT_GE(recipes, 8U);
}

// A run's output as a reader of a pipe sees it: each line with the seconds since the start when
// it arrived, and the run's exit code and wall time.
struct PipedRun {
  int exit_code = -1;
  double wall_s = 0.0;
  std::vector<std::pair<double, std::string>> lines;
  std::string output() const {
    std::string text;
    for (const auto& line : lines) text += line.second;
    return text;
  }
  // The longest wait between two lines, from the first line to the end.
  double longest_silence_s() const {
    double longest = 0.0;
    for (std::size_t i = 1; i < lines.size(); ++i) {
      longest = std::max(longest, lines[i].first - lines[i - 1].first);
    }
    if (!lines.empty()) longest = std::max(longest, wall_s - lines.back().first);
    return longest;
  }
};

// Runs `pixelgym ARGUMENTS` with stdout and stderr into a pipe read line by line; kills it
// after `kill_after_s` (a run that ignores its budget fails instead of hanging the test).
PipedRun run_piped(const std::string& arguments, double kill_after_s) {
  PipedRun run;
  const auto start = std::chrono::steady_clock::now();
  const auto since = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  };
  int fds[2];
  if (::pipe(fds) != 0) return run;
  const std::string command = std::string("exec ") + PIXELGYM_CLI + " " + arguments + " 2>&1";
  const pid_t child = fork();
  if (child == 0) {
    ::dup2(fds[1], STDOUT_FILENO);
    ::close(fds[0]);
    ::close(fds[1]);
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  ::close(fds[1]);
  std::string line;
  std::array<char, 4096> buffer{};
  for (;;) {
    pollfd ready{fds[0], POLLIN, 0};
    const int waited = ::poll(&ready, 1, 200);
    if (since() > kill_after_s) {
      ::kill(child, SIGKILL);
      run.lines.emplace_back(since(),
                             "(killed by the test after " + std::to_string(kill_after_s) + " s)\n");
      break;
    }
    if (waited <= 0) continue;
    const ssize_t got = ::read(fds[0], buffer.data(), buffer.size());
    if (got <= 0) break;
    // Each whole line with the time it arrived.
    for (ssize_t i = 0; i < got; ++i) {
      line += buffer[static_cast<std::size_t>(i)];
      if (buffer[static_cast<std::size_t>(i)] == '\n') {
        run.lines.emplace_back(since(), line);
        line.clear();
      }
    }
  }
  if (!line.empty()) run.lines.emplace_back(since(), line);
  ::close(fds[0]);
  int status = 0;
  ::waitpid(child, &status, 0);
  run.wall_s = since();
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return run;
}

// --minutes bounds the whole run's wall time, the final evaluation included, within 10 % or
// 30 s (whichever is larger), however long an iteration is: the budget is checked within
// iterations (here one iteration would take minutes), and time is kept for the final
// evaluation. The cut iteration is checkpointed and a resume goes on from it. A pipe gets a line
// at least every 10 s throughout.
TEST(TrainCliTest, MinutesBoundTheWholeRunAndLinesReachAPipeEvery10Seconds) {
  const fs::path folder = fresh_folder("budget");
  constexpr double kMinutes = 0.25;
  const double bound_s = kMinutes * 60.0 + std::max(0.1 * kMinutes * 60.0, 30.0);
  const std::string cheap =
      " --set obs_mode=pixels --set width=32 --set height=32 --set max_episode_steps=50 "
      "--wrap frame_stack=2 --threads 1 --eval-episodes 3 --quiet --minutes 0.25 ";
  // PPO: a rollout of 2 x 4096 steps and 10 epochs of 8 minibatches over it.
  std::ofstream(folder / "ppo.json")
      << R"({"num_steps": 4096, "num_envs": 2, "num_minibatches": 8, "update_epochs": 10})";
  // DrQ-v2: one iteration of 5000 env steps, an update after each.
  std::ofstream(folder / "drqv2.json")
      << R"({"iteration_env_steps": 5000, "seed_env_steps": 100, "batch_size": 64,
             "frame_stack": 2})";
  for (const std::string algo : {"ppo", "drqv2"}) {
    SCOPED_TRACE(algo);
    const fs::path run = folder / algo;
    const PipedRun trained =
        run_piped("train CartPoleBalance-v1 --algo " + algo + cheap + "--config " +
                      (folder / (algo + ".json")).string() + " --out " + run.string(),
                  bound_s + 30.0);
    ASSERT_EQ(trained.exit_code, 0) << trained.output();
    std::cout << algo << ": --minutes " << kMinutes << " ran " << trained.wall_s << " s (bound "
              << bound_s << " s), longest silence on the pipe " << trained.longest_silence_s()
              << " s\n";
    EXPECT_LE(trained.wall_s, bound_s) << trained.output();
    EXPECT_LE(trained.longest_silence_s(), 10.0) << trained.output();
    const json summary = json::parse(read_text(run / "summary.json"));
    EXPECT_EQ(summary.at("stopped_by"), "time") << trained.output();
    EXPECT_LE(summary.at("wall_time_s").get<double>(), bound_s);
    EXPECT_TRUE(summary.at("time_budget").contains("evaluation_reserved_s"));
    // The cut iteration was kept: the last checkpoint is of the summary's steps.
    const trainer::CheckpointSearch latest = trainer::find_latest_checkpoint(run);
    ASSERT_TRUE(latest.latest.has_value());
    const std::int64_t steps = summary.at("env_steps").get<std::int64_t>();
    EXPECT_EQ(json::parse(latest.latest->blobs.at("meta")).at("env_steps"), steps);
    EXPECT_GT(steps, 0);
    if (algo == "ppo") {
      // And a resume goes on from it, within its own minutes.
      const CliRun resumed = run_cli("train --resume " + run.string() + " --quiet --minutes 0.05");
      ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
      EXPECT_NE(resumed.output.find("replayed the " + std::to_string(steps) + " env steps"),
                std::string::npos)
          << resumed.output;
      EXPECT_GT(json::parse(read_text(run / "summary.json")).at("env_steps").get<std::int64_t>(),
                steps);
    }
  }
  fs::remove_all(folder);
}

// Ctrl-C (SIGINT) ends the iteration in progress, writes a checkpoint of it and prints the
// command that resumes the run; the exit code is 130 (128 + SIGINT), as for a process killed by
// Ctrl-C. The command resumes.
TEST(TrainCliTest, CtrlCCheckpointsAndPrintsTheCommandThatResumes) {
  const fs::path folder = fresh_folder("sigint");
  const fs::path run = folder / "run";
  const std::string command =
      std::string(PIXELGYM_CLI) + " " +
      train_arguments(folder, "--checkpoint-every 1 --out " + run.string()) + " > " +
      (folder / "log.txt").string() + " 2>&1";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    execl("/bin/sh", "sh", "-c", ("exec " + command).c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!fs::exists(run / "ckpt-000002.pgck") && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  ::kill(child, SIGINT);
  int status = 0;
  ::waitpid(child, &status, 0);
  const std::string log = read_text(folder / "log.txt");
  ASSERT_TRUE(WIFEXITED(status)) << "killed by the signal, not stopped\n" << log;
  EXPECT_EQ(WEXITSTATUS(status), 130) << log;
  const std::string resume = "resume with: pixelgym train --resume " + run.string() + "\n";
  EXPECT_NE(log.find(resume), std::string::npos) << log;
  EXPECT_NE(log.find("interrupted at "), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(run / "summary.json"));
  // The checkpoint it names holds the steps it names.
  const trainer::CheckpointSearch latest = trainer::find_latest_checkpoint(run);
  ASSERT_TRUE(latest.latest.has_value());
  const std::int64_t steps = json::parse(latest.latest->blobs.at("meta")).at("env_steps");
  EXPECT_NE(log.find("interrupted at " + std::to_string(steps) + " env steps: wrote " +
                     latest.latest->path.string()),
            std::string::npos)
      << log;
  const CliRun resumed = run_cli("train --resume " + run.string() + " --steps " +
                                 std::to_string(steps + 32) + " --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_TRUE(fs::exists(run / "summary.json"));
  fs::remove_all(folder);
}

// More torch threads than the cores left free by the machine's load draw a warning naming the
// figures and what to do (PIXELGYM_LOADAVG fakes the load); none on an idle machine
// (ProcessTuningTest checks the bounds).
TEST(TrainCliTest, TorchThreadsAboveTheFreeCoresAreWarnedOf) {
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  ASSERT_EQ(sched_getaffinity(0, sizeof(cpus), &cpus), 0);
  const int cores = CPU_COUNT(&cpus);
  const fs::path folder = fresh_folder("busy");
  const auto train = [&](const std::string& load, const std::string& threads) {
    fs::remove_all(folder / "run");
    return run_cli(train_arguments(folder, "--steps 32 --out " + (folder / "run").string() +
                                               " --torch-threads " + threads),
                   "OMP_NUM_THREADS= PIXELGYM_LOADAVG=" + load);
  };
  const CliRun busy = train("64", std::to_string(std::max(cores, 2)));
  ASSERT_EQ(busy.exit_code, 0) << busy.output;
  EXPECT_THAT(busy.output,
              ::testing::HasSubstr("warning: torch_threads=" + std::to_string(std::max(cores, 2)) +
                                   " (--torch-threads), but about 0.0 of the " +
                                   std::to_string(cores) + " cores"));
  EXPECT_THAT(busy.output, ::testing::HasSubstr("load average 64.00 over the last minute"));
  EXPECT_THAT(busy.output, ::testing::HasSubstr("Give --torch-threads 1 (the free cores)"));
  const CliRun idle = train("0", std::to_string(cores));
  ASSERT_EQ(idle.exit_code, 0) << idle.output;
  EXPECT_THAT(idle.output, ::testing::Not(::testing::HasSubstr("warning: torch_threads")));
  fs::remove_all(folder);
}

// compare's default curve (the evaluations, eval.csv) falls back to the training returns when a
// run has no eval.csv, saying so before the table; asked for by --curve eval, it is refused
// before any line of the table, naming the curve that exists.
TEST(TrainCliTest, CompareFallsBackToTheTrainingCurveWithoutEvaluations) {
  const fs::path folder = fresh_folder("compare");
  const fs::path run = folder / "run";
  const CliRun trained =
      run_cli(train_arguments(folder, "--steps 32 --eval-every 0 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  ASSERT_FALSE(fs::exists(run / "eval.csv"));
  const CliRun fallback =
      run_cli("compare " + run.string() + " --out " + (folder / "default.png").string());
  ASSERT_EQ(fallback.exit_code, 0) << fallback.output;
  EXPECT_THAT(fallback.output, ::testing::HasSubstr("has no eval.csv"));
  EXPECT_THAT(fallback.output, ::testing::HasSubstr("\nrun,32,"));
  EXPECT_LT(fallback.output.find("has no eval.csv"),
            fallback.output.find("run,control_steps,wall_minutes"));
  EXPECT_TRUE(fs::exists(folder / "default.png"));
  const CliRun refused =
      run_cli("compare " + run.string() + " --curve eval --out " + (folder / "eval.png").string());
  EXPECT_EQ(refused.exit_code, 2) << refused.output;
  EXPECT_THAT(refused.output, ::testing::HasSubstr("--curve train"));
  EXPECT_THAT(refused.output, ::testing::Not(::testing::HasSubstr("run,control_steps")));
  EXPECT_FALSE(fs::exists(folder / "eval.png"));
  fs::remove_all(folder);
}

// A mistyped env id, kwarg or wrapper is refused before the run folder is touched, as a usage
// error whose first line is the error (not the threads warning of a run that never starts): no
// folder is made, and a folder given with --out is left without a .lock.
TEST(TrainCliTest, AMistypedIdOrKwargLeavesNoFolderAndNoLock) {
  const fs::path folder = fresh_folder("mistyped");
  const std::vector<std::pair<std::string, std::string>> typos = {
      {"CartPoleBalanc-v0", "pixelgym: unknown env id \"CartPoleBalanc-v0\""},
      {"CartPoleBalance-v0 --set widht=32",
       "pixelgym: CartPoleBalance-v0: unknown kwarg \"widht\""},
      {"CartPoleBalance-v0 --wrap greyscal", "pixelgym: "},
      {"CartPoleBalance-v0 --set msaa=3",
       "pixelgym: CartPoleBalance-v0: msaa must be 0, 2, 4 or 8"},
  };
  for (const auto& [typo, first_line] : typos) {
    SCOPED_TRACE(typo);
    // A load that makes the run warn of busy cores, were it to start.
    const std::string busy = "env -u OMP_NUM_THREADS PIXELGYM_LOADAVG=64";
    const CliRun fresh = run_cli("train " + typo + " --steps 16 --torch-threads 2 --quiet --out " +
                                     (folder / "new").string(),
                                 busy);
    EXPECT_EQ(fresh.exit_code, 2) << fresh.output;
    EXPECT_THAT(fresh.output, ::testing::StartsWith(first_line));
    EXPECT_THAT(fresh.output,
                ::testing::EndsWith("\nRun 'pixelgym train --help' for the options.\n"));
    EXPECT_EQ(std::count(fresh.output.begin(), fresh.output.end(), '\n'), 2) << fresh.output;
    EXPECT_FALSE(fs::exists(folder / "new"));
    fs::create_directories(folder / "given");
    const CliRun given =
        run_cli("train " + typo + " --steps 16 --quiet --out " + (folder / "given").string());
    EXPECT_EQ(given.exit_code, 2) << given.output;
    EXPECT_TRUE(fs::is_empty(folder / "given")) << "a refused run left files in its folder";
    // --print-config checks what the run would: it prints nothing for settings it refuses.
    const CliRun printed = run_cli("train " + typo + " --print-config");
    EXPECT_EQ(printed.exit_code, 2) << printed.output;
    EXPECT_THAT(printed.output, ::testing::StartsWith(first_line));
    EXPECT_THAT(printed.output, ::testing::Not(::testing::HasSubstr("{")));
  }
  // A kwarg the env refuses only once it is built (msaa=8 where this OpenGL offers less) is
  // refused after the lock is taken, as a usage error too: the lock goes with the refusal.
  const CliRun built = run_cli(
      train_arguments(folder, "--steps 16 --set msaa=8 --out " + (folder / "given").string()),
      "env -u OMP_NUM_THREADS PIXELGYM_LOADAVG=64");
  if (built.output.find("is more than this OpenGL offers") != std::string::npos) {
    EXPECT_EQ(built.exit_code, 2) << built.output;
    EXPECT_THAT(built.output, ::testing::StartsWith("pixelgym: "));
    EXPECT_THAT(built.output, ::testing::Not(::testing::HasSubstr("warning:")));
    EXPECT_TRUE(fs::is_empty(folder / "given")) << built.output;
  }
  fs::remove_all(folder);
}

// A config file that does not exist but names a recipe, and an eval path that is no run, are
// answered with what was expected.
TEST(TrainCliTest, MissingConfigFilesAndRunFoldersSayWhatWasExpected) {
  const CliRun recipe = run_cli("train CartPoleSwingup-v1 --config swingup.json --print-config");
  EXPECT_EQ(recipe.exit_code, 2) << recipe.output;
  EXPECT_THAT(recipe.output,
              ::testing::HasSubstr("cannot read swingup.json (no such file); did you mean the "
                                   "recipe --config swingup?"));
  const fs::path folder = fresh_folder("no_run");
  const CliRun missing = run_cli("eval " + (folder / "none").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_THAT(missing.output, ::testing::HasSubstr("eval: " + (folder / "none").string() +
                                                   " does not exist; expected a run folder"));
  const CliRun empty = run_cli("eval " + folder.string());
  EXPECT_EQ(empty.exit_code, 1) << empty.output;
  EXPECT_THAT(empty.output, ::testing::HasSubstr("eval: " + folder.string() +
                                                 " is not a run folder (no checkpoint "
                                                 "ckpt-*.pgck, config.json or summary.json"));
  fs::remove_all(folder);
}

// An evaluation during training skipped for taking too much of the wall time is said once, not
// once per evaluation; summary.json counts them.
TEST(TrainCliTest, SkippedEvaluationsAreSaidOnce) {
  const fs::path folder = fresh_folder("skipped");
  const fs::path run = folder / "run";
  const CliRun trained = run_cli(train_arguments(
      folder, "--steps 160 --eval-every 32 --eval-every-episodes 1 --eval-max-share 0.001 --out " +
                  run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  std::size_t said = 0;
  for (std::size_t at = trained.output.find("env steps skipped"); at != std::string::npos;
       at = trained.output.find("env steps skipped", at + 1)) {
    ++said;
  }
  EXPECT_EQ(said, 1U) << trained.output;
  const json summary = json::parse(read_text(run / "summary.json"));
  EXPECT_EQ(summary.at("evaluations_skipped").get<int>(), 4) << trained.output;
  fs::remove_all(folder);
}

// pixelgym does not link LibTorch: train and eval run in pixelgym-train, the program beside it,
// which takes the process over once the command line parsed. Without it the other subcommands
// work, a train usage error is still found, and train says which program is missing.
TEST(TrainCliTest, TrainAndEvalRunInPixelgymTrainBesideTheTool) {
  const fs::path folder = fresh_folder("alone");
  const fs::path alone = folder / "pixelgym";
  fs::copy_file(PIXELGYM_CLI, alone);
  const std::string tool = alone.string();
  const CliRun listed = run_program(tool + " list");
  EXPECT_EQ(listed.exit_code, 0) << listed.output;
  EXPECT_NE(listed.output.find("CartPoleBalance-v0"), std::string::npos) << listed.output;
  const CliRun usage = run_program(tool + " train CartPoleBalance-v0 --threads 0");
  EXPECT_EQ(usage.exit_code, 2) << usage.output;
  EXPECT_NE(usage.output.find("--threads: must be an integer from 1"), std::string::npos)
      << usage.output;
  const CliRun missing =
      run_program(tool + " train CartPoleBalance-v0 --steps 16 --out " + (folder / "run").string());
  EXPECT_EQ(missing.exit_code, 1) << missing.output;
  EXPECT_NE(
      missing.output.find("pixelgym: error: cannot start " + (folder / "pixelgym-train").string() +
                          ": No such file or directory"),
      std::string::npos)
      << missing.output;
  const CliRun eval = run_program(tool + " eval " + (folder / "run").string());
  EXPECT_EQ(eval.exit_code, 1) << eval.output;
  EXPECT_NE(eval.output.find("cannot start"), std::string::npos) << eval.output;
  EXPECT_FALSE(fs::exists(folder / "run"));
  fs::remove_all(folder);
}

}  // namespace
}  // namespace pixelgym::testing
