// The buffer path allocates nothing per step once warmed up, for every registered env.
//
// This test binary replaces the C allocator (malloc, calloc, realloc, the aligned forms; glibc
// lets an executable define them and forward to __libc_*) and, on top of it, the global
// operator new. So it sees every heap allocation of the process: pixelgym's own code, the C++
// standard library, Eigen (which allocates with malloc), Bullet (btAlignedAlloc -> malloc) and
// Mesa. Counting is switched on only around the steps measured.
//
// Two libraries malloc inside calls no caller can avoid, so each counted malloc is attributed by
// its call stack:
// - Mesa's llvmpipe mallocs while it draws (about 20-40 blocks per frame here: state validation
//   and draw setup inside libOSMesa): a stack with a frame in libOSMesa, libLLVM, libgallium or
//   libglapi is Mesa's.
// - Bullet mallocs when a pair of compound collision shapes starts to overlap (its dispatcher
//   creates a btCompoundCollisionAlgorithm, freed when the pair separates, so this never settles
//   in a task whose contacts come and go) and when its solver arrays grow for constraint rows
//   not seen before: a stack with a frame in libBullet* (collision, dynamics) is Bullet's; one
//   that reaches Bullet's allocator (libLinearMath) only from pixelgym's code is pixelgym's.
// Every other malloc is pixelgym's own (with the C++ library and Eigen, which are inlined into
// it), and operator new is counted on its own: both must be zero. Mesa's and Bullet's counts are
// printed.
#include <dlfcn.h>
#include <execinfo.h>
#include <gtest/gtest.h>

#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <new>

#include "envs/pixel_env.h"
#include "envs/registry.h"
#include "tests/envs/env_ids.h"

namespace {

std::atomic<bool> g_counting{false};
std::atomic<long> g_mallocs{0};         // pixelgym's own: neither Mesa's nor Bullet's
std::atomic<long> g_mesa_mallocs{0};    // with a frame inside Mesa's libraries
std::atomic<long> g_bullet_mallocs{0};  // with a frame inside Bullet's (and none in Mesa's)
std::atomic<long> g_news{0};
thread_local bool t_in_hook = false;

enum class Owner { kPixelgym, kMesa, kBullet };

Owner owner_of(void* const* frames, int depth) {
  Owner owner = Owner::kPixelgym;
  for (int i = 0; i < depth; ++i) {
    Dl_info info;
    if (dladdr(frames[i], &info) == 0 || info.dli_fname == nullptr) continue;
    const char* name = info.dli_fname;
    if (std::strstr(name, "libOSMesa") != nullptr || std::strstr(name, "libLLVM") != nullptr ||
        std::strstr(name, "libgallium") != nullptr || std::strstr(name, "libglapi") != nullptr) {
      return Owner::kMesa;
    }
    // Bullet's collision and dynamics code, not LinearMath: btAlignedObjectArray growth called
    // from pixelgym's own code passes through libLinearMath too, and that is pixelgym's.
    if (std::strstr(name, "libBullet") != nullptr) owner = Owner::kBullet;
  }
  return owner;
}

void count_malloc() {
  if (!g_counting.load(std::memory_order_relaxed) || t_in_hook) return;
  t_in_hook = true;
  void* frames[64];
  const int depth = backtrace(frames, 64);
  switch (owner_of(frames, depth)) {
    case Owner::kMesa:
      g_mesa_mallocs.fetch_add(1);
      break;
    case Owner::kBullet:
      g_bullet_mallocs.fetch_add(1);
      break;
    case Owner::kPixelgym:
      g_mallocs.fetch_add(1);
      break;
  }
  t_in_hook = false;
}

// backtrace() loads libgcc's unwinder (allocating) on its first call: do that before counting.
const bool g_unwinder_loaded = [] {
  void* frames[4];
  return backtrace(frames, 4) > 0;
}();

}  // namespace

extern "C" {
void* __libc_malloc(std::size_t size);
void* __libc_calloc(std::size_t count, std::size_t size);
void* __libc_realloc(void* pointer, std::size_t size);
void* __libc_memalign(std::size_t alignment, std::size_t size);
void __libc_free(void* pointer);

void* malloc(std::size_t size) {
  count_malloc();
  return __libc_malloc(size);
}
void* calloc(std::size_t count, std::size_t size) {
  count_malloc();
  return __libc_calloc(count, size);
}
void* realloc(void* pointer, std::size_t size) {
  count_malloc();
  return __libc_realloc(pointer, size);
}
void* memalign(std::size_t alignment, std::size_t size) {
  count_malloc();
  return __libc_memalign(alignment, size);
}
void* aligned_alloc(std::size_t alignment, std::size_t size) {
  count_malloc();
  return __libc_memalign(alignment, size);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t size) {
  count_malloc();
  *out = __libc_memalign(alignment, size);
  return *out == nullptr ? ENOMEM : 0;
}
void free(void* pointer) { __libc_free(pointer); }
}

void* operator new(std::size_t size) {
  if (g_counting.load(std::memory_order_relaxed)) g_news.fetch_add(1);
  if (void* pointer = std::malloc(size == 0 ? 1 : size)) return pointer;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size) { return operator new(size); }
void operator delete(void* pointer) noexcept { std::free(pointer); }
void operator delete[](void* pointer) noexcept { std::free(pointer); }
void operator delete(void* pointer, std::size_t) noexcept { std::free(pointer); }
void operator delete[](void* pointer, std::size_t) noexcept { std::free(pointer); }

