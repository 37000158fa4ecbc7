// The trainer's Communicator on PyTorch's distributed package (c10d): a TCPStore for the
// rendezvous (a FileStore for train --nproc's local ranks), ProcessGroupGloo for the collectives,
// and a watchdog that names a rank that died or stopped answering. Started the way torchrun starts
// workers: from the variables MASTER_ADDR, MASTER_PORT, WORLD_SIZE, RANK and LOCAL_RANK.
#pragma once

#include <c10/util/intrusive_ptr.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/trainer/communicator.h"

namespace c10d {
class ProcessGroupGloo;
class Store;
}  // namespace c10d

namespace pixelgym::distributed {

/// Where a rank finds the others, as torchrun's variables give it.
struct DistributedSettings {
  std::string master_address = "127.0.0.1";  // MASTER_ADDR: rank 0's host, which holds the store
  int master_port = 29500;                   // MASTER_PORT
  int world_size = 1;                        // WORLD_SIZE
  int rank = 0;                              // RANK
  int local_rank = 0;                        // LOCAL_RANK (0 when unset)
  /// Seconds a rank may go without a sign of life (its heartbeat) before the others stop the
  /// run naming it.
  double timeout_s = 60.0;
  /// Seconds every rank has to join the rendezvous (train --dist-join-timeout; by default
  /// max(timeout_s, 60)): a rank missing then is named and every rank that came stops.
  double join_timeout_s = 60.0;
  /// PIXELGYM_RENDEZVOUS_FILE, which train --nproc sets: the file of a c10d::FileStore, in a
  /// folder only this user may open, that the local ranks meet at instead of a TCPStore on
  /// MASTER_PORT (then unused), so that nothing listens on a port for the rendezvous. Empty
  /// otherwise.
  std::string store_file;

  /// The settings of the environment's WORLD_SIZE, RANK, MASTER_ADDR, MASTER_PORT, LOCAL_RANK and
  /// PIXELGYM_RENDEZVOUS_FILE, with these timeouts; nullopt when WORLD_SIZE is not set. Throws
  /// std::invalid_argument naming the variable and its value when one is not a number in range
  /// or one that is needed is missing.
  static std::optional<DistributedSettings> from_environment(double timeout_s,
                                                             double join_timeout_s);
};

/// A rank of a run over Gloo. Construction is the rendezvous: rank 0 opens the TCPStore on
/// MASTER_PORT (or every rank opens the FileStore of store_file), every rank connects to it,
/// claims its rank there and waits for the others, and the Gloo process group joins all
/// world_size ranks. Throws std::invalid_argument for a launch that cannot work: another process
/// has claimed this rank already (RANK given twice), rank 0 was given another WORLD_SIZE, or
/// MASTER_ADDR does not resolve. Throws DistributedError, naming the cause, when
/// - a rank other than 0 finds at MASTER_ADDR:MASTER_PORT a program that does not answer as
///   rank 0's store within 5 s (another service's port), or nothing there within join_timeout_s;
/// - a rank has not joined within join_timeout_s (naming each missing rank);
/// - rank 0 cannot serve the store on MASTER_PORT (a port in use).
/// Gloo's own socket goes on the interface named by GLOO_SOCKET_IFNAME (as in PyTorch) or else on
/// the local address this host uses to reach MASTER_ADDR (127.0.0.1 for train --nproc).
///
/// Liveness: a thread of each rank adds to its heartbeat counter in the store twice a second
/// and watches the others'. A rank whose counter stands still for timeout_s (dead, stopped or
/// hung), or rank 0's store going away, makes every other rank print
/// "rank R: rank Q has not answered for S s (...)" to stderr and exit with status 3, even from
/// inside a collective that would otherwise wait; a collective that fails at once (a peer's
/// connection reset) throws DistributedError naming the rank whose heartbeat then stops.
/// Nothing is written by the watchdog, so files written atomically stay whole. A rank whose
/// process lives (its watchdog beats) but whose training thread hangs outside a collective is
/// caught only by Gloo's own limit on a collective, 30 minutes. SIGPIPE is ignored from
/// construction on (a write to a peer that died then fails with an error instead). finish() on
/// rank 0, which holds the store, waits (at most the timeout) for every other rank to finish.
///
/// Under torchrun from PyTorch 2.4 on (TORCHELASTIC_USE_AGENT_STORE set), torchrun's agent
/// serves the store and every rank connects to it as a client (not tried here: Debian's
/// torchrun is 1.13's).
class GlooCommunicator final : public trainer::Communicator {
 public:
  explicit GlooCommunicator(const DistributedSettings& settings);
  ~GlooCommunicator() override;
  GlooCommunicator(const GlooCommunicator&) = delete;
  GlooCommunicator& operator=(const GlooCommunicator&) = delete;

