// Run folders written by an earlier build keep working: tests/data/runs/ holds a PPO and a
// DrQ-v2 run folder made with the `pixelgym` of commit bc3ad29 (the trainer before the run took
// over the env loop): CartPoleBalance-v1 from state, 50-step episodes, 384 env steps, one
// checkpoint (ckpt-000006.pgck), config.json, progress.csv and summary.json (curve.png and
// final.mp4 removed to keep them small). Made with
//   pixelgym train CartPoleBalance-v1 --set obs_mode=state --set max_episode_steps=50
//     --set render_width=32 --set render_height=32 --config '{...tiny...}' --steps 384
//     --checkpoint-every 3 --keep-checkpoints 1 --eval-episodes 2 --eval-every 0 --threads 1
//     --torch-threads 1 --quiet --out ppo-bc3ad29   (and --algo drqv2, drqv2-bc3ad29)
// The expected figures are what bc3ad29's own binary printed for the same commands: `pixelgym
// eval` of the folder as it is, and `pixelgym eval` after `train --resume ... --steps 512`. They
// are compared to within 5e-4, the printed precision: the BLAS kernels of CPUs of one kind
// (AVX2 or AVX-512) differ in the last bits, and 128 steps of learning carry that into the sixth
// digit (DrQ-v2's return_std after the resume: 0.143901 on one, 0.1439 on the other), while a
// resume that learns otherwise moves the returns by far more.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "tests/examples/cli_run.h"

namespace pixelgym::testing {
namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// A scratch copy of the committed run folder `name` (the test data itself is never written).
fs::path copy_of_run(const std::string& name) {
  const fs::path copy =
      fs::temp_directory_path() / ("pixelgym_old_runs_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(copy);
  fs::copy(fs::path(OLD_RUNS_DIR) / name, copy, fs::copy_options::recursive);
  return copy;
}

// The first line of `text`, for progress.csv's header.
std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

// The figures `pixelgym eval` prints, in order: each episode's return, return_mean, return_std.
std::vector<double> evaluation_figures(const std::string& output) {
  std::vector<double> figures;
  for (const std::string key : {"return=", "return_mean=", "return_std="}) {
    for (std::size_t at = output.find(key); at != std::string::npos;
         at = output.find(key, at + 1)) {
      figures.push_back(std::stod(output.substr(at + key.size())));
    }
  }
  return figures;
}

void expect_figures(const std::string& output, const std::vector<double>& expected) {
  const std::vector<double> figures = evaluation_figures(output);
  ASSERT_EQ(figures.size(), expected.size()) << output;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    EXPECT_NEAR(figures[i], expected[i], 5e-4) << "figure " << i << " of\n" << output;
  }
}

// What an old run must still do: evaluate to the returns its own build printed, resume to 512
// steps with progress.csv's columns unchanged, and evaluate after the resume to the returns its
// own build's resume gave (the same learning, draw for draw).
void expect_resumes_and_evaluates_unchanged(const std::string& name,
                                            const std::vector<double>& evaluation_before,
                                            const std::vector<double>& evaluation_after) {
  const fs::path run = copy_of_run(name);
  const std::string header = first_line(read_text(run / "progress.csv"));

  const CliRun before = run_cli("eval " + run.string());
  ASSERT_EQ(before.exit_code, 0) << before.output;
  expect_figures(before.output, evaluation_before);

  const CliRun resumed = run_cli("train --resume " + run.string() + " --steps 512 --quiet");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.output;
  EXPECT_NE(resumed.output.find("replayed the 384 env steps of the checkpoint"), std::string::npos)
      << resumed.output;
  // The replayed envs are where the checkpoint's were (its env digest agrees).
  EXPECT_EQ(resumed.output.find("warning"), std::string::npos) << resumed.output;
  EXPECT_TRUE(fs::exists(run / "ckpt-000008.pgck")) << resumed.output;
  const std::string progress = read_text(run / "progress.csv");
  EXPECT_EQ(first_line(progress), header);
  EXPECT_NE(progress.find("\n512,"), std::string::npos) << progress;

  const CliRun after = run_cli("eval " + run.string());
  ASSERT_EQ(after.exit_code, 0) << after.output;
  expect_figures(after.output, evaluation_after);
  fs::remove_all(run);
}

TEST(OldRunsTest, APpoRunOfBc3ad29ResumesAndEvaluatesUnchanged) {
  // episode 0, episode 1, return_mean, return_std
  expect_resumes_and_evaluates_unchanged("ppo-bc3ad29", {49.0411, 49.6917, 49.3664, 0.325322},
                                         {49.0232, 49.6724, 49.3478, 0.324587});
}

TEST(OldRunsTest, ADrqV2RunOfBc3ad29ResumesAndEvaluatesUnchanged) {
  expect_resumes_and_evaluates_unchanged("drqv2-bc3ad29", {48.918, 49.7067, 49.3123, 0.394316},
                                         {47.9797, 48.2675, 48.1236, 0.143901});
}

}  // namespace
}  // namespace pixelgym::testing
