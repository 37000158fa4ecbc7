#include "examples/trainer/distributed/gloo_communicator.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <torch/torch.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <torch/csrc/distributed/c10d/FileStore.hpp>
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
// How long a rank other than 0 gives the service at MASTER_ADDR:MASTER_PORT to answer as rank 0's
// store once it accepted the connection: a store answers in milliseconds, another program (an
// HTTP server, say) never does, and c10d's client would wait for it forever.
constexpr double kStoreAnswerSeconds = 5.0;
// How long a rank other than 0 listens, once connected to MASTER_PORT, for a program that speaks
// first (rank 0's store never does).
constexpr auto kQuietPeriod = std::chrono::milliseconds(500);
// The key rank 0 sets in its store as soon as it serves it: the others' handshake waits for it.
const char* const kStoreKey = "pixelgym/store";
// How often a rank looks whether every rank has joined.
constexpr auto kJoinPollPeriod = std::chrono::milliseconds(50);
// Where rank 0, serving the store, says which ranks did not join before it stops (and its store
// with it), and where the ranks that came count that they read it; how long rank 0 waits for them.
const char* const kJoinFailedKey = "pixelgym/join_failed";
const char* const kJoinFailedSeenKey = "pixelgym/join_failed_seen";
constexpr auto kJoinFailedTellPeriod = std::chrono::seconds(2);
// The variable through which train --nproc gives its ranks their store's file.
const char* const kStoreFileVariable = "PIXELGYM_RENDEZVOUS_FILE";

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

// A socket connected to `address` by `deadline`, or -1.
int connect_by(const addrinfo& address, Clock::time_point deadline) {
  const int fd = socket(address.ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  if (connect(fd, address.ai_addr, address.ai_addrlen) == 0) return fd;
  if (errno == EINPROGRESS) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    pollfd ready{fd, POLLOUT, 0};
    int error = 0;
    socklen_t length = sizeof(error);
    if (poll(&ready, 1, static_cast<int>(std::max<std::int64_t>(left, 0))) == 1 &&
        getsockopt(fd, SOL_SOCKET, SO_ERROR, &error, &length) == 0 && error == 0) {
      return fd;
    }
  }
  close(fd);
  return -1;
}

// What listens at host:port, as a rank other than 0 finds it before c10d's client connects.
struct PortProbe {
  bool accepted = false;  // something accepted a connection before the deadline
  std::string spoke;      // what it said, unasked, within kQuietPeriod, or why it hung up; ""
                          // when it stayed quiet as a store does
};

// Connects to host:port until something accepts (by `deadline`), then listens kQuietPeriod.
// Rank 0's store never speaks first, but many services do at once (an HTTP server's error, an
// SSH banner) or close the connection, and c10d's client dies on such bytes (std::bad_alloc in
// its callback thread, which ends the process).
PortProbe probe_port(const std::string& host, int port, Clock::time_point deadline) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  PortProbe probe;
  int fd = -1;
  while (fd < 0 && Clock::now() < deadline) {
    addrinfo* found = nullptr;
    if (getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) == 0) {
      for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next)
        fd = connect_by(*a, deadline);
      freeaddrinfo(found);
    }
    if (fd < 0) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  if (fd < 0) return probe;
  probe.accepted = true;
  pollfd ready{fd, POLLIN, 0};
  if (poll(&ready, 1, static_cast<int>(kQuietPeriod.count())) == 1) {
    char words[80] = {};
    const ssize_t got = recv(fd, words, sizeof(words), 0);
    if (got <= 0) {
      probe.spoke = "it closed the connection at once";
    } else {
      std::string text;
      for (ssize_t i = 0; i < got && words[i] != '\r' && words[i] != '\n'; ++i) {
        text += std::isprint(static_cast<unsigned char>(words[i])) ? words[i] : '.';
      }
      probe.spoke = "it sent \"" + text + "\" before any request";
    }
  }
  close(fd);
  return probe;
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

std::chrono::milliseconds milliseconds_of(double seconds) {
  return std::chrono::milliseconds(static_cast<std::int64_t>(seconds * 1000.0));
}

// An exception's message; c10's without the C++ stack trace it carries.
std::string message_of(const std::exception& error) {
  if (const auto* c10_error = dynamic_cast<const c10::Error*>(&error)) {
    return c10_error->what_without_backtrace();
  }
  return error.what();
}

