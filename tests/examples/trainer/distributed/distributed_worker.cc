// One rank of the data-parallel trainer's tests (distributed_test.cc starts two, with WORLD_SIZE,
// RANK, MASTER_ADDR and MASTER_PORT set): `distributed_worker SCENARIO` runs a scenario over
// the Gloo communicator, prints what it found and exits 0 when it holds, 1 when it does not.
//
//   equivalence      one update of 2 ranks x 4 envs against one process of 8 envs on the same
//                    rollout, with the same minibatches
//   statistics       running statistics merged across ranks against one batch of all samples
//   digest_mismatch  rank 1's parameters are changed: the digest check must stop both ranks,
//                    naming rank 1
//   preemption       straggler preemption on, rank 1's envs 50 ms slower per step: rank 1's
//                    rollouts are cut short, the ranks still end with identical parameters
#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "examples/trainer/distributed/gloo_communicator.h"
#include "examples/trainer/ppo/ppo.h"
#include "pixelgym/envs/vector/make_vec.h"
#include "pixelgym/envs/vector/vector_wrapper.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace {

using pixelgym::ppo::PpoConfig;
using pixelgym::ppo::RolloutStorage;
using pixelgym::ppo::Trainer;
namespace distributed = pixelgym::distributed;
namespace trainer = pixelgym::trainer;
namespace vector = pixelgym::vector;

constexpr std::int64_t kRanks = 2;
constexpr std::int64_t kEnvsPerRank = 4;
constexpr std::int64_t kSteps = 16;
constexpr std::int64_t kMinibatches = 4;
constexpr std::int64_t kEpochs = 2;

std::unique_ptr<vector::VectorEnv> make_env(std::int64_t envs) {
  // Pixels and state: a CNN, and vector keys with observation normalization.
  const vector::VectorOptions options{vector::VectorMode::kSync, 1,
                                      vector::AutoresetMode::kSameStep, true};
  return vector::make_vec(
      "CartPoleBalance-v0", static_cast<int>(envs),
      {{"obs_mode", "pixels+state"}, {"width", 32}, {"height", 32}, {"max_episode_steps", 12}}, {},
      options);
}

PpoConfig config_for(std::int64_t envs) {
  PpoConfig config;
  config.seed = 5;
  config.num_envs = envs;
  config.num_steps = kSteps;
  config.num_minibatches = kMinibatches;
  config.update_epochs = kEpochs;
  config.total_env_steps = 100'000;
  return config;
}

// Rank q's order of its own kSteps x kEnvsPerRank transitions in `epoch`: known to every rank.
torch::Tensor local_order(std::int64_t epoch, std::int64_t rank) {
  auto generator = at::detail::createCPUGenerator(1000 + 10 * epoch + rank);
  return torch::randperm(kSteps * kEnvsPerRank, generator, torch::kInt64);
}

// The single process's order that visits, in minibatch m, exactly the transitions of every
// rank's minibatch m: a rank's local index t * 4 + j is the single process's t * 8 + 4 q + j.
torch::Tensor combined_order(std::int64_t epoch) {
  const std::int64_t local = kSteps * kEnvsPerRank / kMinibatches;
  std::vector<std::int64_t> order;
  std::vector<torch::Tensor> orders;
  for (std::int64_t q = 0; q < kRanks; ++q) orders.push_back(local_order(epoch, q));
  for (std::int64_t m = 0; m < kMinibatches; ++m) {
    for (std::int64_t q = 0; q < kRanks; ++q) {
      for (std::int64_t k = m * local; k < (m + 1) * local; ++k) {
        const std::int64_t i = orders[static_cast<std::size_t>(q)][k].item<std::int64_t>();
        order.push_back((i / kEnvsPerRank) * kRanks * kEnvsPerRank + q * kEnvsPerRank +
                        i % kEnvsPerRank);
      }
    }
  }
  return torch::tensor(order, torch::kInt64);
}

