// The cost of wrappers over a bare pixel step, measured in one process: the bare env and each
// wrapped one (each its own env, Bullet world and GL context) step in turn, blocks of `block`
// steps each, round after round, so drift on a shared machine hits all alike; the time is the
// thread's CPU time (so another process taking the core does not count) and each configuration's
// figure is the median over rounds of its microseconds per step.
//
// usage: wrappers_bench [ID] [rounds] [block]
// Prints one line per configuration: microseconds per step (median), the overhead over the bare
// step in microseconds and as a share of it, and a last line `overhead_stack_pct=` for
// resize=64x64 + grayscale + frame_stack=3.
#include <time.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rollout.h"
#include "pixelgym/wrappers/wrapper_spec.h"

namespace {

double thread_seconds() {
  timespec now{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
  return static_cast<double>(now.tv_sec) + 1e-9 * static_cast<double>(now.tv_nsec);
}

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

struct Config {
  std::string name;
  std::vector<std::string> wraps;
  std::unique_ptr<pixelgym::Env> env;
  std::unique_ptr<pixelgym::RandomRollout> rollout;
  std::vector<double> micros_per_step;
};

}  // namespace

int main(int argc, char** argv) {
  const std::string id = argc > 1 ? argv[1] : "CartPoleSwingup-v0";
  const int rounds = argc > 2 ? std::atoi(argv[2]) : 15;
  const int block = argc > 3 ? std::atoi(argv[3]) : 500;
  std::vector<Config> configs;
  const std::vector<std::pair<std::string, std::vector<std::string>>> stacks = {
      {"bare", {}},
      {"resize=64x64", {"resize=64x64"}},
      {"grayscale", {"grayscale"}},
      {"frame_stack=3", {"frame_stack=3"}},
      {"resize=64x64 + grayscale + frame_stack=3", {"resize=64x64", "grayscale", "frame_stack=3"}},
      {"grayscale + resize=64x64 + frame_stack=3", {"grayscale", "resize=64x64", "frame_stack=3"}},
  };
  for (const auto& [name, wraps] : stacks) {
    Config config;
    config.name = name;
    config.wraps = wraps;
    config.env = pixelgym::wrappers::apply_wrappers(pixelgym::make(id), wraps);
    config.rollout = std::make_unique<pixelgym::RandomRollout>(*config.env, /*seed=*/0);
    for (int t = 0; t < 50; ++t) config.rollout->step();  // warm up: shaders, tapes, caches
    configs.push_back(std::move(config));
  }
  for (int round = 0; round < rounds; ++round) {
    for (Config& config : configs) {
      const double start = thread_seconds();
      for (int t = 0; t < block; ++t) config.rollout->step();
      config.micros_per_step.push_back((thread_seconds() - start) * 1e6 / block);
    }
  }
  const double bare = median(configs[0].micros_per_step);
  std::printf(
      "%s, step() with seeded random actions, thread CPU time, medians of %d rounds of "
      "%d steps\n",
      id.c_str(), rounds, block);
  std::printf("  %-44s %10s %10s %9s\n", "wrappers", "us/step", "+us", "overhead");
  double stack = 0.0;
  for (const Config& config : configs) {
    const double micros = median(config.micros_per_step);
    const double overhead = (micros / bare - 1.0) * 100.0;
    if (config.name == stacks[4].first) stack = overhead;
    std::printf("  %-44s %10.1f %10.1f %8.1f%%\n", config.name.c_str(), micros, micros - bare,
                overhead);
  }
  std::printf("overhead_stack_pct=%.1f\n", stack);
  return 0;
}