// This rank's connection to the run's store, whose waits (get, wait) end after `timeout`: the
// FileStore of settings.store_file, or the TCPStore at MASTER_ADDR:MASTER_PORT, which this
// process serves when `serve`. A client waits at most `timeout` for the port to open.
c10::intrusive_ptr<c10d::Store> open_store(const DistributedSettings& settings, bool serve,
                                           std::chrono::milliseconds timeout) {
  if (!settings.store_file.empty()) {
    // -1: no count of workers, so that no rank's exit deletes the file under the others; the
    // launcher removes its folder.
    auto store = c10::make_intrusive<c10d::FileStore>(settings.store_file, -1);
    store->setTimeout(timeout);
    return store;
  }
  c10d::TCPStoreOptions options;
  options.port = static_cast<std::uint16_t>(settings.master_port);
  options.isServer = serve;
  options.waitWorkers = false;  // join() waits for the ranks, and names those missing
  options.timeout = timeout;
  return c10::make_intrusive<c10d::TCPStore>(settings.master_address, options);
}

}  // namespace

std::optional<DistributedSettings> DistributedSettings::from_environment(double timeout_s,
                                                                         double join_timeout_s) {
  const std::string world = env_or_empty("WORLD_SIZE");
  if (world.empty()) return std::nullopt;
  DistributedSettings settings;
  settings.timeout_s = timeout_s;
  settings.join_timeout_s = join_timeout_s;
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
  settings.store_file = env_or_empty(kStoreFileVariable);
  if (!settings.store_file.empty()) return settings;  // train --nproc's: no port
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
  if (!(settings_.join_timeout_s > 0.0)) {
    throw std::invalid_argument("the rendezvous's join timeout must be > 0 s, got " +
                                seconds_text(settings_.join_timeout_s));
  }
  const std::string me =
      "rank " + std::to_string(settings_.rank) + " of " + std::to_string(settings_.world_size);
  const std::string where = settings_.master_address + ":" + std::to_string(settings_.master_port);
  // A peer that went away must not kill this rank with SIGPIPE when Gloo writes to it: the
  // write fails and the error names the rank.
  std::signal(SIGPIPE, SIG_IGN);
  // Gloo's device first: a MASTER_ADDR that does not resolve is refused before any waiting.
  auto group_options = c10d::ProcessGroupGloo::Options::create(kCollectiveTimeout);
  const std::string interface = env_or_empty("GLOO_SOCKET_IFNAME");
  group_options->devices.push_back(
      interface.empty() ? c10d::ProcessGroupGloo::createDeviceForHostname(local_address_towards(
                              settings_.master_address, settings_.master_port))
                        : c10d::ProcessGroupGloo::createDeviceForInterface(interface));

  const bool file = !settings_.store_file.empty();
  // torchrun from PyTorch 2.4 on runs the store itself (its agent's) on MASTER_PORT and says
  // so: every rank is then a client.
  const bool serve = settings_.rank == 0 && !file && !agent_store();
  const std::string foreign = me + ": the program at MASTER_ADDR:MASTER_PORT " + where +
                              " is not rank 0's rendezvous store: ";
  if (!serve && !file) {
    const PortProbe probe = probe_port(settings_.master_address, settings_.master_port,
                                       Clock::now() + milliseconds_of(settings_.join_timeout_s));
    if (!probe.accepted) {
      throw DistributedError(me + ": nothing answered at MASTER_ADDR:MASTER_PORT " + where +
                             " within " + seconds_text(settings_.join_timeout_s) +
                             " s (--dist-join-timeout): rank 0 serves the run's store there; did "
                             "it start, with this MASTER_PORT?");
    }
    if (!probe.spoke.empty()) {
      throw DistributedError(foreign + probe.spoke +
                             ", which a store never does; is MASTER_PORT another service's port?");
    }
  }
  try {
    store_ = open_store(settings_, serve, milliseconds_of(settings_.join_timeout_s));
  } catch (const std::exception& e) {
    throw DistributedError(
        me + ": " +
        (file ? "cannot open the rendezvous store file " + settings_.store_file
         : serve
             ? "cannot serve the rendezvous store on MASTER_PORT " +
                   std::to_string(settings_.master_port)
             : "nothing answered at MASTER_ADDR:MASTER_PORT " + where + " within " +
                   seconds_text(settings_.join_timeout_s) +
                   " s (--dist-join-timeout): rank 0 serves the run's store there; did it start, "
                   "with this MASTER_PORT?") +
        ": " + message_of(e));
  }
  if (serve) {
    // The key the others' handshake waits for; its value is the world size, which they check.
    const std::string world = std::to_string(settings_.world_size);
    store_->set(kStoreKey, std::vector<std::uint8_t>(world.begin(), world.end()));
  } else if (!file && !agent_store()) {
    // c10d's client would wait forever for a program that accepts the connection and never
    // answers (an HTTP server on MASTER_PORT): the store must answer within seconds.
    std::string world;
    try {
      store_->wait({kStoreKey},
                   milliseconds_of(std::min(kStoreAnswerSeconds, settings_.join_timeout_s)));
      const std::vector<std::uint8_t> value = store_->get(kStoreKey);
      world.assign(value.begin(), value.end());
    } catch (const std::exception& e) {
      throw DistributedError(
          foreign + "it accepted the connection but did not answer as a c10d store within " +
          seconds_text(std::min(kStoreAnswerSeconds, settings_.join_timeout_s)) + " s (" +
          message_of(e) + "); is MASTER_PORT another service's port?");
    }
    if (world != std::to_string(settings_.world_size)) {
      throw std::invalid_argument(me + ": WORLD_SIZE is " + std::to_string(settings_.world_size) +
                                  " here but " + world + " on rank 0 (MASTER_ADDR:MASTER_PORT " +
                                  where + "): give every rank the same WORLD_SIZE");
    }
  }
  join(serve);
  // From here on a rank that dies (even inside Gloo's connection of the ranks, which would
  // wait for it for kCollectiveTimeout) is named by the watchdog.
  watchdog_ = std::thread([this] { watch(); });
  try {
    group_ = c10::make_intrusive<c10d::ProcessGroupGloo>(store_, settings_.rank,
                                                         settings_.world_size, group_options);
  } catch (const std::exception& e) {
    stop_watchdog();
    throw DistributedError(me + ": Gloo could not connect the ranks: " + message_of(e));
  }
}

