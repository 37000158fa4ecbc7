#include "examples/trainer/distributed/gloo_communicator.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sched.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <torch/torch.h>
#include <unistd.h>

#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <sstream>
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>

namespace pixelgym::distributed {
namespace {

using Clock = std::chrono::steady_clock;
using trainer::DistributedError;

// How often the watchdog beats and looks at the others.
constexpr auto kHeartbeatPeriod = std::chrono::milliseconds(500);
// After a collective failed at once: how long a heartbeat may stand still before its rank is
// named as the one that stopped.
constexpr double kFailedStaleSeconds = 2.5;
// The exit status of a rank that the watchdog stops.
constexpr int kLostRankExitStatus = 3;
// Gloo's own limit on one collective: long, since rank 0 may evaluate while the others wait in
// the next update's all-reduce; the watchdog stops ranks that died or hang much sooner.
constexpr auto kCollectiveTimeout = std::chrono::minutes(30);

std::string env_or_empty(const char* name) {
  const char* value = std::getenv(name);
  return value == nullptr ? std::string() : std::string(value);
}

long parse_variable(const char* name, const std::string& value, long low, long high) {
  char* end = nullptr;
  errno = 0;
  const long parsed = std::strtol(value.c_str(), &end, 10);
  if (value.empty() || *end != '\0' || errno != 0 || parsed < low || parsed > high) {
    throw std::invalid_argument(std::string(name) + " must be an integer in [" +
                                std::to_string(low) + ", " + std::to_string(high) + "], got \"" +
                                value + "\"");
  }
  return parsed;
}

// The local address this host uses to reach `host` (a UDP socket "connected" there sends
// nothing), for Gloo to listen on.
std::string local_address_towards(const std::string& host, int port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0 || !found) {
    throw std::invalid_argument("MASTER_ADDR \"" + host + "\" does not resolve to an address");
  }
  std::string address;
  for (addrinfo* a = found; a != nullptr && address.empty(); a = a->ai_next) {
    const int fd = socket(a->ai_family, SOCK_DGRAM, 0);
    if (fd < 0) continue;
    sockaddr_storage local{};
    socklen_t length = sizeof(local);
    if (connect(fd, a->ai_addr, a->ai_addrlen) == 0 &&
        getsockname(fd, reinterpret_cast<sockaddr*>(&local), &length) == 0) {
      char text[INET6_ADDRSTRLEN] = {};
      const void* raw =
          local.ss_family == AF_INET
              ? static_cast<const void*>(&reinterpret_cast<sockaddr_in*>(&local)->sin_addr)
              : static_cast<const void*>(&reinterpret_cast<sockaddr_in6*>(&local)->sin6_addr);
      if (inet_ntop(local.ss_family, raw, text, sizeof(text)) != nullptr) address = text;
    }
    close(fd);
  }
  freeaddrinfo(found);
  if (address.empty()) {
    throw std::invalid_argument("no local address reaches MASTER_ADDR \"" + host + "\"");
  }
  return address;
}

// Whether a torchrun agent already serves the store at MASTER_ADDR:MASTER_PORT.
bool agent_store() {
  const std::string value = env_or_empty("TORCHELASTIC_USE_AGENT_STORE");
  return value == "True" || value == "true" || value == "1";
}

std::string seconds_text(double s) {
  std::ostringstream text;
  text << std::round(s * 10.0) / 10.0;
  return text.str();
}

}  // namespace

std::optional<DistributedSettings> DistributedSettings::from_environment(double timeout_s) {
  const std::string world = env_or_empty("WORLD_SIZE");
  if (world.empty()) return std::nullopt;
  DistributedSettings settings;
  settings.timeout_s = timeout_s;
  settings.world_size = static_cast<int>(parse_variable("WORLD_SIZE", world, 1, 65536));
  const std::string rank = env_or_empty("RANK");
  if (rank.empty()) throw std::invalid_argument("WORLD_SIZE is set but RANK is not");
  settings.rank = static_cast<int>(parse_variable("RANK", rank, 0, settings.world_size - 1));
  const std::string local_rank = env_or_empty("LOCAL_RANK");
  if (!local_rank.empty()) {
    settings.local_rank = static_cast<int>(parse_variable("LOCAL_RANK", local_rank, 0, 65535));
  }
  if (settings.world_size == 1) return settings;
  settings.master_address = env_or_empty("MASTER_ADDR");
  if (settings.master_address.empty()) {
    throw std::invalid_argument("WORLD_SIZE is " + world +
                                " but MASTER_ADDR is not set (rank 0's host name or address)");
  }
  const std::string port = env_or_empty("MASTER_PORT");
  if (port.empty())
    throw std::invalid_argument("WORLD_SIZE is " + world + " but MASTER_PORT is not set");
  settings.master_port = static_cast<int>(parse_variable("MASTER_PORT", port, 1, 65535));
  return settings;
}

