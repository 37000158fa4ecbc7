// The all-reduce alone: the time of one GlooCommunicator::all_reduce_sum of N floats among the
// ranks, as PPO does after every minibatch (N: the policy's parameter count), without the
// waiting for a slower rank that a training run adds. Not a test: speed goes in benchmarks.
//
// usage: allreduce_bench [--nproc R] [FLOATS] [ITERATIONS]
//   --nproc R   start R local ranks (default 2), as `train --nproc` does; or run it as one rank
//               with WORLD_SIZE, RANK, MASTER_ADDR and MASTER_PORT set
//   FLOATS      elements per all-reduce (default 372787: make demo's policy)
//   ITERATIONS  timed all-reduces (default 200, after 20 untimed)
// Rank 0 prints the median, 10th and 90th percentile times and the bytes per second.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "examples/trainer/distributed/gloo_communicator.h"

int main(int argc, char** argv) {
  std::vector<std::string> arguments(argv, argv + argc);
  int nproc = 2;
  std::vector<std::string> rest;
  for (std::size_t i = 1; i < arguments.size(); ++i) {
    if (arguments[i] == "--nproc" && i + 1 < arguments.size()) {
      nproc = std::atoi(arguments[++i].c_str());
    } else {
      rest.push_back(arguments[i]);
    }
  }
  try {
    auto settings = pixelgym::distributed::DistributedSettings::from_environment(60.0, 60.0);
    if (!settings) {
      std::vector<std::string> child{arguments[0]};
      child.insert(child.end(), rest.begin(), rest.end());
      return pixelgym::distributed::run_local_ranks(nproc, child, 60.0, std::cerr);
    }
    const std::size_t floats = rest.size() > 0 ? std::stoul(rest[0]) : 372787;
    const int iterations = rest.size() > 1 ? std::stoi(rest[1]) : 200;
    pixelgym::distributed::GlooCommunicator communicator(*settings);
    std::vector<float> buffer(floats, 1.0f);
    std::vector<double> seconds;
    for (int i = -20; i < iterations; ++i) {
      const auto start = std::chrono::steady_clock::now();
      communicator.all_reduce_sum(buffer.data(), buffer.size(), "benchmark all-reduce");
      if (i >= 0) {
        seconds.push_back(
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
    }
    communicator.finish();
    if (communicator.rank() != 0) return 0;
    std::sort(seconds.begin(), seconds.end());
    const auto at = [&](double q) {
      return seconds[static_cast<std::size_t>(q * static_cast<double>(seconds.size() - 1))];
    };
    const double bytes = static_cast<double>(floats) * sizeof(float);
    std::cout << "ranks=" << communicator.world_size() << " floats=" << floats << " bytes=" << bytes
              << " iterations=" << iterations << " median_ms=" << at(0.5) * 1e3
              << " p10_ms=" << at(0.1) * 1e3 << " p90_ms=" << at(0.9) * 1e3
              << " MB_per_s=" << bytes / at(0.5) / 1e6 << "\n";
    return 0;
  } catch (const std::exception& error) {
    std::cerr << "allreduce_bench: " << error.what() << "\n";
    return 1;
  }
}
