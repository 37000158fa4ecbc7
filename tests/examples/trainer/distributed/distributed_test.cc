// Data-parallel training over loopback with two processes: the update of 2 ranks x 4 envs is
// the update of one process of 8 envs, the ranks end with identical parameters, a distributed
// run resumes as the run that did not stop, and a rank that dies or hangs stops the run within
// the timeout with an error naming it. Tiny settings (32x32 pixels, 16-step rollouts) keep each
// to seconds.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/trainer/checkpoint_file.h"
#include "pixelgym/trainer/progress_csv.h"
#include "tests/examples/cli_run.h"
#include "tests/examples/trainer/distributed/rank_processes.h"

namespace pixelgym::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct WorkerResult {
  int exit_code = -1;
  std::string output;
};

// Runs distributed_worker SCENARIO as ranks 0 and 1 of a world of two; waits up to 180 s.
std::vector<WorkerResult> run_workers(const std::string& scenario, const fs::path& folder,
                                      int port) {
  std::vector<pid_t> pids;
  for (int rank = 0; rank < 2; ++rank) {
    const fs::path log = folder / (scenario + "_" + std::to_string(rank) + ".txt");
    const pid_t pid = fork();
    if (pid == 0) {
      setenv("WORLD_SIZE", "2", 1);
      setenv("RANK", std::to_string(rank).c_str(), 1);
      setenv("MASTER_ADDR", "127.0.0.1", 1);
      setenv("MASTER_PORT", std::to_string(port).c_str(), 1);
      const std::string command = std::string("exec ") + PIXELGYM_DIST_WORKER + " " + scenario +
                                  " > " + log.string() + " 2>&1";
      execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
      _exit(127);
    }
    pids.push_back(pid);
  }
  std::vector<WorkerResult> results(2);
  const auto deadline = Clock::now() + std::chrono::seconds(180);
  for (int rank = 0; rank < 2; ++rank) {
    int status = 0;
    while (waitpid(pids[static_cast<std::size_t>(rank)], &status, WNOHANG) == 0) {
      if (Clock::now() > deadline) {
        kill(pids[static_cast<std::size_t>(rank)], SIGKILL);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    results[static_cast<std::size_t>(rank)] = {
        WIFEXITED(status) ? WEXITSTATUS(status) : -1,
        read_text(folder / (scenario + "_" + std::to_string(rank) + ".txt"))};
  }
  return results;
}

// Runs a scenario of distributed_worker as two ranks; each must exit 0.
void expect_both_ranks_pass(const std::string& scenario) {
  const fs::path folder = fresh_folder(scenario);
  for (const WorkerResult& result : run_workers(scenario, folder, test_port())) {
    EXPECT_EQ(result.exit_code, 0) << result.output;
  }
  fs::remove_all(folder);
}

// The comparison is made exact in what it compares: both ranks learn from the halves (envs 0-3
// and 4-7) of one 8-env rollout that each also gives, whole, to a single-process trainer; each
// rank visits its half in an order of its own, and the single process visits, in minibatch m,
// the union of the ranks' minibatches m. The ranks' update then averages the same gradients the
// single process takes over the union (advantages standardized over the union too), so the
// parameters agree to float rounding, and the observation statistics to double rounding.
TEST(DistributedTest, AnUpdateOfTwoRanksOfFourEnvsIsAnUpdateOfOneProcessOfEight) {
  expect_both_ranks_pass("equivalence");
}

TEST(DistributedTest, StatisticsMergedAcrossRanksAreThoseOfOneBatch) {
  expect_both_ranks_pass("statistics");
}

TEST(DistributedTest, RanksWhoseParametersDifferAreStoppedByTheDigestCheck) {
  expect_both_ranks_pass("digest_mismatch");
}

// DD-PPO's preemption: with rank 1 a straggler, its rollouts stop once rank 0 has finished (and
// it has a quarter of its steps); the ranks learn from rollouts of different lengths and stay
// identical.
TEST(DistributedTest, AStragglersRolloutIsPreempted) { expect_both_ranks_pass("preemption"); }

TEST(DistributedTest, TwoRanksTrainOneRunWithIdenticalParameters) {
  const fs::path folder = fresh_folder("run");
  const fs::path run = folder / "run";
  // 2 ranks x 2 envs x 16 steps: 64 env steps per update.
  const CliRun trained = run_cli(train_arguments(
      folder,
      "--nproc 2 --steps 256 --checkpoint-every 2 --keep-checkpoints 0 --out " + run.string()));
  ASSERT_EQ(trained.exit_code, 0) << trained.output;
  const json summary = json::parse(read_text(run / "summary.json"));
  ASSERT_TRUE(summary.contains("distributed")) << summary.dump();
  EXPECT_EQ(summary.at("distributed").at("world_size"), 2);
  const json digests = summary.at("distributed").at("parameter_digests");
  ASSERT_EQ(digests.size(), 2U);
  EXPECT_EQ(digests[0], digests[1]);
  EXPECT_EQ(summary.at("env_steps"), 256);
  EXPECT_EQ(json::parse(read_text(run / "config.json")).at("world_size"), 2);
  // progress.csv counts the steps of both ranks.
  const std::vector<double> steps =
      trainer::read_progress_csv(run / "progress.csv").column("steps");
  EXPECT_EQ(steps, (std::vector<double>{64, 128, 192, 256}));
  // A checkpoint holds rank 1's own part beside rank 0's.
  const trainer::CheckpointBlobs checkpoint =
      trainer::read_checkpoint(run / trainer::checkpoint_file_name(4));
  for (const char* blob : {"model", "env_actions", "rank1.meta", "rank1.env_actions",
                           "rank1.rng_sampling", "rank1.rng_augmentation"}) {
    EXPECT_EQ(checkpoint.count(blob), 1U) << blob;
  }
  // The two ranks stepped different envs (env seeds 0-1 and 2-3).
  EXPECT_NE(checkpoint.at("env_actions"), checkpoint.at("rank1.env_actions"));
  // A resume with another world size is refused, naming the run's.
  const CliRun other = run_cli("train --resume " + run.string() + " --steps 320 --quiet");
  EXPECT_EQ(other.exit_code, 2) << other.output;
  EXPECT_NE(other.output.find("trained by 2 ranks"), std::string::npos) << other.output;
  EXPECT_NE(other.output.find("--nproc 2"), std::string::npos) << other.output;
  fs::remove_all(folder);
}

TEST(DistributedTest, ADistributedRunResumesAsTheRunThatDidNotStop) {
  const fs::path folder = fresh_folder("resume");
  const fs::path straight = folder / "straight";
  const fs::path split = folder / "split";
  const CliRun whole =
      run_cli(train_arguments(folder, "--nproc 2 --steps 384 --out " + straight.string()));
  ASSERT_EQ(whole.exit_code, 0) << whole.output;
  const CliRun first =
      run_cli(train_arguments(folder, "--nproc 2 --steps 192 --out " + split.string()));
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const CliRun second =
      run_cli("train --resume " + split.string() + " --nproc 2 --steps 384 --quiet");
  ASSERT_EQ(second.exit_code, 0) << second.output;
  EXPECT_NE(second.output.find("replayed the"), std::string::npos) << second.output;
  EXPECT_EQ(second.output.find("warning"), std::string::npos) << second.output;
  const json a = json::parse(read_text(straight / "summary.json"));
  const json b = json::parse(read_text(split / "summary.json"));
  EXPECT_EQ(b.at("env_steps"), 384);
  EXPECT_EQ(a.at("distributed").at("parameter_digests"),
            b.at("distributed").at("parameter_digests"));
  EXPECT_EQ(a.at("evaluation").at("returns"), b.at("evaluation").at("returns"));
  fs::remove_all(folder);
}

struct Stopped {
  double seconds = 0.0;  // from the signal to the launcher's exit
  int exit_code = -1;
  std::string output;
};

// Starts a long `--nproc 2` run with --dist-timeout `timeout`, waits for its first progress row,
// sends rank 1 `signal_number`, and waits for the launcher to exit (at most 120 s).
Stopped stop_rank_one(const fs::path& folder, int signal_number, int timeout) {
  const fs::path run = folder / "run";
  const fs::path log = folder / "log.txt";
  const std::string command =
      "exec " + std::string(PIXELGYM_CLI) + " " +
      train_arguments(folder,
                      "--nproc 2 --steps 10000000 "
                      "--checkpoint-every 1 --dist-timeout " +
                          std::to_string(timeout) + " --out " + run.string()) +
      " > " + log.string() + " 2>&1";
  const pid_t launcher = fork();
  if (launcher == 0) {
    execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  Stopped stopped;
  const auto deadline = Clock::now() + std::chrono::seconds(120);
  while (Clock::now() < deadline &&
         !(fs::exists(run / "progress.csv") &&
           trainer::read_progress_csv(run / "progress.csv").rows.size() >= 2)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  const pid_t victim = rank_pid(launcher, 1);
  if (victim <= 0) {
    kill(launcher, SIGTERM);
    waitpid(launcher, nullptr, 0);
    stopped.output = "rank 1 not found; " + read_text(log);
    return stopped;
  }
  const auto signalled = Clock::now();
  kill(victim, signal_number);
  int status = 0;
  while (waitpid(launcher, &status, WNOHANG) == 0 &&
         Clock::now() < signalled + std::chrono::seconds(120)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  stopped.seconds = std::chrono::duration<double>(Clock::now() - signalled).count();
  if (waitpid(launcher, &status, WNOHANG) == 0) {
    kill(launcher, SIGKILL);
    kill(victim, SIGKILL);
    waitpid(launcher, &status, 0);
  }
  stopped.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  stopped.output = read_text(log);
  std::cout << "the launcher exited " << stopped.seconds << " s after signal " << signal_number
            << " to rank 1\n";
  return stopped;
}

// Every checkpoint left is whole (read_checkpoint checks sizes and checksums).
void expect_whole_checkpoints(const fs::path& run) {
  for (const fs::path& path : trainer::list_checkpoints(run)) {
    EXPECT_NO_THROW(trainer::read_checkpoint(path)) << path;
  }
}

TEST(DistributedTest, AKilledRankStopsTheRunWithAnErrorNamingIt) {
  const fs::path folder = fresh_folder("killed");
  const Stopped stopped = stop_rank_one(folder, SIGKILL, 10);
  EXPECT_EQ(stopped.exit_code, 1) << stopped.output;
  // Rank 0 finds the dead peer at its next collective (a connection reset) and names it.
  EXPECT_LT(stopped.seconds, 10.0 + 5.0) << stopped.output;
  EXPECT_NE(stopped.output.find("rank 1 (pid"), std::string::npos) << stopped.output;
  EXPECT_NE(stopped.output.find("was killed by signal 9"), std::string::npos) << stopped.output;
  EXPECT_NE(stopped.output.find("rank 0: "), std::string::npos) << stopped.output;
  EXPECT_NE(stopped.output.find("rank 1 has not answered"), std::string::npos) << stopped.output;
  expect_whole_checkpoints(folder / "run");
  fs::remove_all(folder);
}

TEST(DistributedTest, AHungRankStopsTheRunWithinTheTimeout) {
  const fs::path folder = fresh_folder("hung");
  // SIGSTOP: the process lives and its sockets stay open, but it answers nothing.
  const Stopped stopped = stop_rank_one(folder, SIGSTOP, 5);
  EXPECT_EQ(stopped.exit_code, 1) << stopped.output;
  EXPECT_NE(stopped.output.find("rank 1 has not answered for"), std::string::npos)
      << stopped.output;
  // Rank 0 stops after the 5 s timeout; the launcher then ends the stopped rank 1.
  EXPECT_LT(stopped.seconds, 5.0 + 5.0 + 10.0 + 5.0) << stopped.output;
  expect_whole_checkpoints(folder / "run");
  fs::remove_all(folder);
}

}  // namespace
}  // namespace pixelgym::testing
