#include "pixelgym/trainer/run_folder.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "pixelgym/render/image_io.h"
#include "pixelgym/trainer/atomic_file.h"
#include "pixelgym/trainer/checkpoint_file.h"
#include "tests/examples/trainer/run/test_folders.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using test_folders::entries;
using test_folders::fresh_folder;
using ::testing::HasSubstr;

nlohmann::json sample_config() {
  return {{"env_id", "CartPoleBalance-v0"}, {"seed", 7}, {"ppo", {{"lr", 2.5e-4}}}};
}

ProgressRow row_at(std::int64_t steps) {
  ProgressRow row;
  row.steps = steps;
  row.wall_time_s = static_cast<double>(steps) / 100.0;
  row.fps = 100.0;
  row.episode_return_mean = static_cast<double>(steps) / 10.0;
  row.episode_return_std = 5.0;
  return row;
}

std::string file_text(const fs::path& path) { return read_whole_file(path, "test"); }

nlohmann::json read_json(const fs::path& path) { return nlohmann::json::parse(file_text(path)); }

std::vector<double> steps_on_disk(const fs::path& folder) {
  return read_progress_csv(folder / "progress.csv").column("steps");
}

// Rows as CSV text (NaN compares unequal to itself; its empty field does not).
std::string as_csv(const std::vector<std::vector<double>>& rows) {
  std::string text;
  for (const std::vector<double>& row : rows) text += format_progress_values(row);
  return text;
}

TEST(RunFolderTest, CreateWritesTheConfigWithTheCodeVersionAndTheCsvHeader) {
  const fs::path folder = fresh_folder("run_create") / "runs" / "demo";  // parents created
  const RunFolder run = RunFolder::create(folder, sample_config(), {"lr"});
  EXPECT_EQ(entries(folder), (std::vector<std::string>{"config.json", "progress.csv"}));
  const nlohmann::json config = read_json(folder / "config.json");
  EXPECT_EQ(config["env_id"], "CartPoleBalance-v0");
  EXPECT_EQ(config["ppo"]["lr"], 2.5e-4);
  EXPECT_THAT(config["code_version"]["commit"].get<std::string>(), ::testing::SizeIs(40));
  EXPECT_TRUE(config["code_version"]["dirty"].is_boolean());
  EXPECT_EQ(config, run.config());
  EXPECT_EQ(file_text(folder / "progress.csv"), format_progress_header({"lr"}));
  EXPECT_EQ(run.metric_columns(), std::vector<std::string>{"lr"});
  EXPECT_TRUE(run.progress().rows.empty());
}

TEST(RunFolderTest, CreateRefusesAFolderThatHoldsARun) {
  const fs::path folder = fresh_folder("run_twice");
  RunFolder::create(folder, sample_config());
  const std::string before = file_text(folder / "config.json");
  try {
    RunFolder::create(folder, {{"other", true}});
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("\"" + folder.string() +
                                        "\" already holds a run (config.json); resume it or "
                                        "choose another folder"));
  }
  EXPECT_EQ(file_text(folder / "config.json"), before);
}

// A run folder is locked while a process trains in it: a second lock is refused naming the
// holder's PID; released, or left by a dead process (its PID still in the file), it is free.
TEST(RunLockTest, ASecondLockIsRefusedNamingTheHolderAndAStaleOneDoesNotBlock) {
  const fs::path folder = fresh_folder("run_lock");
  {
    const RunLock held = RunLock::acquire(folder, "train");
    try {
      RunLock::acquire(folder, "train --resume");
      FAIL() << "a second lock was granted";
    } catch (const std::runtime_error& error) {
      EXPECT_THAT(error.what(), HasSubstr("train --resume: \"" + folder.string() +
                                          "\" is in use: another process (pid " +
                                          std::to_string(::getpid()) + ") is training in it"));
    }
  }
  EXPECT_NO_THROW(RunLock::acquire(folder, "train"));
  // What a killed process leaves: the file with its PID, and no lock (the kernel dropped it).
  std::ofstream(folder / ".lock") << "999999\n";
  EXPECT_NO_THROW(RunLock::acquire(folder, "train"));
}

// Deleting .lock (or all of the folder's files) while a run holds the lock does not free it: a
// lock on the file itself was granted to a second run, and both then wrote one progress.csv.
TEST(RunLockTest, DeletingTheLockFileDoesNotFreeTheLock) {
  const fs::path folder = fresh_folder("run_lock_deleted");
  const RunLock held = RunLock::acquire(folder, "train");
  std::ofstream(folder / "progress.csv") << "steps\n";
  fs::remove(folder / ".lock");
  EXPECT_THROW(RunLock::acquire(folder, "train"), std::runtime_error);
  fs::remove(folder / "progress.csv");
  EXPECT_THROW(RunLock::acquire(folder, "train --resume"), std::runtime_error);
  // Without the PID file the refusal still says why, only without the PID.
  try {
    RunLock::acquire(folder, "train");
    FAIL() << "a second lock was granted";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("\" is in use: another process is training in it"));
  }
}

TEST(RunFolderTest, CreateRejectsABadConfig) {
  const fs::path folder = fresh_folder("run_bad_config");
  EXPECT_THROW(RunFolder::create(folder, nlohmann::json::array()), std::invalid_argument);
  EXPECT_THROW(RunFolder::create(folder, {{"code_version", "mine"}}), std::invalid_argument);
  EXPECT_THROW(RunFolder::create(folder, sample_config(), {"fps"}), std::invalid_argument);
  EXPECT_TRUE(entries(folder).empty());
}

