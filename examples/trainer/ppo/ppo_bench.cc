// ppo_bench: forward and forward + backward throughput of the policy's CNNs on a CPU, for picking
// the default architecture. Not a test (timings never are): run it by hand.
//
//   ppo_bench [--threads 2] [--batch 256] [--seconds 3]
//
// The process is set up as `pixelgym train` sets it up (trainer::tune_process_for_training).
// For each CNN (nature, small, fine, finer) and image size (64x64, 84x84), a Policy over a
// uint8 (9, H, W) image (3 stacked RGB frames, channel-first) with a 1-D Box action: samples per
// second of
//   act:    Policy::act without gradients (what collecting a rollout costs per observation);
//   train:  Policy::evaluate + a PPO-like loss + backward + Adam step (what an update costs per
//           sample per epoch).
#include <torch/torch.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <string>

#include "examples/trainer/ppo/policy.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/trainer/process_tuning.h"

namespace {

using pixelgym::DType;
using Clock = std::chrono::steady_clock;

double run_for(double seconds, const std::function<void()>& body) {
  body();  // warm-up
  int iterations = 0;
  const auto start = Clock::now();
  double elapsed = 0.0;
  while (elapsed < seconds) {
    body();
    ++iterations;
    elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  }
  return elapsed / iterations;
}

}  // namespace

int main(int argc, char** argv) {
  // As pixelgym train runs (OpenBLAS on one thread beside torch's, freed memory kept).
  pixelgym::trainer::tune_process_for_training();
  int threads = 2;
  std::int64_t batch = 256;
  double seconds = 3.0;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (std::strcmp(argv[i], "--threads") == 0)
      threads = std::atoi(argv[i + 1]);
    else if (std::strcmp(argv[i], "--batch") == 0)
      batch = std::atoll(argv[i + 1]);
    else if (std::strcmp(argv[i], "--seconds") == 0)
      seconds = std::atof(argv[i + 1]);
    else {
      std::fprintf(stderr, "usage: ppo_bench [--threads N] [--batch B] [--seconds S]\n");
      return 2;
    }
  }
  torch::set_num_threads(threads);
  torch::manual_seed(0);
  std::printf("threads %d, batch %lld; samples per second (ms per batch)\n", threads,
              static_cast<long long>(batch));
  std::printf("%-8s %-6s %10s %16s %16s\n", "cnn", "size", "params", "act", "train");
  for (auto architecture :
       {pixelgym::ppo::CnnArchitecture::kNature, pixelgym::ppo::CnnArchitecture::kSmall,
        pixelgym::ppo::CnnArchitecture::kFine, pixelgym::ppo::CnnArchitecture::kFiner}) {
    for (std::int64_t size : {64, 84}) {
      pixelgym::spaces::Box observation_space(0, 255, {9, size, size}, DType::kUInt8);
      pixelgym::spaces::Box action_space(-1, 1, {1});
      pixelgym::ppo::PolicyConfig config;
      config.cnn = architecture;
      pixelgym::ppo::Policy policy(observation_space, action_space, config);
      torch::optim::Adam optimizer(policy.parameters(), torch::optim::AdamOptions(2.5e-4));
      std::int64_t parameters = 0;
      for (const auto& p : policy.parameters()) parameters += p.numel();
      pixelgym::ppo::ObservationTensors obs{
          {"", torch::randint(0, 256, {batch, 9, size, size}, torch::kUInt8)}};
      const double act = run_for(seconds, [&] {
        torch::NoGradGuard no_grad;
        policy.act(obs, false);
      });
      torch::Tensor actions = torch::randn({batch, 1});
      const double train = run_for(seconds, [&] {
        const auto e = policy.evaluate(obs, actions);
        const auto loss =
            -(e.log_prob.exp()).mean() + 0.5 * e.value.pow(2).mean() - 0.01 * e.entropy.mean();
        optimizer.zero_grad();
        loss.backward();
        optimizer.step();
      });
      std::printf("%-8s %lldx%-3lld %10lld %9.0f (%5.1f) %9.0f (%5.1f)\n",
                  pixelgym::ppo::to_string(architecture), static_cast<long long>(size),
                  static_cast<long long>(size), static_cast<long long>(parameters),
                  static_cast<double>(batch) / act, act * 1e3, static_cast<double>(batch) / train,
                  train * 1e3);
      std::fflush(stdout);
    }
  }
  return 0;
}
