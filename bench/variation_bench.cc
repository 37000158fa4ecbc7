// What visual variation costs a pixel step: each task plain, its -distracting variant (colours,
// camera, the procedural background and see-through floor), the plain task with every factor at
// 0.3 (light and floor and sky colours too) and procedural floor and sky images, and the plain
// task observing two cameras ("pixels/<a>", "pixels/<b>") instead of one. All in one process, in
// turn, blocks of `block` steps each, round after round, so drift on a shared machine hits all
// alike; episodes end and reset as in training (so the per-episode work of variation counts);
// the time is the thread's CPU time and each figure the median over rounds of its microseconds
// per step.
//
// usage: variation_bench [rounds] [block] [size]
// Prints a line per task and configuration: microseconds per step (median) and its ratio to the
// plain step's (the median of the rounds' ratios).
#include <time.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rollout.h"

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
  std::unique_ptr<pixelgym::Env> env;
  std::unique_ptr<pixelgym::RandomRollout> rollout;
  std::vector<double> micros_per_step;
};

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 9;
  const int block = argc > 2 ? std::atoi(argv[2]) : 300;
  const int size = argc > 3 ? std::atoi(argv[3]) : 84;
  // Each task with two of its cameras for the two-camera configuration.
  const std::vector<std::array<std::string, 3>> tasks = {
      {"CartPoleSwingup-v1", "fixed", "tracking"}, {"ReacherEasy-v1", "top", "angled"},
      {"CheetahRun-v0", "side", "back"},           {"FingerSpin-v0", "cam0", "cam1"},
      {"BallInCupCatch-v0", "cam0", "cam1"},       {"WalkerWalk-v0", "side", "back"}};
  std::printf(
      "step() with seeded random actions at %dx%d, episodes reset as they end; thread CPU time, "
      "medians of %d rounds of %d steps\n",
      size, size, rounds, block);
  for (const auto& [id, camera_a, camera_b] : tasks) {
    const pixelgym::Params base = {{"width", size}, {"height", size}};
    const std::string variant =
        id.substr(0, id.rfind("-v")) + "-distracting" + id.substr(id.rfind("-v"));
    pixelgym::Params every = base;
    every.emplace("variation", 0.3);
    every.emplace("sky_texture", "noise");
    every.emplace("floor_texture", "noise");
    pixelgym::Params two = base;
    two.emplace("cameras", camera_a + "," + camera_b);
    std::vector<Config> configs;
    for (auto& [name, env_id, kwargs] :
         std::vector<std::tuple<std::string, std::string, pixelgym::Params>>{
             {"plain", id, base},
             {"distracting (0.2)", variant, base},
             {"every factor 0.3, noise floor and sky", id, every},
             {"two cameras", id, two}}) {
      Config config;
      config.name = name;
      config.env = pixelgym::make(env_id, kwargs);
      config.rollout = std::make_unique<pixelgym::RandomRollout>(*config.env, /*seed=*/0);
      for (int t = 0; t < 50; ++t) config.rollout->step();  // warm up: shaders, meshes, caches
      configs.push_back(std::move(config));
    }
    std::vector<std::vector<double>> ratios(configs.size());
    for (int round = 0; round < rounds; ++round) {
      for (Config& config : configs) {
        const double start = thread_seconds();
        for (int t = 0; t < block; ++t) config.rollout->step();
        config.micros_per_step.push_back((thread_seconds() - start) * 1e6 / block);
      }
      for (std::size_t c = 0; c < configs.size(); ++c) {
        ratios[c].push_back(configs[c].micros_per_step.back() / configs[0].micros_per_step.back());
      }
    }
    for (std::size_t c = 0; c < configs.size(); ++c) {
      std::printf("%-20s %-40s us_per_step=%8.1f ratio=%.3f\n", id.c_str(), configs[c].name.c_str(),
                  median(configs[c].micros_per_step), median(ratios[c]));
    }
  }
  return 0;
}
