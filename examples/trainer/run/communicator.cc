#include "pixelgym/trainer/communicator.h"

#include <algorithm>
#include <sstream>

namespace pixelgym::trainer {

void SingleProcessCommunicator::all_reduce_sum(float* /*data*/, std::size_t /*count*/,
                                               const std::string& /*what*/) {}

void SingleProcessCommunicator::all_reduce_sum(double* /*data*/, std::size_t /*count*/,
                                               const std::string& /*what*/) {}

void SingleProcessCommunicator::broadcast(float* /*data*/, std::size_t /*count*/,
                                          const std::string& /*what*/) {}

std::vector<std::uint64_t> SingleProcessCommunicator::all_gather(std::uint64_t value,
                                                                 const std::string& /*what*/) {
  return {value};
}

std::vector<std::string> SingleProcessCommunicator::gather_bytes(const std::string& bytes,
                                                                 const std::string& /*what*/) {
  return {bytes};
}

std::string SingleProcessCommunicator::scatter_bytes(const std::vector<std::string>& per_rank,
                                                     const std::string& what) {
  if (per_rank.size() != 1) {
    throw std::invalid_argument("SingleProcessCommunicator::scatter_bytes (" + what +
                                "): one part (for rank 0) expected, got " +
                                std::to_string(per_rank.size()));
  }
  return per_rank.front();
}

int SingleProcessCommunicator::mark_rollout_done(std::int64_t round) {
  rounds_done_ = std::max(rounds_done_, round);
  return 1;
}

int SingleProcessCommunicator::rollouts_done(std::int64_t round) {
  return round <= rounds_done_ ? 1 : 0;
}

void merge_statistics_across_ranks(Communicator& communicator,
                                   const wrappers::RunningStatistics& before,
                                   wrappers::RunningStatistics& statistics,
                                   const std::string& what) {
  const std::size_t size = before.mean.size();
  if (statistics.mean.size() != size || statistics.var.size() != size ||
      before.var.size() != size) {
    throw std::invalid_argument("merge_statistics_across_ranks: statistics of " +
                                std::to_string(size) + " elements expected, got " +
                                std::to_string(statistics.mean.size()));
  }
  // This rank's samples: count n, and, centred on `before`'s mean (the same on every rank, so
  // that the sums below keep their precision), n * (batch mean - mean0) and the batch's sum of
  // squared deviations plus n * (batch mean - mean0)^2.
  const double c0 = before.count;
  const double c = statistics.count;
  const double n = std::max(c - c0, 0.0);
  std::vector<double> sums(1 + 2 * size, 0.0);
  sums[0] = n;
  if (n > 0.0) {
    for (std::size_t i = 0; i < size; ++i) {
      const double offset = (statistics.mean[i] - before.mean[i]) * c / n;  // batch mean - mean0
      const double squares =
          std::max(statistics.var[i] * c - before.var[i] * c0 - offset * offset * c0 * n / c, 0.0);
      sums[1 + i] = n * offset;
      sums[1 + size + i] = squares + n * offset * offset;
    }
  }
  communicator.all_reduce_sum(sums.data(), sums.size(), what);
  const double total_n = sums[0];
  statistics = before;
  if (total_n <= 0.0) return;
  const double total = c0 + total_n;
  for (std::size_t i = 0; i < size; ++i) {
    const double offset = sums[1 + i] / total_n;  // every rank's batch mean - mean0
    const double batch_var = std::max(sums[1 + size + i] / total_n - offset * offset, 0.0);
    statistics.mean[i] = before.mean[i] + offset * total_n / total;
    statistics.var[i] =
        (before.var[i] * c0 + batch_var * total_n + offset * offset * c0 * total_n / total) / total;
  }
  statistics.count = total;
}

std::uint64_t fnv1a(const void* data, std::size_t size, std::uint64_t digest) {
  const auto* bytes = static_cast<const unsigned char*>(data);
  for (std::size_t k = 0; k < size; ++k) digest = (digest ^ bytes[k]) * 1099511628211ULL;
  return digest;
}

std::vector<std::uint64_t> check_same_on_every_rank(Communicator& communicator,
                                                    std::uint64_t digest, std::int64_t updates) {
  const std::vector<std::uint64_t> digests =
      communicator.all_gather(digest, "parameter digest check");
  std::ostringstream differ;
  int count = 0;
  for (std::size_t r = 1; r < digests.size(); ++r) {
    if (digests[r] == digests[0]) continue;
    differ << (count++ == 0 ? "" : ", ") << "rank " << r << " (" << std::hex << digests[r]
           << std::dec << ")";
  }
  if (count == 0) return digests;
  std::ostringstream message;
  message << "the ranks' parameters differ after update " << updates << ": " << differ.str()
          << (count == 1 ? " differs" : " differ") << " from rank 0's (" << std::hex << digests[0]
          << std::dec << "); data-parallel ranks must hold identical parameters, so the run stops";
  throw DistributedError(message.str());
}

}  // namespace pixelgym::trainer