GlooCommunicator::GlooCommunicator(const DistributedSettings& settings) : settings_(settings) {
  if (settings_.world_size < 1 || settings_.rank < 0 || settings_.rank >= settings_.world_size) {
    throw std::invalid_argument("GlooCommunicator: rank " + std::to_string(settings_.rank) +
                                " of world size " + std::to_string(settings_.world_size));
  }
  if (!(settings_.timeout_s > 0.0)) {
    throw std::invalid_argument("the distributed timeout must be > 0 s, got " +
                                seconds_text(settings_.timeout_s));
  }
  const auto rendezvous = std::chrono::milliseconds(
      static_cast<std::int64_t>(std::max(settings_.timeout_s, 60.0) * 1000.0));
  const std::string where = settings_.master_address + ":" + std::to_string(settings_.master_port);
  // A peer that went away must not kill this rank with SIGPIPE when Gloo writes to it: the
  // write fails and the error names the rank.
  std::signal(SIGPIPE, SIG_IGN);
  try {
    c10d::TCPStoreOptions options;
    options.port = static_cast<std::uint16_t>(settings_.master_port);
    // torchrun from PyTorch 2.4 on runs the store itself (its agent's) on MASTER_PORT and says
    // so: every rank is then a client.
    options.isServer = settings_.rank == 0 && !agent_store();
    options.numWorkers = static_cast<std::size_t>(settings_.world_size);
    options.waitWorkers = true;
    options.timeout = rendezvous;
    store_ = c10::make_intrusive<c10d::TCPStore>(settings_.master_address, options);
    auto group_options = c10d::ProcessGroupGloo::Options::create(kCollectiveTimeout);
    const std::string interface = env_or_empty("GLOO_SOCKET_IFNAME");
    group_options->devices.push_back(
        interface.empty() ? c10d::ProcessGroupGloo::createDeviceForHostname(local_address_towards(
                                settings_.master_address, settings_.master_port))
                          : c10d::ProcessGroupGloo::createDeviceForInterface(interface));
    group_ = c10::make_intrusive<c10d::ProcessGroupGloo>(store_, settings_.rank,
                                                         settings_.world_size, group_options);
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw DistributedError(
        "rank " + std::to_string(settings_.rank) + " of " + std::to_string(settings_.world_size) +
        ": the rendezvous at MASTER_ADDR:MASTER_PORT " + where +
        " failed (every rank must start within " +
        seconds_text(static_cast<double>(rendezvous.count()) / 1000.0) + " s): " + e.what());
  }
  watchdog_ = std::thread([this] { watch(); });
}

GlooCommunicator::~GlooCommunicator() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
}

