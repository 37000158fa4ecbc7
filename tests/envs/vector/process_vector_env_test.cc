// ProcessVectorEnv, with worker 0 run by the calling process (the default) and with every worker
// a child: a task registered by the user reaches the workers and runs there (one pid per worker),
// infos and renders come back batched in env order, an env's error names the env and its worker,
// and a worker killed mid-step makes step() throw within a second, after which close() returns
// and no child is left. (Byte-for-byte equality with SyncVectorEnv on the pixel tasks,
// under every autoreset mode, is in determinism_test.cc.)
#include "pixelgym/envs/vector/process_vector_env.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/envs/spaces/discrete.h"
#include "pixelgym/envs/vector/make_vec.h"

namespace pixelgym::vector {
namespace {

using ::testing::HasSubstr;

// A user's own env: observes {its reset seed, its step count}, reports the pid it runs in, ends
// its episode after 3 steps. Action 1 throws, action 2 sleeps for 3 s (a worker to kill mid-step).
class PidEnv final : public Env {
 public:
  explicit PidEnv(std::int64_t obs_size = 2)
      : observation_space_(
            std::make_shared<spaces::Box>(-1e9, 1e9, Shape{obs_size}, DType::kFloat64)),
        action_space_(std::make_shared<spaces::Discrete>(3)) {}
  const Space& observation_space() const override { return *observation_space_; }
  const Space& action_space() const override { return *action_space_; }
  const Metadata& metadata() const override { return metadata_; }

