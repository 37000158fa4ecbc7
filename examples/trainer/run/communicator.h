// The ranks of a data-parallel training run as the trainer sees them, without torch: the
// collective operations a run and its algorithm need (sums, broadcast, gathers of digests and of
// bytes), and straggler bookkeeping. distributed::GlooCommunicator implements it on PyTorch's
// c10d (Gloo over TCP); SingleProcessCommunicator is the run of one process (world size 1).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::trainer {

/// A collective operation that could not complete: a rank died, stopped answering, or disagreed
/// (parameters that differ). The message names the ranks involved.
class DistributedError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One process (rank) of a run of world_size() processes that train one model together. Every
/// operation below is collective: every rank calls it, in the same order, with the same `what`
/// (a few words naming the step, used in errors and as a key). Throws DistributedError when
/// another rank dies or stops answering within the communicator's timeout, naming it.
class Communicator {
 public:
  virtual ~Communicator() = default;

  /// This process's rank, 0 .. world_size() - 1; rank 0 writes the run folder.
  virtual int rank() const = 0;
  virtual int world_size() const = 0;

  /// Element-wise sums over the ranks of `count` values at `data`, in place, on every rank.
  virtual void all_reduce_sum(float* data, std::size_t count, const std::string& what) = 0;
  virtual void all_reduce_sum(double* data, std::size_t count, const std::string& what) = 0;
  /// Rank 0's `count` values at `data` written into every other rank's.
  virtual void broadcast(float* data, std::size_t count, const std::string& what) = 0;
  /// Every rank's `value`, in rank order, on every rank.
  virtual std::vector<std::uint64_t> all_gather(std::uint64_t value, const std::string& what) = 0;
  /// Rank 0 gets every rank's `bytes` in rank order (its own first); the others get {}.
  virtual std::vector<std::string> gather_bytes(const std::string& bytes,
                                                const std::string& what) = 0;
  /// Rank 0 gives `per_rank` (world_size() strings, ignored elsewhere); each rank gets its own.
  virtual std::string scatter_bytes(const std::vector<std::string>& per_rank,
                                    const std::string& what) = 0;

  /// Straggler preemption (DD-PPO): counts this rank's rollout number `round` as finished and
  /// returns how many ranks have finished it so far. Not collective.
  virtual int mark_rollout_done(std::int64_t round) = 0;
  /// How many ranks have finished rollout `round`. Not collective.
  virtual int rollouts_done(std::int64_t round) = 0;

  /// This rank leaves the run normally: the others stop watching it. Not collective; no
  /// collective may follow on this rank.
  virtual void finish() = 0;
};

/// The communicator of a run of one process: rank 0 of a world of size 1. Its collectives are
/// what they are with one rank: sums and broadcasts leave the values as they are, gathers return
/// this process's own, and scatter returns per_rank[0]. Never throws DistributedError.
class SingleProcessCommunicator final : public Communicator {
 public:
  int rank() const override { return 0; }
  int world_size() const override { return 1; }
  void all_reduce_sum(float* data, std::size_t count, const std::string& what) override;
  void all_reduce_sum(double* data, std::size_t count, const std::string& what) override;
  void broadcast(float* data, std::size_t count, const std::string& what) override;
  std::vector<std::uint64_t> all_gather(std::uint64_t value, const std::string& what) override;
  std::vector<std::string> gather_bytes(const std::string& bytes, const std::string& what) override;
  /// Throws std::invalid_argument when `per_rank` does not hold exactly one string.
  std::string scatter_bytes(const std::vector<std::string>& per_rank,
                            const std::string& what) override;
  /// 1 (this process) once `round` is marked, else 0.
  int mark_rollout_done(std::int64_t round) override;
  int rollouts_done(std::int64_t round) override;
  void finish() override {}

 private:
  std::int64_t rounds_done_ = -1;  // the latest round marked done; -1: none
};

/// Sums over the ranks of the samples merged into running statistics since they were `before`
/// (identical on every rank): `statistics` (this rank's: `before` with its own samples merged in)
/// becomes `before` with every rank's samples merged in, the same on every rank. Each rank's
/// samples are recovered from the two states by inverting the merge of Chan et al.; their moments
/// are summed across ranks (one all_reduce_sum) and merged into `before`, which equals merging
/// all the ranks' samples as one batch up to rounding.
void merge_statistics_across_ranks(Communicator& communicator,
                                   const wrappers::RunningStatistics& before,
                                   wrappers::RunningStatistics& statistics,
                                   const std::string& what);

/// A 64-bit FNV-1a digest of `size` bytes at `data`, continuing from `digest`.
std::uint64_t fnv1a(const void* data, std::size_t size,
                    std::uint64_t digest = 14695981039346656037ULL);

/// Checks that every rank's `digest` (of its parameters after `updates` updates) is rank 0's:
/// throws DistributedError naming the ranks whose digests differ from rank 0's, and the digests.
/// Returns every rank's digest, in rank order.
std::vector<std::uint64_t> check_same_on_every_rank(Communicator& communicator,
                                                    std::uint64_t digest, std::int64_t updates);

}  // namespace pixelgym::trainer