TEST(RunFolderTest, RowsAreOnDiskAsSoonAsAppendedAndStepsMustIncrease) {
  const fs::path folder = fresh_folder("run_append");
  RunFolder run = RunFolder::create(folder, sample_config());
  run.append_progress(row_at(1000));
  EXPECT_EQ(steps_on_disk(folder), std::vector<double>{1000});
  run.append_progress(row_at(2000));
  EXPECT_EQ(steps_on_disk(folder), (std::vector<double>{1000, 2000}));
  EXPECT_THROW(run.append_progress(row_at(2000)), std::invalid_argument);
  EXPECT_EQ(run.progress().rows.size(), 2U);
  EXPECT_EQ(as_csv(read_progress_csv(folder / "progress.csv").rows), as_csv(run.progress().rows));
}

// A process killed right after appending rows has them in progress.csv: nothing waits in a
// buffer of the process.
TEST(RunFolderTest, RowsSurviveASigkillRightAfterAppending) {
  const fs::path folder = fresh_folder("run_sigkill");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    RunFolder run = RunFolder::create(folder, sample_config());
    for (int i = 1; i <= 3; ++i) run.append_progress(row_at(1000 * i));
    ::kill(::getpid(), SIGKILL);
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL);
  EXPECT_EQ(steps_on_disk(folder), (std::vector<double>{1000, 2000, 3000}));
}

TEST(RunFolderTest, ResumeDropsRowsAfterTheCheckpointAndAppendsAfterTheRest) {
  const fs::path folder = fresh_folder("run_resume");
  {
    RunFolder run = RunFolder::create(folder, sample_config(), {"lr"});
    for (int i = 1; i <= 5; ++i) {
      ProgressRow row = row_at(1000 * i);
      row.metrics = {{"lr", 0.1 * i}};
      run.append_progress(row);
    }
  }
  // The last checkpoint was at 3000 steps: 4000 and 5000 will be logged again.
  EXPECT_THROW(RunFolder::resume(folder, 3000, nlohmann::json::array()), std::invalid_argument);
  EXPECT_THROW(RunFolder::resume(folder, 3000, {{"steps", 1}}), std::invalid_argument);
  RunFolder run = RunFolder::resume(folder, 3000, {{"total_env_steps", 9000}, {"minutes", 2.5}});
  EXPECT_EQ(steps_on_disk(folder), (std::vector<double>{1000, 2000, 3000}));
  EXPECT_EQ(run.progress().rows.size(), 3U);
  EXPECT_EQ(run.metric_columns(), std::vector<std::string>{"lr"});
  ProgressRow row = row_at(4000);
  row.metrics = {{"lr", 0.4}};
  EXPECT_THROW(run.append_progress(row_at(3000)), std::invalid_argument);
  run.append_progress(row);
  EXPECT_EQ(steps_on_disk(folder), (std::vector<double>{1000, 2000, 3000, 4000}));
  EXPECT_EQ(as_csv(read_progress_csv(folder / "progress.csv").rows), as_csv(run.progress().rows));
  // The resume is in config.json, with the code that resumed and its budget.
  const nlohmann::json config = read_json(folder / "config.json");
  ASSERT_EQ(config["resumes"].size(), 1U);
  EXPECT_EQ(config["resumes"][0]["steps"], 3000);
  EXPECT_TRUE(config["resumes"][0]["code_version"].contains("commit"));
  EXPECT_EQ(config["resumes"][0]["total_env_steps"], 9000);
  EXPECT_EQ(config["resumes"][0]["minutes"], 2.5);
  EXPECT_EQ(config["env_id"], "CartPoleBalance-v0");
  // No temporary left by the rewrite.
  EXPECT_EQ(entries(folder), (std::vector<std::string>{"config.json", "progress.csv"}));
}

TEST(RunFolderTest, ResumeDropsARowCutShortByAKill) {
  const fs::path folder = fresh_folder("run_resume_cut");
  {
    RunFolder run = RunFolder::create(folder, sample_config());
    run.append_progress(row_at(1000));
  }
  std::ofstream(folder / "progress.csv", std::ios::app) << "2000,20,10";
  RunFolder run = RunFolder::resume(folder, 5000);
  run.append_progress(row_at(2000));
  EXPECT_EQ(steps_on_disk(folder), (std::vector<double>{1000, 2000}));
}

TEST(RunFolderTest, ResumeWithoutARunNamesTheMissingFile) {
  const fs::path folder = fresh_folder("run_resume_missing");
  try {
    RunFolder::resume(folder, 0);
    FAIL() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("cannot read " + (folder / "config.json").string() +
                                        ": No such file or directory"));
  }
}

TEST(RunFolderTest, SummaryCurveAndCheckpointPathsLandInTheFolder) {
  const fs::path folder = fresh_folder("run_files");
  RunFolder run = RunFolder::create(folder, sample_config());
  for (int i = 1; i <= 20; ++i) run.append_progress(row_at(1000 * i));
  run.write_summary({{"eval_return_mean", 812.5}, {"eval_return_std", 10.0}, {"episodes", 10}});
  run.write_curve("CartPoleBalance-v0");
  EXPECT_EQ(read_json(folder / "summary.json")["eval_return_mean"], 812.5);
  EXPECT_EQ(file_text(folder / "summary.json").back(), '\n');
  const render::Image curve = render::read_png((folder / "curve.png").string());
  EXPECT_EQ(curve.width, 900);
  EXPECT_EQ(curve.height, 450);
  EXPECT_EQ(run.checkpoint_path(120), folder / "ckpt-000120.pgck");
  EXPECT_EQ(entries(folder),
            (std::vector<std::string>{"config.json", "curve.png", "progress.csv", "summary.json"}));
}

}  // namespace
}  // namespace pixelgym::trainer