  int rank() const override { return settings_.rank; }
  int world_size() const override { return settings_.world_size; }
  void all_reduce_sum(float* data, std::size_t count, const std::string& what) override;
  void all_reduce_sum(double* data, std::size_t count, const std::string& what) override;
  void broadcast(float* data, std::size_t count, const std::string& what) override;
  std::vector<std::uint64_t> all_gather(std::uint64_t value, const std::string& what) override;
  std::vector<std::string> gather_bytes(const std::string& bytes, const std::string& what) override;
  std::string scatter_bytes(const std::vector<std::string>& per_rank,
                            const std::string& what) override;
  int mark_rollout_done(std::int64_t round) override;
  int rollouts_done(std::int64_t round) override;
  void finish() override;

  const DistributedSettings& settings() const { return settings_; }

 private:
  // Runs `operation`; on failure throws DistributedError naming the rank that stopped, once the
  // watchdog has found it (or the failure itself when none has stopped).
  template <typename Operation>
  void collective(const std::string& what, const Operation& operation);
  // A sum all-reduce of `count` values of T (float or double).
  template <typename T>
  void all_reduce(T* data, std::size_t count, const std::string& what);
  // Claims this rank in the store and waits for every rank to claim its own (the rendezvous);
  // `serves_store`: this rank's process serves the store (rank 0 over TCP).
  void join(bool serves_store);
  void watch();
  void stop_watchdog();
  std::string key(const std::string& what);

  DistributedSettings settings_;
  c10::intrusive_ptr<c10d::Store> store_;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> group_;
  std::int64_t sequence_ = 0;  // collectives through the store so far (unique keys)

  // The watchdog.
  std::thread watchdog_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool collective_failed_ = false;   // shortens the watchdog's wait to kFailedStaleSeconds
  std::optional<std::string> lost_;  // why a rank is lost, once the watchdog knows
};

/// Runs `arguments` (a pixelgym command line without --nproc; arguments[0] is ignored: this
/// executable runs) as `nproc` local ranks, as torchrun --standalone does: child processes with
/// MASTER_ADDR 127.0.0.1, WORLD_SIZE, RANK, LOCAL_RANK and LOCAL_WORLD_SIZE set,
/// PIXELGYM_RENDEZVOUS_FILE naming a store file in a new folder of $TMPDIR (or /tmp) that only
/// this user may open (removed at the end), and OMP_NUM_THREADS set to the cores divided among
/// them unless it is set. Each rank gets SIGTERM when the launcher dies (PR_SET_PDEATHSIG), so
/// none is left training when it is killed. Waits for all; when one fails, gives the others
/// timeout_s + 10 s to stop on their own, then kills them. Forwards SIGINT and SIGTERM. Reports
/// each rank that failed to `errors` ("rank 1 (pid 123) was killed by signal 9 (Killed)").
/// Returns 0 when every rank exited 0, else 1.
int run_local_ranks(int nproc, const std::vector<std::string>& arguments, double timeout_s,
                    std::ostream& errors);

}  // namespace pixelgym::distributed