GlooCommunicator::~GlooCommunicator() { stop_watchdog(); }

void GlooCommunicator::stop_watchdog() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (watchdog_.joinable()) watchdog_.join();
}

void GlooCommunicator::join(bool serves_store) {
  const int world = settings_.world_size;
  const std::string mine = std::to_string(settings_.rank);
  const std::string me = "rank " + mine + " of " + std::to_string(world);
  const std::string where = settings_.store_file.empty()
                                ? "MASTER_ADDR:MASTER_PORT " + settings_.master_address + ":" +
                                      std::to_string(settings_.master_port)
                                : "the store file " + settings_.store_file;
  try {
    // Every rank's heartbeat exists before any rank passes the rendezvous: the watchdogs read
    // them without waiting.
    store_->add("heartbeat/" + mine, 0);
    if (store_->add("joined/" + mine, 1) > 1) {
      throw std::invalid_argument(me + ": another process has already joined the run at " + where +
                                  " as rank " + mine + " (RANK=" + mine +
                                  " given to two processes?); give each RANK from 0 to " +
                                  std::to_string(world - 1) + " to one process");
    }
    std::vector<std::string> joined;
    for (int r = 0; r < world; ++r) joined.push_back("joined/" + std::to_string(r));
    const auto deadline = Clock::now() + milliseconds_of(settings_.join_timeout_s);
    while (!store_->check(joined)) {
      if (!serves_store && store_->check({kJoinFailedKey})) {
        // Rank 0 stopped waiting, and its store goes with it: say what it found.
        const std::vector<std::uint8_t> why = store_->get(kJoinFailedKey);
        store_->add(kJoinFailedSeenKey, 1);
        throw DistributedError(me +
                               ": rank 0 stopped waiting: " + std::string(why.begin(), why.end()));
      }
      if (Clock::now() < deadline) {
        std::this_thread::sleep_for(kJoinPollPeriod);
        continue;
      }
      std::string missing;
      int count = 0;
      for (int r = 0; r < world; ++r) {
        if (store_->check({joined[static_cast<std::size_t>(r)]})) continue;
        missing += (count++ == 0 ? "" : ", ") + std::to_string(r);
      }
      const std::string why =
          "rank" + std::string(count == 1 ? " " : "s ") + missing +
          (count == 1 ? " has" : " have") + " not joined the rendezvous at " + where + " within " +
          seconds_text(settings_.join_timeout_s) +
          " s (--dist-join-timeout): start every RANK from 0 to " + std::to_string(world - 1) +
          " with WORLD_SIZE=" + std::to_string(world) + " and the same MASTER_ADDR and MASTER_PORT";
      if (serves_store) {
        // The store goes when this rank stops: first the ranks that came learn why (briefly).
        store_->set(kJoinFailedKey, std::vector<std::uint8_t>(why.begin(), why.end()));
        const std::int64_t waiting = world - count - 1;
        const auto told_by = Clock::now() + kJoinFailedTellPeriod;
        while (store_->add(kJoinFailedSeenKey, 0) < waiting && Clock::now() < told_by) {
          std::this_thread::sleep_for(kJoinPollPeriod);
        }
      }
      throw DistributedError(me + ": " + why);
    }
  } catch (const DistributedError&) {
    throw;
  } catch (const std::invalid_argument&) {
    throw;
  } catch (const std::exception& e) {
    throw DistributedError(me + ": the rendezvous at " + where +
                           " failed (rank 0, which serves the store, has gone?): " + message_of(e));
  }
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
    store = open_store(settings_, false, milliseconds_of(settings_.timeout_s));
  } catch (const std::exception& e) {
    lose("cannot reach rank 0's store at MASTER_ADDR:MASTER_PORT: " + message_of(e));
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
        // A get, not an add of 0: a FileStore appends every add to its file.
        const std::vector<std::uint8_t> value = store->get("heartbeat/" + std::to_string(q));
        const std::int64_t beats = std::stoll(std::string(value.begin(), value.end()));
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
      lose(settings_.rank == 0 || !settings_.store_file.empty()
               ? "the rendezvous store failed: " + message_of(e)
               : "rank 0 has gone (its store at MASTER_ADDR:MASTER_PORT " +
                     settings_.master_address + ":" + std::to_string(settings_.master_port) +
                     " no longer answers: " + message_of(e) + ")");
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
  const std::string key = "rollout_done/" + std::to_string(round);
  if (settings_.store_file.empty()) return static_cast<int>(store_->add(key, 0));
  // A FileStore appends every add, an add of 0 included, to its file: once per env step here.
  if (!store_->check({key})) return 0;
  const std::vector<std::uint8_t> value = store_->get(key);
  return std::stoi(std::string(value.begin(), value.end()));
}

