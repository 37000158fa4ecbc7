// drqv2_bench: where one DrQ-v2 update's time goes (sampling, augmentation, encoder forward,
// critic, backward, actor, target update), its medians over many updates, and its FLOP rate
// against this CPU's FP32 peak. A replay buffer of random frames stands in for an env's.
//
//   drqv2_bench [--size 64] [--encoder drqv2|mrq|fine] [--batch 256] [--stack 3] [--channels 3]
//               [--updates 30] [--hidden 1024] [--threads 0] [--bfloat16] [--channels-last]
#include <ATen/CPUGeneratorImpl.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "examples/trainer/drqv2/drqv2.h"
#include "examples/trainer/torch_common/torch_state.h"
#include "pixelgym/trainer/process_tuning.h"

namespace {

using pixelgym::drqv2::DrqV2Config;
using pixelgym::drqv2::EncoderArchitecture;
using pixelgym::drqv2::InputLayout;
using pixelgym::drqv2::Learner;
using pixelgym::drqv2::ObservationView;
using pixelgym::drqv2::ReplayBatch;
using pixelgym::drqv2::ReplayBuffer;
using pixelgym::drqv2::UpdateTimes;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

// Multiply-adds of the encoder's convolutions for one sample, and of its first layer.
std::pair<double, double> conv_macs(const InputLayout& input, EncoderArchitecture encoder,
                                    std::int64_t* features) {
  const std::vector<std::int64_t> strides = pixelgym::drqv2::encoder_strides(encoder);
  std::int64_t channels = input.stack * input.channels, h = input.height, w = input.width;
  double total = 0.0, first = 0.0;
  for (const std::int64_t stride : strides) {
    h = (h - 3) / stride + 1;
    w = (w - 3) / stride + 1;
    const double macs = static_cast<double>(h * w * 32 * channels * 9);
    if (total == 0.0) first = macs;
    total += macs;
    channels = 32;
  }
  *features = channels * h * w;
  return {total, first};
}

// FP32 FLOPs per cycle per core: 2 FMA pipes of 16 floats with AVX-512, of 8 with AVX2.
double cpu_peak_gflops(int threads) {
  std::ifstream cpuinfo("/proc/cpuinfo");
  std::string line;
  double mhz = 0.0;
  bool avx512 = false;
  while (std::getline(cpuinfo, line)) {
    if (line.rfind("cpu MHz", 0) == 0 && mhz == 0.0)
      mhz = std::stod(line.substr(line.find(':') + 1));
    if (line.rfind("flags", 0) == 0) avx512 = line.find(" avx512f") != std::string::npos;
  }
  const double flops_per_cycle = avx512 ? 64.0 : 32.0;
  return threads * flops_per_cycle * mhz / 1000.0;
}

}  // namespace

