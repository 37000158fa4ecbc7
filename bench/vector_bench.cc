// Vector-env scaling: total env steps per second of SyncVectorEnv, AsyncVectorEnv and
// ProcessVectorEnv at 1, 2, 4, 8 and 16 envs, each beside the single-env loop in the same run.
//
// For each env count N the configurations are built, warmed up, and then stepped in turn, round
// after round: the single-env loop, N envs stepped one after the other in a plain loop (no vector
// env, each env with a GL context of its own: what N separate envs cost by themselves),
// SyncVectorEnv, AsyncVectorEnv with 1 and 2 threads (the vector envs share one GL context per
// thread, their default) and ProcessVectorEnv with 1 and 2 worker processes. Every configuration
// does the same work: env i is seeded i and steps through row i of one pool of 64 seeded random
// batched actions, in a cycle (reset when done). The single-env loop steps those same N envs, but
// one at a time: 64 steps of env 0 alone, then 64 of env 1, and so on, so that it measures one env
// stepped alone (its caches warm) over the states the batch visits. (A step's cost depends on the
// state: the arm's steps/s alone ranges over 10% between seeds, so a baseline of one seed would
// compare different work.) Each block runs for about `block_ms` of wall time. A configuration's
// ratio to the single-env loop is taken within each round (so drift on a shared machine hits both
// alike) and the medians over rounds are printed.
//
// usage: vector_bench [IDS] [rounds] [block_ms] [max_envs] [cpu]
//   IDS: comma-separated env ids (default CartPoleSwingup-v0,ArmReach-v0), 84x84 (their default)
//   cpu: time the one-thread configurations (the loops and sync) by the thread's CPU time
//        instead of wall time, and skip the others: steadier on a busy machine, for
//        decisions about per-env costs (another process taking the core does not count)
// Prints a table per id and, per id, the two figures the vector-env issue sets targets for:
//   <id> two_threads_over_one_8envs=   AsyncVectorEnv(2 threads) / SyncVectorEnv at 8 envs
//   <id> one_thread_8envs_over_loop=   SyncVectorEnv at 8 envs / the single-env loop
// and, for the worker processes at 8 and 16 envs:
//   <id> two_workers_over_one_<N>envs=      ProcessVectorEnv(2 workers) / (1 worker)
//   <id> two_workers_over_two_threads_<N>envs=  ProcessVectorEnv(2) / AsyncVectorEnv(2 threads)
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rng.h"
#include "pixelgym/envs/vector/batch_space.h"
#include "pixelgym/envs/vector/make_vec.h"