void GlooCommunicator::finish() {
  try {
    store_->set("finished/" + std::to_string(settings_.rank), std::vector<std::uint8_t>{1});
    if (settings_.rank == 0 && !agent_store() && settings_.store_file.empty()) {
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
  stop_watchdog();
}

// ---- run_local_ranks ---------------------------------------------------------------------------

namespace {

volatile sig_atomic_t forwarded_signal = 0;

void remember_signal(int signal_number) { forwarded_signal = signal_number; }

// A new folder of $TMPDIR (or /tmp) that only this user may open (mkdtemp makes it 0700), for
// the local ranks' store file: no port to listen on, and no other user can reach the store.
std::filesystem::path private_folder() {
  const std::string base = env_or_empty("TMPDIR").empty() ? "/tmp" : env_or_empty("TMPDIR");
  std::string pattern = base + "/pixelgym-nproc-XXXXXX";
  if (mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error("train --nproc: cannot create a folder for the ranks' store in " +
                             base + ": " + std::strerror(errno));
  }
  return pattern;
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
  const std::filesystem::path folder = private_folder();
  const std::string store_file = (folder / "store").string();
  const pid_t launcher = getpid();
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
      // The rank ends with the launcher (a kill -9 of it included) rather than train on as an
      // orphan. The launcher may have died before the request: then its parent is another.
      if (prctl(PR_SET_PDEATHSIG, SIGTERM) != 0 || getppid() != launcher) std::_Exit(1);
      setenv("MASTER_ADDR", "127.0.0.1", 1);  // Gloo listens on loopback
      unsetenv("MASTER_PORT");
      setenv(kStoreFileVariable, store_file.c_str(), 1);
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
  std::error_code ignored;
  std::filesystem::remove_all(folder, ignored);
  return result;
}

}  // namespace pixelgym::distributed