// Envs [first, first + count) of `all`'s rollout.
void copy_envs(const RolloutStorage& all, std::int64_t first, std::int64_t count,
               RolloutStorage& part) {
  for (auto& [key, stored] : part.observations) {
    stored.copy_(all.observations.at(key).slice(1, first, first + count));
  }
  part.actions.copy_(all.actions.slice(1, first, first + count));
  for (auto [into, from] : std::vector<std::pair<torch::Tensor*, const torch::Tensor*>>{
           {&part.log_probs, &all.log_probs},
           {&part.values, &all.values},
           {&part.rewards, &all.rewards},
           {&part.terminated, &all.terminated},
           {&part.truncated, &all.truncated},
           {&part.final_values, &all.final_values},
           {&part.advantages, &all.advantages},
           {&part.returns, &all.returns}}) {
    into->copy_(from->slice(1, first, first + count));
  }
  part.last_values.copy_(all.last_values.slice(0, first, first + count));
}

int equivalence(distributed::GlooCommunicator& communicator) {
  const std::int64_t rank = communicator.rank();
  // The single process of 8 envs (every rank computes it: it is deterministic).
  auto env8 = make_env(kRanks * kEnvsPerRank);
  Trainer single(*env8, config_for(kRanks * kEnvsPerRank));
  single.collect();
  // This rank: 4 envs, learning from its half of the same rollout.
  auto env4 = make_env(kEnvsPerRank);
  Trainer ranked(*env4, config_for(kEnvsPerRank), communicator);
  RolloutStorage half(ranked.policy(), kSteps, kEnvsPerRank);
  copy_envs(single.storage(), rank * kEnvsPerRank, kEnvsPerRank, half);
  ranked.load_rollout(half);
  ranked.set_minibatch_order([rank](std::int64_t epoch, std::int64_t size) {
    if (size != kSteps * kEnvsPerRank) throw std::logic_error("unexpected batch size");
    return local_order(epoch, rank);
  });
  single.set_minibatch_order(
      [](std::int64_t epoch, std::int64_t) { return combined_order(epoch); });
  const auto before = single.policy().parameters()[0].clone();
  single.update();
  ranked.update();
  double moved = (single.policy().parameters()[0] - before).abs().max().item<double>();
  double worst = 0.0;
  const auto a = single.policy().parameters();
  const auto b = ranked.policy().parameters();
  for (std::size_t i = 0; i < a.size(); ++i) {
    worst = std::max(worst, (a[i] - b[i]).abs().max().item<double>());
  }
  double stats_worst = 0.0;
  for (const char* key : {"joint_pos", "joint_vel"}) {
    const auto stats_a = single.policy().observation_statistics(key);
    const auto stats_b = ranked.policy().observation_statistics(key);
    stats_worst = std::max(stats_worst, std::abs(stats_a.count - stats_b.count));
    for (std::size_t i = 0; i < stats_a.mean.size(); ++i) {
      stats_worst = std::max(
          {stats_worst, std::abs(stats_a.mean[i] - stats_b.mean[i]),
           std::abs(stats_a.var[i] - stats_b.var[i]) / std::max(1.0, std::abs(stats_a.var[i]))});
    }
  }
  trainer::check_same_on_every_rank(communicator, ranked.parameter_digest(), 1);
  std::cout << "rank " << rank << ": parameters moved by up to " << moved
            << "; largest difference from the single process " << worst
            << "; observation statistics differ by " << stats_worst << "\n";
  return moved > 1e-4 && worst < 1e-6 && stats_worst < 1e-9 ? 0 : 1;
}

int statistics(distributed::GlooCommunicator& communicator) {
  const int rank = communicator.rank();
  // Samples of rank q: 50 + 30 q rows of 3 elements, from a generator of its own.
  const auto samples = [](int q) {
    auto generator = at::detail::createCPUGenerator(static_cast<std::uint64_t>(70 + q));
    return (torch::randn({50 + 30 * q, 3}, generator, torch::kFloat64) * (q + 1) + 3.0 * q)
        .contiguous();
  };
  const auto merge = [](pixelgym::wrappers::RunningStatistics& statistics, const torch::Tensor& x) {
    const double* data = x.data_ptr<double>();
    statistics.update_batch(static_cast<std::size_t>(x.size(0)),
                            [&](std::size_t row, std::size_t i) { return data[row * 3 + i]; });
  };
  auto before = pixelgym::wrappers::RunningStatistics::initial(3);
  merge(before, torch::full({20, 3}, 0.5, torch::kFloat64) + torch::arange(3, torch::kFloat64));
  auto mine = before;
  merge(mine, samples(rank));
  trainer::merge_statistics_across_ranks(communicator, before, mine, "test statistics");
  auto expected = before;
  merge(expected, torch::cat({samples(0), samples(1)}).contiguous());
  double worst = std::abs(mine.count - expected.count);
  for (std::size_t i = 0; i < 3; ++i) {
    worst = std::max({worst, std::abs(mine.mean[i] - expected.mean[i]),
                      std::abs(mine.var[i] - expected.var[i])});
  }
  std::cout << "rank " << rank << ": merged statistics differ from one batch's by " << worst
            << "\n";
  return worst < 1e-12 ? 0 : 1;
}

