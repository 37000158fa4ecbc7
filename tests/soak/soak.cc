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
// The verdict: the resident size is sampled at every hundredth of the run, and the median of the
// samples in the last tenth is compared with the median of those in the tenth that follows
// warm-up (the first 10% of the steps, at least 10,000). A leak grows the one against the other;
// one sample alone may catch a clip being encoded and read back (tens of MiB that are freed a
// moment later), which medians leave out. Exits 0 when the growth is within --rss-growth-mib, 1
// when it is more, 2 for bad arguments. Under AddressSanitizer the sizes are printed but not
// judged: its quarantine holds freed memory back on purpose (LeakSanitizer checks leaks there).
//
// glibc caches memory in two ways that read as growth here, though neither is a leak. It keeps the
// stacks of ended threads for reuse, up to 40 MiB, resident; the H.264 encoder and decoder start
// threads for every clip (OpenCV 4.6 offers no way to stop them). And after a large block is
// freed it raises its mmap threshold, so later large blocks (the codecs' frame buffers) come from
// the heap, which keeps its high-water mark. Both level off once enough clips have overlapped,
// after a number of clips that varies from run to run (docs/reliability.md). So unless
// --glibc default is given, the soak runs itself again with glibc.pthread.stack_cache_size=0 and
// glibc.malloc.mmap_threshold=131072 (each unless GLIBC_TUNABLES already sets it), and what it
// measures is the memory pixelgym and its libraries hold.
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/wrappers/record_video.h"
#include "pixelgym/wrappers/wrapper_spec.h"

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
  bool glibc_default = false;
};

[[noreturn]] void usage(const std::string& problem) {
  std::cerr << "soak: " << problem
            << "\nusage: soak [--steps N] [--num-envs N] [--threads N] [--env ID] "
               "[--video-every EPISODES] [--video-folder DIR] [--rss-growth-mib MIB] "
               "[--glibc tuned|default]\n";
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
      } else if (flag == "--glibc") {
        if (value != "tuned" && value != "default") {
          usage("--glibc expects tuned or default, got \"" + value + "\"");
        }
        options.glibc_default = value == "default";
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

// Runs this program again with glibc's caches tuned (see the top of the file); returns only when
// GLIBC_TUNABLES already sets both.
void run_with_glibc_tuned(char** argv) {
  const char* given = std::getenv("GLIBC_TUNABLES");
  std::string tunables = given != nullptr ? given : "";
  bool added = false;
  for (const char* tunable :
       {"glibc.pthread.stack_cache_size=0", "glibc.malloc.mmap_threshold=131072"}) {
    const std::string name = std::string(tunable).substr(0, std::strcspn(tunable, "="));
    if (tunables.find(name) != std::string::npos) continue;
    tunables += (tunables.empty() ? "" : ":") + std::string(tunable);
    added = true;
  }
  if (!added) return;
  setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
  ::execv("/proc/self/exe", argv);
  std::cerr << "soak: cannot run itself again with GLIBC_TUNABLES=" << tunables << ": "
            << std::strerror(errno) << "\n";
  std::exit(1);
}

struct Sample {
  std::int64_t steps;
  double rss_mib;
};

// The median resident size of the samples taken after `from` steps, up to and including `to`.
double median_rss(const std::vector<Sample>& samples, std::int64_t from, std::int64_t to) {
  std::vector<double> window;
  for (const Sample& sample : samples) {
    if (sample.steps > from && sample.steps <= to) window.push_back(sample.rss_mib);
  }
  if (window.empty()) return 0;
  std::sort(window.begin(), window.end());
  const std::size_t middle = window.size() / 2;
  return window.size() % 2 == 1 ? window[middle] : (window[middle - 1] + window[middle]) / 2;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pixelgym;  // NOLINT(google-build-using-namespace): a program's main
  const SoakOptions options = parse(argc, argv);
  if (!options.glibc_default) run_with_glibc_tuned(argv);
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
  std::vector<Sample> samples;
  const std::int64_t sample_every = std::max<std::int64_t>(1, options.steps / 100);
  std::int64_t next_sample = sample_every;
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
    if (steps >= next_sample) {
      samples.push_back({steps, resident_mib()});
      next_sample += sample_every;
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
  std::printf(
      "done: %lld env steps, %lld episodes, %lld clips in %s; resident %.1f MiB, %+.1f MiB "
      "since warm-up (%lld steps)\n",
      static_cast<long long>(steps), static_cast<long long>(episodes),
      static_cast<long long>(clips), options.video_folder.c_str(), rss, rss - rss_after_warmup,
      static_cast<long long>(warmup));
  const std::int64_t tenth = std::max<std::int64_t>(1, options.steps / 10);
  const double early = median_rss(samples, warmup, warmup + tenth);
  const double late = median_rss(samples, options.steps - tenth, options.steps);
  const double grown = late - early;
  std::printf(
      "median resident size after warm-up (env steps %lld-%lld): %.1f MiB; over the last tenth "
      "(env steps %lld-%lld): %.1f MiB; %+.1f MiB (GLIBC_TUNABLES=%s)\n",
      static_cast<long long>(warmup), static_cast<long long>(warmup + tenth), early,
      static_cast<long long>(options.steps - tenth), static_cast<long long>(options.steps), late,
      grown, std::getenv("GLIBC_TUNABLES") != nullptr ? std::getenv("GLIBC_TUNABLES") : "");
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