namespace {

using pixelgym::Env;
using pixelgym::Rng;
using pixelgym::SpacePtr;
using pixelgym::Value;
namespace vector = pixelgym::vector;

bool cpu_time = false;  // see usage

double now_seconds() {
  if (cpu_time) {
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

constexpr int kActionPool = 64;
constexpr int kSoloChunk = 64;  // steps of one env before the single-env loop moves to the next

// Row i of each batched action of the pool: what env i is sent, in a cycle.
std::vector<Value> action_rows(const std::vector<Value>& pool, int i) {
  std::vector<Value> rows;
  for (const Value& batch : pool) rows.push_back(vector::batch_slot(batch, i));
  return rows;
}

// One env stepped through a cycle of actions, reset (unseeded) when done.
class LoopedEnv {
 public:
  LoopedEnv(const std::string& id, std::uint64_t seed, std::vector<Value> actions)
      : env_(pixelgym::make(id)), actions_(std::move(actions)) {
    reset_.obs = env_->observation_space().zeros();
    step_.obs = env_->observation_space().zeros();
    env_->reset_into(reset_, seed);
  }
  void step() {
    env_->step_into(actions_[next_++ % actions_.size()], step_);
    if (step_.terminated || step_.truncated) env_->reset_into(reset_);
  }

 private:
  std::unique_ptr<Env> env_;
  std::vector<Value> actions_;  // views into the pool (kept alive by the caller)
  std::size_t next_ = 0;
  pixelgym::ResetResult reset_;
  pixelgym::StepResult step_;
};

// The pool's N envs stepped one at a time: kSoloChunk steps of one, then the next.
class SoloEnvs {
 public:
  SoloEnvs(const std::string& id, const std::vector<Value>& pool, int n) {
    for (int i = 0; i < n; ++i) {
      envs_.emplace_back(id, static_cast<std::uint64_t>(i), action_rows(pool, i));
    }
  }
  void step() {
    envs_[current_].step();
    if (++steps_ == kSoloChunk) {
      steps_ = 0;
      current_ = (current_ + 1) % envs_.size();
    }
  }

 private:
  std::vector<LoopedEnv> envs_;
  std::size_t current_ = 0;
  int steps_ = 0;
};

// A configuration: `batch()` advances `envs_per_batch` env steps.
struct Config {
  std::string name;
  int envs_per_batch = 1;
  std::function<void()> batch;
  std::vector<double> steps_per_s;
  std::vector<double> over_loop;  // steps_per_s / the single-env loop's, same round
};

// Runs `config` for about `seconds` of wall time; returns env steps per second.
double time_block(Config& config, double seconds) {
  const double start = now_seconds();
  double elapsed = 0.0;
  long batches = 0;
  while (elapsed < seconds) {
    for (int k = 0; k < 8; ++k) config.batch();
    batches += 8;
    elapsed = now_seconds() - start;
  }
  return static_cast<double>(batches * config.envs_per_batch) / elapsed;
}

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> parts;
  std::stringstream stream(text);
  for (std::string part; std::getline(stream, part, ',');) {
    if (!part.empty()) parts.push_back(part);
  }
  return parts;
}

struct Row {
  int num_envs;
  double loop;                 // single-env loop, steps/s
  std::vector<double> values;  // per configuration (after the loop): steps/s
  std::vector<double> ratios;  // per configuration: over the loop
};

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> ids = split(argc > 1 ? argv[1] : "CartPoleSwingup-v0,ArmReach-v0");
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 7;
  const double block = (argc > 3 ? std::atof(argv[3]) : 250.0) / 1000.0;
  const int max_envs = argc > 4 ? std::atoi(argv[4]) : 16;
  cpu_time = argc > 5 && std::string(argv[5]) == "cpu";
  const char* names[] = {"loop, own contexts", "sync",      "async 1 thread",
                         "async 2 threads",    "1 process", "2 processes"};
  for (const std::string& id : ids) {
    std::vector<Row> rows;
    for (int n = 1; n <= max_envs; n *= 2) {
      std::vector<Config> configs;
      // The batched actions every configuration steps through (see the top of this file).
      const SpacePtr batched_actions = vector::batch_space(*pixelgym::describe(id).action_space, n);
      auto pool = std::make_shared<std::vector<Value>>();
      Rng rng(0);
      for (int k = 0; k < kActionPool; ++k) pool->push_back(batched_actions->sample(rng));
      vector::VectorOptions modes[] = {
          {vector::VectorMode::kSync, 0, vector::AutoresetMode::kNextStep},
          {vector::VectorMode::kAsync, 1, vector::AutoresetMode::kNextStep},
          {vector::VectorMode::kAsync, 2, vector::AutoresetMode::kNextStep},
          {vector::VectorMode::kProcess, 0, vector::AutoresetMode::kNextStep},
          {vector::VectorMode::kProcess, 0, vector::AutoresetMode::kNextStep},
      };
      modes[3].num_workers = 1;
      modes[4].num_workers = 2;
      const int num_modes = cpu_time ? 1 : 5;
      // The worker processes are forked first, from a process that has no env yet, as
      // docs/vector.md advises (a child forked later carries a copy of everything made before).
      std::shared_ptr<vector::VectorEnv> vector_envs[5];
      for (int m = num_modes - 1; m >= 0; --m) {
        vector_envs[m] = vector::make_vec(id, n, {}, {}, modes[m]);
      }
      auto solo = std::make_shared<SoloEnvs>(id, *pool, n);
      configs.push_back({"single-env loop", 1, [solo, pool] { solo->step(); }, {}, {}});
      auto plain = std::make_shared<std::vector<LoopedEnv>>();
      for (int i = 0; i < n; ++i) {
        plain->emplace_back(id, static_cast<std::uint64_t>(i), action_rows(*pool, i));
      }
      configs.push_back({names[0],
                         n,
                         [plain] {
                           for (LoopedEnv& env : *plain) env.step();
                         },
                         {},
                         {}});
      for (int m = 0; m < num_modes; ++m) {
        std::shared_ptr<vector::VectorEnv> env = vector_envs[m];
        env->reset(0);
        auto next = std::make_shared<std::size_t>(0);
        configs.push_back({names[m + 1],
                           n,
                           [env, pool, next] { env->step((*pool)[(*next)++ % pool->size()]); },
                           {},
                           {}});
      }
      for (Config& config : configs) time_block(config, 0.05);  // warm up: shaders, caches
      for (int round = 0; round < rounds; ++round) {
        for (Config& config : configs) config.steps_per_s.push_back(time_block(config, block));
        for (Config& config : configs) {
          config.over_loop.push_back(config.steps_per_s.back() / configs[0].steps_per_s.back());
        }
      }
      Row row{n, median(configs[0].steps_per_s), {}, {}};
      for (std::size_t c = 1; c < configs.size(); ++c) {
        row.values.push_back(median(configs[c].steps_per_s));
        row.ratios.push_back(median(configs[c].over_loop));
      }
      rows.push_back(row);
      std::fprintf(stderr, "%s: %d envs done\n", id.c_str(), n);
    }
    std::printf(
        "%s: total env steps/s (%s), medians of %d rounds of %.0f ms; (x) = over the "
        "single-env loop in the same rounds\n",
        id.c_str(), cpu_time ? "thread CPU time" : "wall time", rounds, block * 1000.0);
    std::printf("  %8s %12s", "num_envs", "single loop");
    for (const char* name : names) std::printf(" %20s", name);
    std::printf("\n");
    for (const Row& row : rows) {
      std::printf("  %8d %12.0f", row.num_envs, row.loop);
      for (std::size_t c = 0; c < row.values.size(); ++c) {
        std::printf(" %12.0f (%4.2fx)", row.values[c], row.ratios[c]);
      }
      std::printf("\n");
    }
    for (const Row& row : rows) {
      if (row.num_envs != 8 || row.ratios.size() < 4) continue;
      std::printf("%s two_threads_over_one_8envs=%.2f\n", id.c_str(),
                  row.ratios[3] / row.ratios[1]);
      std::printf("%s one_thread_8envs_over_loop=%.2f\n", id.c_str(), row.ratios[1]);
    }
    for (const Row& row : rows) {
      if (row.num_envs < 8 || row.ratios.size() < 6) continue;
      std::printf("%s two_workers_over_one_%denvs=%.2f\n", id.c_str(), row.num_envs,
                  row.ratios[5] / row.ratios[4]);
      std::printf("%s two_workers_over_two_threads_%denvs=%.2f\n", id.c_str(), row.num_envs,
                  row.ratios[5] / row.ratios[3]);
    }
    std::fflush(stdout);
  }
  return 0;
}
