// Pixel envs stepped from several threads, as the vector envs step them: each env (its own Bullet
// world and GL context) on one thread at a time, concurrently with the others, sometimes made,
// moved or destroyed on another thread. Every test compares observations, rewards, flags and
// render() frames byte for byte with the same envs, seeds and actions stepped on one thread.
#include <gtest/gtest.h>

#include <cstdint>
#include <future>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "tests/worker_thread.h"

namespace pixelgym {
namespace {

using testing::WorkerThread;

constexpr int kSteps = 24;

// Small images keep the test quick under ThreadSanitizer.
Params small_images() {
  return {{"width", 24}, {"height", 24}, {"render_width", 24}, {"render_height", 24}};
}

struct Case {
  std::string id;
  std::uint64_t seed;
};

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {{"CartPoleSwingup-v0", 10},
                                        {"ArmReach-v0", 11},
                                        {"CartPoleSwingup-v0", 12},
                                        {"ArmReach-v0", 13}};
  return all;
}

// What an env returned: the observations (copied), rewards, flags and a frame every 8 steps.
struct Trace {
  std::vector<Value> obs;
  std::vector<double> rewards;
  std::vector<int> flags;
  std::vector<Array> frames;
};

void expect_same(const Trace& got, const Trace& expected, const std::string& what) {
  ASSERT_EQ(got.obs.size(), expected.obs.size()) << what;
  for (std::size_t i = 0; i < got.obs.size(); ++i)
    EXPECT_TRUE(got.obs[i].equals(expected.obs[i])) << what << ": observation " << i;
  EXPECT_EQ(got.rewards, expected.rewards) << what;
  EXPECT_EQ(got.flags, expected.flags) << what;
  ASSERT_EQ(got.frames.size(), expected.frames.size()) << what;
  for (std::size_t i = 0; i < got.frames.size(); ++i)
    EXPECT_TRUE(got.frames[i].equals(expected.frames[i])) << what << ": frame " << i;
}

// The env of case `c` with its actions drawn up front (the same on every thread).
struct Episode {
  explicit Episode(const Case& c) : env(make(c.id, small_images())), seed(c.seed) {
    Rng rng(c.seed + 1000);
    for (int t = 0; t < kSteps; ++t) actions.push_back(env->action_space().sample(rng));
  }
  // Resets (seeded) when `from` is 0, then steps [from, to), resetting after a done.
  void steps(int from, int to) {
    if (from == 0) trace.obs.push_back(env->reset(seed).obs.clone());
    for (int t = from; t < to; ++t) {
      const StepResult result = env->step(actions[static_cast<std::size_t>(t)]);
      trace.obs.push_back(result.obs.clone());
      trace.rewards.push_back(result.reward);
      trace.flags.push_back((result.terminated ? 1 : 0) + (result.truncated ? 2 : 0));
      if (t % 8 == 0) trace.frames.push_back(env->render());
      if (result.terminated || result.truncated) trace.obs.push_back(env->reset().obs.clone());
    }
  }
  std::unique_ptr<Env> env;
  std::uint64_t seed;
  std::vector<Value> actions;
  Trace trace;
};

// Every case stepped on this thread, one env after the other.
std::vector<Trace> sequential() {
  std::vector<Trace> traces;
  for (const Case& c : cases()) {
    Episode run(c);
    run.steps(0, kSteps);
    traces.push_back(run.trace);
  }
  return traces;
}

TEST(EnvThreadsTest, EnvsSteppedConcurrentlyOnTheirOwnThreadsMatchOneThread) {
  const std::vector<Trace> expected = sequential();
  std::vector<Trace> got(cases().size());
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < cases().size(); ++i) {
    threads.emplace_back([i, &got] {
      Episode run(cases()[i]);  // made, stepped and destroyed on this thread
      run.steps(0, kSteps);
      got[i] = run.trace;
    });
  }
  for (std::thread& thread : threads) thread.join();
  for (std::size_t i = 0; i < cases().size(); ++i) expect_same(got[i], expected[i], cases()[i].id);
}

TEST(EnvThreadsTest, EnvsMadeOnOneThreadAndSteppedOnOthersMatchOneThread) {
  const std::vector<Trace> expected = sequential();
  std::vector<std::unique_ptr<Episode>> runs;
  for (const Case& c : cases()) {
    runs.push_back(std::make_unique<Episode>(c));
    runs.back()->env->reset(0);  // the renderer (its GL context) is made here, on this thread
  }
  std::vector<std::thread> threads;
  for (auto& run : runs) threads.emplace_back([&run] { run->steps(0, kSteps); });
  for (std::thread& thread : threads) thread.join();
  for (std::size_t i = 0; i < runs.size(); ++i) {
    expect_same(runs[i]->trace, expected[i], cases()[i].id);
  }
  runs.clear();  // destroyed here, after other threads drew with their contexts
}

TEST(EnvThreadsTest, EnvsMovedBetweenLongLivedThreadsMatchOneThread) {
  const std::vector<Trace> expected = sequential();
  // Two workers that outlive the envs; every third of the episode the envs change workers, so
  // each worker steps one env, then another, while the other worker steps the first (a pool's
  // pattern), and the main thread steps them in between.
  WorkerThread a;
  WorkerThread b;
  std::vector<std::unique_ptr<Episode>> runs;
  for (const Case& c : cases()) runs.push_back(std::make_unique<Episode>(c));
  const int third = kSteps / 3;
  for (int part = 0; part < 3; ++part) {
    const int from = part * third;
    const int to = part == 2 ? kSteps : from + third;
    std::vector<std::future<void>> done;
    for (std::size_t i = 0; i < runs.size(); ++i) {
      Episode& run = *runs[i];
      if (part == 1 && i == 0) {
        run.steps(from, to);  // one env takes its middle third on the main thread
        continue;
      }
      WorkerThread& worker = (i + static_cast<std::size_t>(part)) % 2 == 0 ? a : b;
      done.push_back(worker.start([&run, from, to] { run.steps(from, to); }));
    }
    for (std::future<void>& d : done) d.get();
  }
  for (std::size_t i = 0; i < runs.size(); ++i)
    expect_same(runs[i]->trace, expected[i], cases()[i].id);
}

TEST(EnvThreadsTest, AnEnvDestroyedOffTheThreadThatSteppedItLeavesThatThreadUsable) {
  const std::vector<Trace> expected = sequential();
  WorkerThread worker;
  for (std::size_t i = 0; i < cases().size(); ++i) {
    // Made here, stepped on the worker, destroyed here; the worker then steps the next env.
    auto run = std::make_unique<Episode>(cases()[i]);
    worker.run([&run] { run->steps(0, kSteps); });
    expect_same(run->trace, expected[i], cases()[i].id);
    run.reset();
  }
}

}  // namespace
}  // namespace pixelgym