namespace pixelgym {
namespace {

struct Counts {
  long news;            // operator new
  long mallocs;         // the C allocator, pixelgym's own (operator new included)
  long mesa_mallocs;    // the C allocator, inside Mesa
  long bullet_mallocs;  // the C allocator, inside Bullet
};

// Steps `env` through the buffer path for `steps` steps with pre-drawn actions, resetting (into
// the same buffer) when an episode ends, and returns the allocations counted during the steps.
Counts count_step_allocations(Env& env, int warmup_steps, int steps) {
  ResetResult reset;
  reset.obs = env.observation_space().zeros();
  env.reset_into(reset, /*seed=*/0);
  StepResult step;
  step.obs = env.observation_space().zeros();
  Rng rng(1);
  std::vector<Value> actions;
  for (int i = 0; i < warmup_steps + steps; ++i) actions.push_back(env.action_space().sample(rng));
  Counts counts{0, 0, 0, 0};
  for (int i = 0; i < warmup_steps + steps; ++i) {
    const bool measured = i >= warmup_steps;
    g_mallocs = 0;
    g_mesa_mallocs = 0;
    g_bullet_mallocs = 0;
    g_news = 0;
    g_counting = measured;
    env.step_into(actions[static_cast<std::size_t>(i)], step);
    g_counting = false;
    counts.news += g_news;
    counts.mallocs += g_mallocs;
    counts.mesa_mallocs += g_mesa_mallocs;
    counts.bullet_mallocs += g_bullet_mallocs;
    if (step.terminated || step.truncated) env.reset_into(reset);  // not counted
  }
  return counts;
}

TEST(StepAllocationsTest, TheCounterSeesAllocations) {
  // Guards the test itself: a counter that sees nothing would make every test below pass.
  g_mallocs = 0;
  g_news = 0;
  g_counting = true;
  auto* vector = new std::vector<int>(100);
  void* raw = std::malloc(64);
  g_counting = false;
  std::free(raw);
  delete vector;
  EXPECT_GE(g_news.load(), 2);     // the vector object and its elements
  EXPECT_GE(g_mallocs.load(), 3);  // those two through operator new, and the malloc
  EXPECT_EQ(g_mesa_mallocs.load(), 0);
  EXPECT_EQ(g_bullet_mallocs.load(), 0);
}

class StepAllocationsTest : public ::testing::TestWithParam<std::string> {};

TEST_P(StepAllocationsTest, StepIntoAllocatesNothingAfterWarmUp) {
  std::unique_ptr<Env> env = make(GetParam());
  const Counts counts = count_step_allocations(*env, /*warmup_steps=*/20, /*steps=*/100);
  EXPECT_EQ(counts.news, 0) << GetParam() << ": operator new calls in 100 steps";
  EXPECT_EQ(counts.mallocs, 0) << GetParam() << ": pixelgym's malloc calls in 100 steps";
  std::printf("%s: in 100 steps, %ld mallocs inside Mesa, %ld inside Bullet\n", GetParam().c_str(),
              counts.mesa_mallocs, counts.bullet_mallocs);
}

TEST_P(StepAllocationsTest, StateModeAllocatesNothingOutsideBullet) {
  // No GL at all in state mode, so not even Mesa allocates.
  if (GetParam() == "GridWorld-v0") GTEST_SKIP() << "GridWorld has no state mode";
  std::unique_ptr<Env> env = make(GetParam(), {{"obs_mode", "state"}});
  const Counts counts = count_step_allocations(*env, 20, 100);
  EXPECT_EQ(counts.news, 0) << GetParam();
  EXPECT_EQ(counts.mallocs + counts.mesa_mallocs, 0) << GetParam();
  std::printf("%s, obs_mode=state: in 100 steps, %ld mallocs inside Bullet\n", GetParam().c_str(),
              counts.bullet_mallocs);
}

TEST_P(StepAllocationsTest, StepIntoWritesIntoTheCallersBuffer) {
  std::unique_ptr<Env> env = make(GetParam());
  ResetResult reset;
  reset.obs = env->observation_space().zeros();
  const std::vector<Array> reset_leaves = reset.obs.leaves();
  env->reset_into(reset, 0);
  // The observation is in the caller's arrays (no array of the env's own swapped in) and equals
  // what reset() gives for the same seed.
  const std::vector<Array> after = reset.obs.leaves();
  ASSERT_EQ(after.size(), reset_leaves.size());
  for (std::size_t i = 0; i < after.size(); ++i) {
    EXPECT_EQ(after[i].raw_data(), reset_leaves[i].raw_data()) << "leaf " << i;
  }
  std::unique_ptr<Env> other = make(GetParam());
  EXPECT_TRUE(other->reset(0).obs.equals(reset.obs));
}

TEST_P(StepAllocationsTest, StepIntoRefusesABufferOfAnotherLayout) {
  std::unique_ptr<Env> env = make(GetParam());
  env->reset(0);
  StepResult step;  // obs: an empty float32 array
  EXPECT_THROW(env->step_into(env->action_space().sample(), step), std::invalid_argument);
}

INSTANTIATE_TEST_SUITE_P(AllEnvs, StepAllocationsTest, ::testing::ValuesIn(registered_ids()),
                         testing::env_id_test_name);

TEST(StepAllocationsTest, GridWorldPixelsAllocatesNothing) {
  std::unique_ptr<Env> env = make("GridWorld-v0", {{"obs_mode", "pixels"}});
  const Counts counts = count_step_allocations(*env, 20, 100);
  EXPECT_EQ(counts.news, 0);
  EXPECT_EQ(counts.mallocs + counts.mesa_mallocs + counts.bullet_mallocs, 0);
}

}  // namespace
}  // namespace pixelgym
