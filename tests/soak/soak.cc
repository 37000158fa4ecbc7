// soak: steps a vector of pixel envs, wrapped and recording video, for a long time over many
// resets, and checks that resident memory stays flat after warm-up (issue 31). `make test` runs a
// short soak (ctest Soak.Short, 40,000 steps); the full one is
//   build/tests/soak/soak --steps 1000000
// and prints the resident set size at 10k, 100k and 1M env steps (docs/reliability.md).
//
// The envs: --num-envs copies of --env (pixels, 84x84) on --threads worker threads, each wrapped
// in record_episode_statistics, grayscale and frame_stack=3, episodes cut at 200 steps, and each
// records every --video-every-th of its episodes with RecordVideo into --video-folder. Actions are
// drawn from the action space. Every reward must be finite, and every clip recorded must be on
// disk.
//
// Exits 0 when the resident size after the last step is within --rss-growth-mib of the size after
// warm-up (the first 10% of the steps, at least 10,000), 1 when it grew more, 2 for bad
// arguments. Under AddressSanitizer the size is printed but not judged: its quarantine holds
// freed memory back on purpose (LeakSanitizer checks leaks there instead).
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "envs/vector/make_vec.h"
#include "wrappers/record_video.h"
#include "wrappers/wrapper_spec.h"

namespace {

#if defined(__SANITIZE_ADDRESS__)
constexpr bool kUnderAddressSanitizer = true;
#else
constexpr bool kUnderAddressSanitizer = false;
#endif

double resident_mib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0;
  long resident = 0;
  statm >> pages >> resident;
  return static_cast<double>(resident) * 4096.0 / (1 << 20);
}

struct SoakOptions {
  std::int64_t steps = 1000000;
  int num_envs = 4;
  int threads = 2;
  std::string env = "CartPoleSwingup-v0";
  std::int64_t video_every = 100;
  std::filesystem::path video_folder;
  double rss_growth_mib = 16;
};

[[noreturn]] void usage(const std::string& problem) {
  std::cerr << "soak: " << problem
            << "\nusage: soak [--steps N] [--num-envs N] [--threads N] [--env ID] "
               "[--video-every EPISODES] [--video-folder DIR] [--rss-growth-mib MIB]\n";
  std::exit(2);
}