int main(int argc, char** argv) {
  std::int64_t size = 64, batch = 256, stack = 3, channels = 3, updates = 30;
  int threads = 0;
  DrqV2Config config;
  config.bfloat16 = false;
  config.channels_last = false;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "drqv2_bench: " << arg << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--size")
      size = std::stoll(next());
    else if (arg == "--encoder")
      config.encoder = pixelgym::drqv2::parse_encoder_architecture(next());
    else if (arg == "--batch")
      batch = std::stoll(next());
    else if (arg == "--stack")
      stack = std::stoll(next());
    else if (arg == "--channels")
      channels = std::stoll(next());
    else if (arg == "--updates")
      updates = std::stoll(next());
    else if (arg == "--hidden")
      config.hidden_dim = std::stoll(next());
    else if (arg == "--threads")
      threads = std::stoi(next());
    else if (arg == "--bfloat16")
      config.bfloat16 = true;
    else if (arg == "--channels-last")
      config.channels_last = true;
    else {
      std::cerr
          << "drqv2_bench: unknown argument " << arg
          << " (--size, --encoder, --batch, --stack, --channels, --updates, --hidden, --threads, "
             "--bfloat16, --channels-last)\n";
      return 2;
    }
  }
  pixelgym::trainer::tune_process_for_training();  // as `pixelgym train`: OpenBLAS on 1 thread
  threads = pixelgym::trainer::set_torch_threads(threads);
  config.batch_size = batch;
  config.frame_stack = stack;
  InputLayout input;
  input.has_image = true;
  input.image_key = "pixels";
  input.stack = stack;
  input.height = size;
  input.width = size;
  input.channels = channels;
  input.action_size = 1;
  input.action_low = {-1.0f};
  input.action_high = {1.0f};
  Learner learner(input, config);
  const bool bf16 = learner.agent().autocast();

  // Episodes of 125 steps of random frames (a frame repeated within a stack at the start).
  const std::int64_t frame = size * size * channels;
  ReplayBuffer buffer(input.replay_layout(), 1, 20000, config.n_step, config.gamma);
  std::mt19937_64 rng(0);
  std::vector<std::uint8_t> stacked(static_cast<std::size_t>(stack * frame));
  std::vector<std::vector<std::uint8_t>> history;
  const auto observation = [&](bool first) {
    std::vector<std::uint8_t> newest(static_cast<std::size_t>(frame));
    for (auto& byte : newest) byte = static_cast<std::uint8_t>(rng());
    if (first)
      history.assign(static_cast<std::size_t>(stack), newest);
    else {
      history.erase(history.begin());
      history.push_back(newest);
    }
    for (std::int64_t d = 0; d < stack; ++d) {
      std::copy(history[d].begin(), history[d].end(), stacked.begin() + d * frame);
    }
    return ObservationView{{stacked.data()}, {}};
  };
  buffer.add_first(0, observation(true));
  for (int t = 0; t < 5000; ++t) {
    const float action = 0.0f;
    const bool end = t % 125 == 124;
    buffer.add_step(0, &action, 1.0, false, end, observation(false));
    if (end) buffer.add_first(0, observation(true));
  }

  at::Generator augmentation = at::detail::createCPUGenerator(1);
  at::Generator noise = at::detail::createCPUGenerator(2);
  ReplayBatch samples;
  std::vector<UpdateTimes> laps;
  std::vector<double> totals;
  for (std::int64_t u = 0; u < updates + 3; ++u) {
    UpdateTimes times;
    const auto start = std::chrono::steady_clock::now();
    buffer.sample(batch, rng, samples);
    times.sample = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    learner.update(samples, 100000, augmentation, noise, &times);
    const double total =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (u < 3) continue;  // warm-up
    laps.push_back(times);
    totals.push_back(total);
  }
  const auto phase = [&](double UpdateTimes::*member) {
    std::vector<double> values;
    for (const UpdateTimes& t : laps) values.push_back(t.*member);
    return median(values) * 1e3;
  };

  std::int64_t features = 0;
  const auto [conv, first] = conv_macs(input, config.encoder, &features);
  const double trunk = static_cast<double>(features * config.feature_dim);
  const double hidden = static_cast<double>(config.hidden_dim);
  const double q = (config.feature_dim + 1) * hidden + hidden * hidden + hidden;
  const double actor = config.feature_dim * hidden + hidden * hidden + hidden;
  // Encoder: forward on obs and next obs, backward on obs (no input gradient for the first
  // layer); trunks 9 passes, Q networks 14, actor head 4 (see docs/training.md).
  const double macs =
      static_cast<double>(batch) * (4.0 * conv - first + 9.0 * trunk + 14.0 * q + 4.0 * actor);
  const double total_ms = median(totals) * 1e3;
  const double gflops = 2.0 * macs / (total_ms * 1e-3) / 1e9;
  const double peak = cpu_peak_gflops(threads);
  std::cout << std::fixed << std::setprecision(1) << "drqv2_bench: " << size << "x" << size << "x"
            << channels << " stack " << stack << ", encoder "
            << pixelgym::drqv2::to_string(config.encoder) << " (" << conv / 1e6
            << "M multiply-adds/sample, " << features << " features), batch " << batch << ", "
            << threads << " threads, bfloat16 " << (bf16 ? "on" : "off") << ", channels_last "
            << (config.channels_last ? "on" : "off") << "\n"
            << "update_ms=" << total_ms << " sample_ms=" << phase(&UpdateTimes::sample)
            << " augment_ms=" << phase(&UpdateTimes::augment)
            << " encode_ms=" << phase(&UpdateTimes::encode)
            << " critic_ms=" << phase(&UpdateTimes::critic)
            << " backward_ms=" << phase(&UpdateTimes::backward)
            << " actor_ms=" << phase(&UpdateTimes::actor)
            << " target_ms=" << phase(&UpdateTimes::target) << "\n"
            << "gflop_per_update=" << 2.0 * macs / 1e9 << " achieved_gflops=" << gflops
            << " fp32_peak_gflops=" << peak << " fraction_of_peak=" << std::setprecision(3)
            << gflops / peak << "\n";
  return 0;
}