void GlooCommunicator::watch() {
  // A client of its own: the main thread's store calls may block (a get waits for its key).
  c10::intrusive_ptr<c10d::Store> store;
  const std::string me = "rank " + std::to_string(settings_.rank);
  const auto lose = [&](const std::string& why) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (stop_) return;
    lost_ = why;
    wake_.notify_all();
    if (collective_failed_) return;  // the main thread throws it
    // The main thread may be inside a collective that waits for the lost rank: stop here.
    std::cerr << "train: " << me << ": " << why << "; stopping this rank\n" << std::flush;
    std::_Exit(kLostRankExitStatus);
  };
  try {
    c10d::TCPStoreOptions options;
    options.port = static_cast<std::uint16_t>(settings_.master_port);
    options.isServer = false;
    options.waitWorkers = false;
    options.timeout =
        std::chrono::milliseconds(static_cast<std::int64_t>(settings_.timeout_s * 1000.0));
    store = c10::make_intrusive<c10d::TCPStore>(settings_.master_address, options);
  } catch (const std::exception& e) {
    lose(std::string("cannot reach rank 0's store at MASTER_ADDR:MASTER_PORT: ") + e.what());
    return;
  }
  const int world = settings_.world_size;
  std::vector<std::int64_t> seen(static_cast<std::size_t>(world), -1);
  std::vector<Clock::time_point> changed(static_cast<std::size_t>(world), Clock::now());
  std::vector<bool> finished(static_cast<std::size_t>(world), false);
  std::unique_lock<std::mutex> lock(mutex_);
  while (!stop_) {
    const bool failed = collective_failed_;
    lock.unlock();
    try {
      store->add("heartbeat/" + std::to_string(settings_.rank), 1);
      const auto now = Clock::now();
      for (int q = 0; q < world; ++q) {
        const auto qi = static_cast<std::size_t>(q);
        if (q == settings_.rank || finished[qi]) continue;
        const std::int64_t beats = store->add("heartbeat/" + std::to_string(q), 0);
        if (beats != seen[qi]) {
          seen[qi] = beats;
          changed[qi] = now;
          continue;
        }
        const double still = std::chrono::duration<double>(now - changed[qi]).count();
        if (still <
            (failed ? std::min(kFailedStaleSeconds, settings_.timeout_s) : settings_.timeout_s)) {
          continue;
        }
        if (store->check({"finished/" + std::to_string(q)})) {
          finished[qi] = true;
          continue;
        }
        lose("rank " + std::to_string(q) + " has not answered for " + seconds_text(still) +
             " s (it died, was stopped or hangs; --dist-timeout " +
             seconds_text(settings_.timeout_s) + " s)");
        return;
      }
    } catch (const std::exception& e) {
      lose(settings_.rank == 0
               ? std::string("the rendezvous store failed: ") + e.what()
               : "rank 0 has gone (its store at MASTER_ADDR:MASTER_PORT " +
                     settings_.master_address + ":" + std::to_string(settings_.master_port) +
                     " no longer answers: " + e.what() + ")");
      return;
    }
    lock.lock();
    wake_.wait_for(lock, kHeartbeatPeriod, [this] { return stop_; });
  }
}

template <typename Operation>
void GlooCommunicator::collective(const std::string& what, const Operation& operation) {
  try {
    operation();
    return;
  } catch (const std::exception& e) {
    const std::string cause = e.what();
    std::unique_lock<std::mutex> lock(mutex_);
    collective_failed_ = true;
    // Wait for the watchdog to find the rank that stopped (its heartbeat stands still).
    wake_.wait_for(lock,
                   std::chrono::milliseconds(static_cast<std::int64_t>(
                       (std::min(kFailedStaleSeconds, settings_.timeout_s) + 2.0) * 1000.0)),
                   [this] { return lost_.has_value(); });
    throw DistributedError("rank " + std::to_string(settings_.rank) + ": " + what + " failed: " +
                           (lost_ ? *lost_ : std::string("no rank stopped answering")) + " [" +
                           cause + "]");
  }
}

template <typename T>
void GlooCommunicator::all_reduce(T* data, std::size_t count, const std::string& what) {
  if (count == 0) return;
  collective(what, [&] {
    std::vector<at::Tensor> tensors{torch::from_blob(data, {static_cast<std::int64_t>(count)},
                                                     c10::CppTypeToScalarType<T>::value)};
    group_->allreduce(tensors)->wait();
  });
}

void GlooCommunicator::all_reduce_sum(float* data, std::size_t count, const std::string& what) {
  all_reduce(data, count, what);
}

void GlooCommunicator::all_reduce_sum(double* data, std::size_t count, const std::string& what) {
  all_reduce(data, count, what);
}

void GlooCommunicator::broadcast(float* data, std::size_t count, const std::string& what) {
  if (count == 0) return;
  collective(what, [&] {
    std::vector<at::Tensor> tensors{
        torch::from_blob(data, {static_cast<std::int64_t>(count)}, torch::kFloat32)};
    group_->broadcast(tensors)->wait();
  });
}