 protected:
  std::string type_name() const override { return "PidEnv"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override {
    if (seed) seed_ = static_cast<double>(*seed);
    if (options.count("offset") != 0) seed_ += options.at("offset").as_float();
    t_ = 0;
    observe(out.obs);
    out.info.insert("pid", Array::scalar<std::int64_t>(::getpid()));
  }
  void do_step(const Value& action, StepResult& out) override {
    const std::int64_t a = action.array().item<std::int64_t>();
    if (a == 1) throw std::invalid_argument("action 1 is bad luck");
    if (a == 2) std::this_thread::sleep_for(std::chrono::seconds(3));
    ++t_;
    observe(out.obs);
    out.reward = seed_ + t_;
    out.terminated = t_ == 3;
    out.info.insert("pid", Array::scalar<std::int64_t>(::getpid()));
    if (t_ == 2) out.info.insert("second", Array::scalar<double>(seed_));
  }
  Array do_render() override {
    Array frame(DType::kUInt8, {2, 2, 3});
    for (std::int64_t k = 0; k < frame.size(); ++k) {
      frame.data<std::uint8_t>()[k] = static_cast<std::uint8_t>(seed_);
    }
    return frame;
  }

 private:
  void observe(Value& obs) const {
    obs.array().data<double>()[0] = seed_;
    obs.array().data<double>()[1] = t_;
  }
  SpacePtr observation_space_;
  SpacePtr action_space_;
  Metadata metadata_;
  double seed_ = 0;
  int t_ = 0;
};

// A registry of the user's own, holding Pid-v0.
struct UserRegistry : Registry {
  UserRegistry() {
    EnvSpec spec;
    spec.id = "Pid-v0";
    spec.description = "reports its pid";
    spec.factory = [](const Params&, const MakeOptions&) { return std::make_unique<PidEnv>(); };
    register_env(std::move(spec));
  }
};

// Whether the calling process runs worker 0 (VectorOptions::caller_steps_envs).
class ProcessVectorEnvTest : public ::testing::TestWithParam<bool> {};

std::unique_ptr<VectorEnv> make_process(const Registry& registry, int num_envs, int workers,
                                        AutoresetMode mode = AutoresetMode::kNextStep) {
  VectorOptions options;
  options.mode = VectorMode::kProcess;
  options.num_workers = workers;
  options.autoreset = mode;
  options.caller_steps_envs = ProcessVectorEnvTest::GetParam();
  return make_vec(registry, "Pid-v0", num_envs, {}, nullptr, options);
}

Array actions(std::vector<std::int64_t> values) {
  const auto n = static_cast<std::int64_t>(values.size());
  return Array::from_vector<std::int64_t>({n}, values);
}

bool alive(int pid) { return ::kill(pid, 0) == 0 || errno != ESRCH; }

TEST_P(ProcessVectorEnvTest, AUsersTaskRunsInTheWorkersAndMatchesSync) {
  const UserRegistry registry;
  const auto process = make_process(registry, 5, 2, AutoresetMode::kSameStep);
  VectorOptions sync_options;
  sync_options.autoreset = AutoresetMode::kSameStep;
  const auto sync = make_vec(registry, "Pid-v0", 5, {}, nullptr, sync_options);
  EXPECT_EQ(process->name(), "ProcessVectorEnv(Pid-v0, num_envs=5)");
  auto& workers = dynamic_cast<ProcessVectorEnv&>(*process);
  ASSERT_EQ(workers.num_workers(), 2);

  const Options options{{"offset", 0.5}};
  const VectorResetResult& reset = process->reset(10, options);
  EXPECT_TRUE(reset.obs.equals(sync->reset(10, options).obs));
  // Envs 0-2 ran in worker 0 (this process, or a child), envs 3-4 in worker 1 (a child).
  const std::int64_t* pids = reset.infos.at("pid").array().data<std::int64_t>();
  EXPECT_EQ(pids[0], workers.worker_pid(0));
  EXPECT_EQ(pids[2], workers.worker_pid(0));
  EXPECT_EQ(pids[3], workers.worker_pid(1));
  EXPECT_NE(pids[0], pids[4]);
  EXPECT_EQ(pids[0] == ::getpid(), GetParam());
  EXPECT_NE(pids[4], ::getpid());

  for (int t = 0; t < 4; ++t) {
    const Array a = actions({0, 0, 0, 0, 0});
    const VectorStepResult& got = process->step(a);
    const VectorStepResult& want = sync->step(a);
    const std::string where = "step " + std::to_string(t);
    EXPECT_TRUE(got.obs.equals(want.obs)) << where;
    EXPECT_TRUE(got.rewards.equals(want.rewards)) << where;
    EXPECT_TRUE(got.terminated.equals(want.terminated)) << where;
    // The infos batch as sync's do, pids aside: masks, the key only step 2 reports, final_obs.
    for (const std::string& key : want.infos.keys()) {
      ASSERT_TRUE(got.infos.contains(key)) << where << ": " << key;
      if (key == "pid" || key == "final_info") continue;
      EXPECT_TRUE(got.infos.at(key).equals(want.infos.at(key))) << where << ": " << key;
    }
    EXPECT_EQ(got.infos.size(), want.infos.size()) << where;
  }
  const std::vector<Array> frames = process->render();
  const std::vector<Array> sync_frames = sync->render();
  ASSERT_EQ(frames.size(), 5U);
  for (std::size_t i = 0; i < frames.size(); ++i) EXPECT_TRUE(frames[i].equals(sync_frames[i]));

  process->close();
  EXPECT_EQ(alive(workers.worker_pid(0)), GetParam());  // this process, or a child ended
  EXPECT_FALSE(alive(workers.worker_pid(1)));
  EXPECT_THROW(process->step(actions({0, 0, 0, 0, 0})), ResetNeeded);
}

TEST_P(ProcessVectorEnvTest, AnEnvErrorNamesTheEnvAndItsWorkerAndAResetRecovers) {
  const UserRegistry registry;
  const auto env = make_process(registry, 4, 2);
  const auto& workers = dynamic_cast<const ProcessVectorEnv&>(*env);
  env->reset(0);
  try {
    env->step(actions({0, 0, 0, 1}));
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("ProcessVectorEnv(Pid-v0, num_envs=4): env 3 ("));
    EXPECT_THAT(e.what(),
                HasSubstr("on worker 1 (pid " + std::to_string(workers.worker_pid(1)) + ")"));
    EXPECT_THAT(e.what(), HasSubstr("action 1 is bad luck"));
  }
  EXPECT_THROW(env->step(actions({0, 0, 0, 0})), ResetNeeded);
  EXPECT_THROW(env->reset(std::nullopt, {}, Array::from_vector<bool>({4}, {0, 0, 0, 1})),
               ResetNeeded);
  env->reset(0);
  EXPECT_EQ(env->step(actions({0, 0, 0, 0})).rewards.data<double>()[3], 4.0);
}

TEST_P(ProcessVectorEnvTest, AWorkerKilledMidStepIsAnErrorNamingItWithinASecond) {
  const UserRegistry registry;
  const auto env = make_process(registry, 4, 2);
  const auto& workers = dynamic_cast<const ProcessVectorEnv&>(*env);
  const int victim = workers.worker_pid(1);
  const int survivor = workers.worker_pid(0);
  env->reset(0);
  std::chrono::steady_clock::time_point killed;
  std::thread killer([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    killed = std::chrono::steady_clock::now();
    ::kill(victim, SIGKILL);
  });
  std::string message;
  try {
    env->step(actions({0, 0, 2, 2}));  // worker 1's envs sleep 3 s each
  } catch (const std::runtime_error& e) {
    message = e.what();
  }
  const auto thrown = std::chrono::steady_clock::now();
  killer.join();
  EXPECT_LT(thrown - killed, std::chrono::seconds(1));
  EXPECT_THAT(message, HasSubstr("step(): worker 1 (pid " + std::to_string(victim) +
                                 ", envs 2-3) killed by signal 9"));
  EXPECT_THROW(env->step(actions({0, 0, 0, 0})), ResetNeeded);
  EXPECT_THROW(env->reset(0), ResetNeeded);
  const auto closing = std::chrono::steady_clock::now();
  env->close();
  EXPECT_LT(std::chrono::steady_clock::now() - closing, std::chrono::seconds(2));
  EXPECT_FALSE(alive(victim));
  EXPECT_EQ(alive(survivor), GetParam());
}

TEST_P(ProcessVectorEnvTest, DestroyingWithoutCloseEndsTheWorkers) {
  const UserRegistry registry;
  std::vector<int> pids;
  {
    const auto env = make_process(registry, 3, 3);
    const auto& workers = dynamic_cast<const ProcessVectorEnv&>(*env);
    for (int w = GetParam() ? 1 : 0; w < workers.num_workers(); ++w) {
      pids.push_back(workers.worker_pid(w));
    }
    env->reset(1);
  }
  ASSERT_EQ(pids.size(), GetParam() ? 2U : 3U);
  for (const int pid : pids) EXPECT_FALSE(alive(pid)) << pid;
}

// The children of a second vector env are forked while the first one's sockets are open: they
// must not keep them, or the first one's workers would never see it go (its destructor would
// wait, then kill them).
TEST_P(ProcessVectorEnvTest, AnotherVectorEnvsChildrenDoNotKeepTheFirstsWorkersAlive) {
  const UserRegistry registry;
  auto first = make_process(registry, 2, 2);
  const int first_child = dynamic_cast<const ProcessVectorEnv&>(*first).worker_pid(1);
  const auto second = make_process(registry, 2, 2);
  first->reset(0);
  second->reset(0);
  const auto start = std::chrono::steady_clock::now();
  first.reset();  // without close(): its children see their sockets close
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
  EXPECT_FALSE(alive(first_child));
  EXPECT_EQ(second->step(actions({0, 0})).rewards.data<double>()[1], 2.0);
}

TEST_P(ProcessVectorEnvTest, BadArgumentsAndAFailingFactory) {
  const UserRegistry registry;
  EXPECT_THROW(make_process(registry, 2, -1), std::invalid_argument);
  EXPECT_EQ(ProcessVectorEnv::workers_for(3, 8), 3);
  const std::shared_ptr<const Env> like = std::make_shared<PidEnv>();
  try {
    ProcessVectorEnv env(
        4,
        [](int /*worker*/) {
          return EnvFactory([](int i) -> std::unique_ptr<Env> {
            if (i == 2) throw std::runtime_error("no env 2 today");
            return std::make_unique<PidEnv>();
          });
        },
        like, 2, AutoresetMode::kNextStep, GetParam());
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_THAT(e.what(), HasSubstr("env 2 (not built) on worker 1"));
    EXPECT_THAT(e.what(), HasSubstr("no env 2 today"));
  }
  // An env whose spaces are not those the batch was laid out for.
  try {
    ProcessVectorEnv env(
        2,
        [](int /*worker*/) {
          return EnvFactory(
              [](int) -> std::unique_ptr<Env> { return std::make_unique<PidEnv>(3); });
        },
        like, 2, AutoresetMode::kNextStep, GetParam());
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_THAT(e.what(), HasSubstr("differ from those the vector env was laid out for"));
  }
}

INSTANTIATE_TEST_SUITE_P(Workers, ProcessVectorEnvTest, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& param_info) {
                           return param_info.param ? "CallerStepsWorker0" : "AllInChildren";
                         });

}  // namespace
}  // namespace pixelgym::vector