SoakOptions parse(int argc, char** argv) {
  SoakOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string flag = argv[i];
    if (i + 1 >= argc) usage(flag + " needs a value");
    const std::string value = argv[++i];
    try {
      if (flag == "--steps") {
        options.steps = std::stoll(value);
      } else if (flag == "--num-envs") {
        options.num_envs = std::stoi(value);
      } else if (flag == "--threads") {
        options.threads = std::stoi(value);
      } else if (flag == "--env") {
        options.env = value;
      } else if (flag == "--video-every") {
        options.video_every = std::stoll(value);
      } else if (flag == "--video-folder") {
        options.video_folder = value;
      } else if (flag == "--rss-growth-mib") {
        options.rss_growth_mib = std::stod(value);
      } else {
        usage("unknown option " + flag);
      }
    } catch (const std::logic_error&) {
      usage(flag + " expects a number, got \"" + value + "\"");
    }
  }
  if (options.steps < 1 || options.num_envs < 1 || options.threads < 1 || options.video_every < 1)
    usage("--steps, --num-envs, --threads and --video-every must be >= 1");
  if (options.video_folder.empty()) {
    options.video_folder =
        std::filesystem::temp_directory_path() / ("pixelgym-soak-" + std::to_string(::getpid()));
  }
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixelgym;  // NOLINT(google-build-using-namespace): a program's main
  const SoakOptions options = parse(argc, argv);
  std::filesystem::remove_all(options.video_folder);

  const EnvWrapping wrap_all =
      wrappers::wrapping({"record_episode_statistics", "grayscale", "frame_stack=3"});
  std::atomic<int> built{0};
  const std::int64_t every = options.video_every;
  const EnvWrapping wrap = [&](std::unique_ptr<Env> env) {
    // Every env records, each under a prefix of its own (make_vec also wraps a stand-in first,
    // which is never stepped).
    const std::string prefix = "env" + std::to_string(built.fetch_add(1));
    return std::make_unique<wrappers::RecordVideo>(
        wrap_all(std::move(env)), options.video_folder,
        [every](std::int64_t episode) { return episode % every == 0; }, nullptr, 0, prefix);
  };
  vector::VectorOptions vector_options;
  vector_options.mode = vector::VectorMode::kAsync;
  vector_options.num_threads = options.threads;
  auto envs =
      vector::make_vec(options.env, options.num_envs,
                       {{"obs_mode", "pixels"}, {"max_episode_steps", 200}}, wrap, vector_options);
  envs->action_space().seed(0);
  envs->reset(std::uint64_t{0});

  const std::int64_t warmup = std::max<std::int64_t>(10000, options.steps / 10);
  // The resident size is printed at 10k, 100k and 1M env steps, after warm-up, at every tenth of
  // the run and at its end.
  std::vector<std::int64_t> milestones = {10000, 100000, 1000000, warmup, options.steps};
  for (int tenth = 1; tenth < 10; ++tenth) milestones.push_back(options.steps * tenth / 10);
  double rss_after_warmup = -1;
  std::int64_t episodes = 0;
  const auto start = std::chrono::steady_clock::now();
  std::int64_t steps = 0;
  while (steps < options.steps) {
    const vector::VectorStepResult& result = envs->step(envs->action_space().sample());
    steps += envs->num_envs();
    for (int i = 0; i < envs->num_envs(); ++i) {
      if (!std::isfinite(result.rewards.data<double>()[i])) {
        std::cerr << "soak: env " << i << " returned reward " << result.rewards.data<double>()[i]
                  << " at env step " << steps << "\n";
        return 1;
      }
      episodes += result.terminated.data<bool>()[i] || result.truncated.data<bool>()[i];
    }
    for (const std::int64_t milestone : milestones) {
      if (steps >= milestone && steps - envs->num_envs() < milestone) {
        const double rss = resident_mib();
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        std::printf("env steps %lld: resident %.1f MiB, %lld episodes, %.0f steps/s\n",
                    static_cast<long long>(steps), rss, static_cast<long long>(episodes),
                    static_cast<double>(steps) / seconds);
        std::fflush(stdout);
        if (milestone == warmup) rss_after_warmup = rss;
        break;
      }
    }
  }
  envs->close();
  std::int64_t clips = 0;
  for (const auto& entry : std::filesystem::directory_iterator(options.video_folder)) {
    if (entry.path().extension() != ".mp4" || entry.path().filename().string()[0] == '.') {
      std::cerr << "soak: " << entry.path() << " is not a finished clip\n";
      return 1;
    }
    ++clips;
  }
  const double rss = resident_mib();
  const double grown = rss - rss_after_warmup;
  std::printf(
      "done: %lld env steps, %lld episodes, %lld clips in %s; resident %.1f MiB, %+.1f MiB "
      "since warm-up (%lld steps)\n",
      static_cast<long long>(steps), static_cast<long long>(episodes),
      static_cast<long long>(clips), options.video_folder.c_str(), rss, grown,
      static_cast<long long>(warmup));
  if (clips == 0) {
    std::cerr << "soak: no clip was recorded\n";
    return 1;
  }
  std::filesystem::remove_all(options.video_folder);
  if (kUnderAddressSanitizer) {
    std::printf(
        "resident size not judged under AddressSanitizer (its quarantine keeps freed memory)\n");
    return 0;
  }
  if (grown > options.rss_growth_mib) {
    std::printf("FAILED: resident memory grew %.1f MiB after warm-up, more than %.1f\n", grown,
                options.rss_growth_mib);
    return 1;
  }
  return 0;
}