int digest_mismatch(distributed::GlooCommunicator& communicator) {
  auto env = make_env(kEnvsPerRank);
  Trainer ranked(*env, config_for(kEnvsPerRank), communicator);
  if (communicator.rank() == 1) {
    torch::NoGradGuard no_grad;
    ranked.policy().parameters()[0].view(-1)[0].add_(1e-3);
  }
  try {
    trainer::check_same_on_every_rank(communicator, ranked.parameter_digest(), 7);
  } catch (const trainer::DistributedError& error) {
    const std::string message = error.what();
    std::cout << "rank " << communicator.rank() << ": " << message << "\n";
    return message.find("after update 7: rank 1 (") != std::string::npos ? 0 : 1;
  }
  std::cout << "rank " << communicator.rank() << ": no error\n";
  return 1;
}

}  // namespace

// A vector env that takes 50 ms longer per step: a straggler.
class SlowSteps final : public vector::VectorWrapper {
 public:
  using vector::VectorWrapper::VectorWrapper;

 protected:
  const vector::VectorStepResult& do_step(const pixelgym::Value& actions) override {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    return vector::VectorWrapper::do_step(actions);
  }
};

int preemption(distributed::GlooCommunicator& communicator) {
  std::unique_ptr<vector::VectorEnv> env = make_env(kEnvsPerRank);
  if (communicator.rank() == 1) env = std::make_unique<SlowSteps>(std::move(env));
  PpoConfig config = config_for(kEnvsPerRank);
  config.preempt_stragglers = true;
  config.preempt_done_fraction = 0.5;  // rank 0 alone
  config.preempt_min_steps_fraction = 0.25;
  config.num_minibatches = 2;
  config.update_epochs = 1;
  Trainer ranked(*env, config, communicator);
  constexpr int kIterations = 3;
  std::int64_t local_steps = 0;
  for (int i = 0; i < kIterations; ++i) {
    ranked.collect();
    // One float32 action element per env step.
    local_steps = static_cast<std::int64_t>(ranked.env_action_log().size() / sizeof(float));
    ranked.update();
  }
  trainer::check_same_on_every_rank(communicator, ranked.parameter_digest(), kIterations);
  const std::int64_t full = kIterations * kSteps * kEnvsPerRank;
  std::cout << "rank " << communicator.rank() << ": stepped " << local_steps << " of " << full
            << " env steps; every rank's: " << ranked.env_steps() << " of " << kRanks * full
            << "\n";
  // Rank 0 never waits for rank 1; rank 1 stops its rollouts early, after 4 of its 16 steps
  // when rank 0's 16 steps take less than 4 of rank 1's (a loaded machine may add a few).
  const bool expected = communicator.rank() == 0 ? local_steps == full : local_steps < full;
  return expected && ranked.env_steps() < kRanks * full ? 0 : 1;
}

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: distributed_worker equivalence|statistics|digest_mismatch\n";
    return 2;
  }
  torch::set_num_threads(1);
  try {
    auto settings = distributed::DistributedSettings::from_environment(30.0, 60.0);
    if (!settings) throw std::invalid_argument("WORLD_SIZE is not set");
    distributed::GlooCommunicator communicator(*settings);
    const std::string scenario = argv[1];
    int result = 2;
    if (scenario == "equivalence") result = equivalence(communicator);
    if (scenario == "statistics") result = statistics(communicator);
    if (scenario == "digest_mismatch") result = digest_mismatch(communicator);
    if (scenario == "preemption") result = preemption(communicator);
    communicator.finish();
    return result;
  } catch (const std::exception& error) {
    std::cout << "error: " << error.what() << "\n";
    return 1;
  }
}