std::vector<std::uint64_t> GlooCommunicator::all_gather(std::uint64_t value,
                                                        const std::string& what) {
  std::vector<std::uint64_t> values(static_cast<std::size_t>(settings_.world_size));
  collective(what, [&] {
    std::int64_t mine = 0;
    std::memcpy(&mine, &value, sizeof(mine));
    std::vector<at::Tensor> input{torch::full({1}, mine, torch::kInt64)};
    std::vector<std::vector<at::Tensor>> output(1);
    for (int r = 0; r < settings_.world_size; ++r) {
      output[0].push_back(torch::zeros({1}, torch::kInt64));
    }
    group_->allgather(output, input)->wait();
    for (int r = 0; r < settings_.world_size; ++r) {
      const std::int64_t got = output[0][static_cast<std::size_t>(r)].item<std::int64_t>();
      std::memcpy(&values[static_cast<std::size_t>(r)], &got, sizeof(got));
    }
  });
  return values;
}

std::string GlooCommunicator::key(const std::string& what) {
  return "bytes/" + std::to_string(sequence_++) + "/" + what;
}

std::vector<std::string> GlooCommunicator::gather_bytes(const std::string& bytes,
                                                        const std::string& what) {
  const std::string prefix = key(what);
  std::vector<std::string> gathered;
  collective(what, [&] {
    if (settings_.rank != 0) {
      store_->set(prefix + "/" + std::to_string(settings_.rank),
                  std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
      return;
    }
    gathered.push_back(bytes);
    for (int r = 1; r < settings_.world_size; ++r) {
      const std::string name = prefix + "/" + std::to_string(r);
      const std::vector<std::uint8_t> value = store_->get(name);
      gathered.emplace_back(value.begin(), value.end());
      store_->deleteKey(name);
    }
  });
  return gathered;
}

std::string GlooCommunicator::scatter_bytes(const std::vector<std::string>& per_rank,
                                            const std::string& what) {
  const std::string prefix = key(what);
  std::string mine;
  collective(what, [&] {
    if (settings_.rank == 0) {
      if (per_rank.size() != static_cast<std::size_t>(settings_.world_size)) {
        throw std::invalid_argument("scatter_bytes: " + std::to_string(settings_.world_size) +
                                    " strings expected, got " + std::to_string(per_rank.size()));
      }
      for (int r = 1; r < settings_.world_size; ++r) {
        const std::string& bytes = per_rank[static_cast<std::size_t>(r)];
        store_->set(prefix + "/" + std::to_string(r),
                    std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
      }
      mine = per_rank[0];
      return;
    }
    const std::string name = prefix + "/" + std::to_string(settings_.rank);
    const std::vector<std::uint8_t> value = store_->get(name);
    mine.assign(value.begin(), value.end());
    try {
      store_->deleteKey(name);
    } catch (const std::exception&) {
      // Rank 0 has finished and its store is gone: the bytes are here.
    }
  });
  return mine;
}

int GlooCommunicator::mark_rollout_done(std::int64_t round) {
  return static_cast<int>(store_->add("rollout_done/" + std::to_string(round), 1));
}

int GlooCommunicator::rollouts_done(std::int64_t round) {
  return static_cast<int>(store_->add("rollout_done/" + std::to_string(round), 0));
}

void GlooCommunicator::finish() {
  try {
    store_->set("finished/" + std::to_string(settings_.rank), std::vector<std::uint8_t>{1});
    if (settings_.rank == 0 && !agent_store()) {
      // Rank 0 holds the store: it stays until every rank has finished with it (at most the
      // timeout), so that none finds it gone on its way out.
      const auto deadline =
          Clock::now() +
          std::chrono::milliseconds(static_cast<std::int64_t>(settings_.timeout_s * 1000.0));
      for (int r = 1; r < settings_.world_size && Clock::now() < deadline; ++r) {
        while (!store_->check({"finished/" + std::to_string(r)}) && Clock::now() < deadline) {
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
      }
    }
  } catch (const std::exception&) {
    // Rank 0 (the store) has finished first: nobody watches this rank any more.
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
}

// ---- run_local_ranks ---------------------------------------------------------------------------

namespace {

volatile sig_atomic_t forwarded_signal = 0;

void remember_signal(int signal_number) { forwarded_signal = signal_number; }

int free_local_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0)
    throw std::runtime_error(std::string("train --nproc: socket: ") + std::strerror(errno));
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  socklen_t length = sizeof(address);
  if (bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    const std::string reason = std::strerror(errno);
    close(fd);
    throw std::runtime_error("train --nproc: cannot find a free local port: " + reason);
  }
  close(fd);
  return ntohs(address.sin_port);
}

std::string describe_status(int status) {
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) {
    return "was killed by signal " + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  }
  return "stopped (status " + std::to_string(status) + ")";
}

}  // namespace

int run_local_ranks(int nproc, const std::vector<std::string>& arguments, double timeout_s,
                    std::ostream& errors) {
  if (nproc < 1) throw std::invalid_argument("--nproc must be >= 1, got " + std::to_string(nproc));
  const int port = free_local_port();
  cpu_set_t cpus;
  CPU_ZERO(&cpus);
  const int cores = sched_getaffinity(0, sizeof(cpus), &cpus) == 0 ? CPU_COUNT(&cpus) : 1;
  const std::string omp_threads = std::to_string(std::max(1, cores / nproc));
  struct sigaction forward {};
  forward.sa_handler = remember_signal;
  sigemptyset(&forward.sa_mask);
  struct sigaction old_int {
  }, old_term{};
  sigaction(SIGINT, &forward, &old_int);
  sigaction(SIGTERM, &forward, &old_term);

  std::vector<pid_t> pids;
  for (int r = 0; r < nproc; ++r) {
    const pid_t pid = fork();
    if (pid < 0) {
      errors << "train --nproc: fork: " << std::strerror(errno) << "\n";
      for (const pid_t started : pids) kill(started, SIGTERM);
      break;
    }
    if (pid == 0) {
      setenv("MASTER_ADDR", "127.0.0.1", 1);
      setenv("MASTER_PORT", std::to_string(port).c_str(), 1);
      setenv("WORLD_SIZE", std::to_string(nproc).c_str(), 1);
      setenv("RANK", std::to_string(r).c_str(), 1);
      setenv("LOCAL_RANK", std::to_string(r).c_str(), 1);
      setenv("LOCAL_WORLD_SIZE", std::to_string(nproc).c_str(), 1);
      setenv("OMP_NUM_THREADS", omp_threads.c_str(), 0);
      std::vector<char*> argv;
      std::string self = "/proc/self/exe";
      argv.push_back(arguments.empty() ? self.data() : const_cast<char*>(arguments[0].c_str()));
      for (std::size_t i = 1; i < arguments.size(); ++i) {
        argv.push_back(const_cast<char*>(arguments[i].c_str()));
      }
      argv.push_back(nullptr);
      execv("/proc/self/exe", argv.data());
      std::fprintf(stderr, "train --nproc: exec of rank %d failed: %s\n", r, std::strerror(errno));
      std::_Exit(127);
    }
    pids.push_back(pid);
  }
  int result = pids.size() == static_cast<std::size_t>(nproc) ? 0 : 1;
  std::vector<bool> running(pids.size(), true);
  std::size_t left = pids.size();
  std::optional<Clock::time_point> failed_at;
  bool killed = false;
  while (left > 0) {
    if (forwarded_signal != 0) {
      for (std::size_t r = 0; r < pids.size(); ++r) {
        if (running[r]) kill(pids[r], forwarded_signal);
      }
      forwarded_signal = 0;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      for (std::size_t r = 0; r < pids.size(); ++r) {
        if (pids[r] != pid || !running[r]) continue;
        running[r] = false;
        --left;
        if (!(WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
          errors << "train --nproc: rank " << r << " (pid " << pid << ") "
                 << describe_status(status) << "\n";
          result = 1;
          if (!failed_at) failed_at = Clock::now();
        }
      }
      continue;
    }
    if (failed_at && !killed &&
        std::chrono::duration<double>(Clock::now() - *failed_at).count() > timeout_s + 10.0) {
      for (std::size_t r = 0; r < pids.size(); ++r) {
        if (!running[r]) continue;
        errors << "train --nproc: rank " << r << " (pid " << pids[r]
               << ") did not stop after another rank failed; killing it\n";
        kill(pids[r], SIGKILL);
      }
      killed = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  sigaction(SIGINT, &old_int, nullptr);
  sigaction(SIGTERM, &old_term, nullptr);
  return result;
}

}  // namespace pixelgym::distributed
