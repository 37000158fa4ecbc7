#include "pixelgym/envs/vector/process_vector_env.h"

#include <poll.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <mutex>
#include <new>
#include <stdexcept>
#include <thread>
#include <utility>

#include "pixelgym/envs/errors.h"
#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/vector/batch_space.h"

namespace pixelgym::vector {
namespace {

// What the parent asks a worker; the worker answers every command with one reply.
enum class Op : std::uint8_t { kReset = 1, kStep, kRender, kClose };
// A reply's first byte.
enum class Status : std::uint8_t { kOk = 0, kError = 1 };
// The standard type an error is rethrown as.
enum class ErrorKind : std::uint8_t { kRuntime, kInvalidArgument, kOutOfRange, kResetNeeded };

// How long the parent waits in poll() before it asks the kernel whether a worker has ended
// (a dead worker's socket normally says so at once; this catches one whose socket another
// process still holds).
constexpr int kPollMs = 100;
// How long a worker that has replied keeps checking its socket for the next command (pausing or
// yielding the core between checks, see pause_or_yield) before it sleeps in the kernel: a wakeup
// from sleep costs tens of microseconds, a step of a few envs a few hundred, and the parent sends
// the next command as soon as it has the results.
constexpr std::chrono::microseconds kSpin{500};
// How long the parent, having sent a call, watches for its end without sleeping (pausing or
// yielding the core between checks) before it sleeps until the last worker done wakes it. A wakeup
// adds about 25 microseconds to every call (measured on 2 cores: with 1 worker stepping 2
// state-only envs, 34 microseconds a call sleeping, 11 watching).
constexpr std::chrono::microseconds kParentSpin{1000};

// Between two checks of a watch: with a core for every process of the vector env (`own_core`), the
// CPU's spin-wait hint, as AsyncVectorEnv's threads wait; else the core is offered to the others
// (sched_yield: a system call each time). Measured on 2 cores, 8 cart-pole envs on 2 workers:
// yielding made the vector env 1% slower than 2 threads (0.99x, 6 interleaved runs each), pausing
// 0.5-1% faster (1.005x and 1.009x).
void pause_or_yield(bool own_core) {
#if defined(__x86_64__) || defined(__i386__)
  if (own_core) {
    _mm_pause();
    return;
  }
#endif
  ::sched_yield();
}
// How long ending the workers waits for each to exit before killing it.
constexpr std::chrono::seconds kExitWait{5};

std::string process_name(const std::string& id, int num_envs) {
  return "ProcessVectorEnv(" + (id.empty() ? std::string() : id + ", ") +
         "num_envs=" + std::to_string(num_envs) + ")";
}

// ---- The messages: length-prefixed frames of plain bytes. ----------------------------------

class Writer {
 public:
  explicit Writer(Status status) { u8(static_cast<std::uint8_t>(status)); }
  explicit Writer(Op op) { u8(static_cast<std::uint8_t>(op)); }

  void u8(std::uint8_t v) { out_.push_back(static_cast<char>(v)); }
  void u64(std::uint64_t v) { bytes(&v, sizeof v); }
  void bytes(const void* data, std::size_t n) { out_.append(static_cast<const char*>(data), n); }
  void str(const std::string& s) {
    u64(s.size());
    out_.append(s);
  }
  void array(const Array& a) {
    u8(static_cast<std::uint8_t>(a.dtype()));
    u64(a.shape().size());
    for (std::int64_t d : a.shape()) u64(static_cast<std::uint64_t>(d));
    bytes(a.raw_data(), a.nbytes());
  }
  void value(const Value& v) {
    if (v.is_array()) {
      u8(0);
      array(v.array());
    } else if (v.is_dict()) {
      u8(1);
      u64(v.dict().size());
      for (std::size_t k = 0; k < v.dict().size(); ++k) {
        str(v.dict().keys()[k]);
        value(v.dict().values()[k]);
      }
    } else {
      u8(2);
      u64(v.tuple().size());
      for (const Value& item : v.tuple().items()) value(item);
    }
  }
  void params(const Params& params) {
    u64(params.size());
    for (const auto& [key, param] : params) {
      str(key);
      u8(static_cast<std::uint8_t>(param.type()));
      switch (param.type()) {
        case ParamType::kBool:
          u8(param.as_bool() ? 1 : 0);
          break;
        case ParamType::kInt:
          u64(static_cast<std::uint64_t>(param.as_int()));
          break;
        case ParamType::kFloat: {
          const double d = param.as_float();
          bytes(&d, sizeof d);
          break;
        }
        case ParamType::kString:
          str(param.as_string());
          break;
      }
    }
  }
  const std::string& frame() const { return out_; }

 private:
  std::string out_;
};

class Reader {
 public:
  explicit Reader(const std::string& in) : in_(in) {}

  std::uint8_t u8() { return static_cast<std::uint8_t>(*take(1)); }
  std::uint64_t u64() {
    std::uint64_t v = 0;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  std::string str() {
    const std::uint64_t n = u64();
    return std::string(take(n), n);
  }
  Array array() {
    const auto dtype = static_cast<DType>(u8());
    Shape shape(u64());
    for (std::int64_t& d : shape) d = static_cast<std::int64_t>(u64());
    Array a(dtype, shape);
    std::memcpy(a.raw_data(), take(a.nbytes()), a.nbytes());
    return a;
  }
  Value value() {
    switch (u8()) {
      case 0:
        return array();
      case 1: {
        ValueDict dict;
        for (std::uint64_t n = u64(); n > 0; --n) {
          std::string key = str();
          dict.insert(key, value());
        }
        return dict;
      }
      default: {
        std::vector<Value> items(u64());
        for (Value& item : items) item = value();
        return ValueTuple(std::move(items));
      }
    }
  }
  Params params() {
    Params params;
    for (std::uint64_t n = u64(); n > 0; --n) {
      std::string key = str();
      switch (static_cast<ParamType>(u8())) {
        case ParamType::kBool:
          params.emplace(key, Param(u8() != 0));
          break;
        case ParamType::kInt:
          params.emplace(key, Param(static_cast<long long>(u64())));
          break;
        case ParamType::kFloat: {
          double d = 0;
          std::memcpy(&d, take(sizeof d), sizeof d);
          params.emplace(key, Param(d));
          break;
        }
        case ParamType::kString:
          params.emplace(key, Param(str()));
          break;
      }
    }
    return params;
  }

 private:
  const char* take(std::uint64_t n) {
    if (n > in_.size() - pos_)
      throw std::runtime_error("ProcessVectorEnv: a message was cut short");
    const char* at = in_.data() + pos_;
    pos_ += n;
    return at;
  }
  const std::string& in_;
  std::size_t pos_ = 0;
};

// Sends one frame; false when the other end is gone.
bool send_frame(int fd, const std::string& payload) {
  const std::uint64_t n = payload.size();
  std::string frame(reinterpret_cast<const char*>(&n), sizeof n);
  frame += payload;
  std::size_t sent = 0;
  while (sent < frame.size()) {
    const ssize_t k = ::send(fd, frame.data() + sent, frame.size() - sent, MSG_NOSIGNAL);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    sent += static_cast<std::size_t>(k);
  }
  return true;
}

bool receive_exactly(int fd, char* data, std::size_t n) {
  std::size_t got = 0;
  while (got < n) {
    const ssize_t k = ::recv(fd, data + got, n - got, 0);
    if (k < 0 && errno == EINTR) continue;
    if (k <= 0) return false;
    got += static_cast<std::size_t>(k);
  }
  return true;
}

// Whether `fd` has something to read (a frame, or the end of the connection), checking without
// sleeping, with the core yielded between checks, until `within` has passed.
bool readable_within(int fd, std::chrono::microseconds within) {
  const auto deadline = std::chrono::steady_clock::now() + within;
  char byte = 0;
  do {
    const ssize_t k = ::recv(fd, &byte, 1, MSG_DONTWAIT | MSG_PEEK);
    if (k >= 0 || (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) return true;
    ::sched_yield();
  } while (std::chrono::steady_clock::now() < deadline);
  return false;
}

// Receives one frame (blocking); false when the other end is gone.
bool receive_frame(int fd, std::string& payload) {
  std::uint64_t n = 0;
  if (!receive_exactly(fd, reinterpret_cast<char*>(&n), sizeof n)) return false;
  payload.resize(n);
  return receive_exactly(fd, payload.data(), n);
}

Writer error_reply() {
  Writer reply(Status::kError);
  ErrorKind kind = ErrorKind::kRuntime;
  std::string message;
  try {
    throw;
  } catch (const ResetNeeded& e) {
    kind = ErrorKind::kResetNeeded;
    message = e.what();
  } catch (const std::invalid_argument& e) {
    kind = ErrorKind::kInvalidArgument;
    message = e.what();
  } catch (const std::out_of_range& e) {
    kind = ErrorKind::kOutOfRange;
    message = e.what();
  } catch (const std::exception& e) {
    message = e.what();
  } catch (...) {
    message = "an exception of unknown type";
  }
  reply.u8(static_cast<std::uint8_t>(kind));
  reply.str(message);
  return reply;
}

// ---- Values in shared memory. -------------------------------------------------------------

constexpr std::size_t kAlign = 64;

std::size_t aligned(std::size_t n) { return (n + kAlign - 1) / kAlign * kAlign; }

std::size_t layout_bytes(const Value& value) {
  std::size_t bytes = 0;
  for (const Array& leaf : value.leaves()) bytes += aligned(leaf.nbytes());
  return bytes;
}

// A Value of `value`'s structure (Dicts and Tuples alike) whose arrays are `f(array)`, in order.
template <typename F>
Value map_arrays(const Value& value, const F& f) {
  if (value.is_array()) return f(value.array());
  if (value.is_dict()) {
    ValueDict dict;
    for (std::size_t k = 0; k < value.dict().size(); ++k) {
      dict.insert(value.dict().keys()[k], map_arrays(value.dict().values()[k], f));
    }
    return dict;
  }
  std::vector<Value> items;
  for (const Value& item : value.tuple().items()) items.push_back(map_arrays(item, f));
  return ValueTuple(std::move(items));
}

// A Value of `like`'s structure, dtypes and shapes whose arrays are carved from `cursor`.
Value place(const Value& like, std::byte*& cursor, const std::shared_ptr<void>& owner) {
  return map_arrays(like, [&](const Array& a) {
    Array placed = Array::from_external(cursor, a.dtype(), a.shape(), owner);
    cursor += aligned(a.nbytes());
    return placed;
  });
}

// Rows [begin, end) of every array of a batch, as views.
Value rows(const Value& batch, std::int64_t begin, std::int64_t end) {
  return map_arrays(batch, [&](const Array& a) { return a.slice(begin, end); });
}

// A zero batch of `n` rows with the structure of `part` (whose arrays' leading axis is rows).
Value grown(const Value& part, std::int64_t n) {
  return map_arrays(part, [&](const Array& a) {
    Shape shape = a.shape();
    shape.at(0) = n;
    return Array(a.dtype(), shape);
  });
}

// Adds a worker's batched infos (leading axis: its `count` envs) to `infos` (leading axis: all
// `n` envs) at rows [first, first + count): Dicts are merged key by key, as Gymnasium batches
// infos; anything else is copied into its rows.
void merge_rows(ValueDict& infos, const ValueDict& part, std::int64_t first, std::int64_t count,
                std::int64_t n) {
  for (std::size_t k = 0; k < part.size(); ++k) {
    const std::string& key = part.keys()[k];
    const Value& value = part.values()[k];
    if (value.is_dict()) {
      if (!infos.contains(key)) infos.insert(key, ValueDict{});
      merge_rows(infos.at(key).dict(), value.dict(), first, count, n);
      continue;
    }
    if (!infos.contains(key)) infos.insert(key, grown(value, n));
    try {
      copy_value(value, rows(infos.at(key), first, first + count));
    } catch (const std::exception& e) {
      throw std::invalid_argument("info \"" + key + "\" of envs " + std::to_string(first) + "-" +
                                  std::to_string(first + count - 1) +
                                  " does not batch with another worker's: " + e.what());
    }
  }
}

// The parent's ends of every worker socket this process holds, of every ProcessVectorEnv: a
// child closes them all at once, or it would keep another worker from seeing its parent close
// (and that vector env's destructor would wait, then kill it).
std::mutex& parent_fds_mutex() {
  static std::mutex mutex;
  return mutex;
}
std::vector<int>& parent_fds() {
  static std::vector<int> fds;
  return fds;
}
void add_parent_fd(int fd) {
  const std::lock_guard<std::mutex> lock(parent_fds_mutex());
  parent_fds().push_back(fd);
}
void remove_parent_fd(int fd) {
  const std::lock_guard<std::mutex> lock(parent_fds_mutex());
  std::vector<int>& fds = parent_fds();
  fds.erase(std::remove(fds.begin(), fds.end(), fd), fds.end());
}
std::vector<int> parent_fds_now() {
  const std::lock_guard<std::mutex> lock(parent_fds_mutex());
  return parent_fds();
}

std::string describe_exit(int status) {
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    const char* what = ::strsignal(sig);
    return "killed by signal " + std::to_string(sig) +
           (what != nullptr ? " (" + std::string(what) + ")" : "");
  }
  if (WIFEXITED(status)) return "exited with status " + std::to_string(WEXITSTATUS(status));
  return "ended";
}

// The BatchRunner a worker runs its envs with: a loop, whose results go to the worker's rows of
// the shared batch and whose errors name the envs by their index in the whole vector env.
class WorkerRunner final : public BatchRunner {
 public:
  WorkerRunner(int first, int count, int total, int worker, const EnvFactory& make_env,
               AutoresetMode autoreset, const BatchBuffers& buffers)
      : BatchRunner("ProcessVectorEnv", count, autoreset),
        first_(first),
        worker_(worker),
        name_(process_name("", total)),
        total_(total) {
    build([&](int j) { return make_env(first_ + j); }, &buffers);
    if (env(0).spec() != nullptr) name_ = process_name(env(0).spec()->id, total_);
  }
  ~WorkerRunner() override { destroy_envs(); }

  std::string name() const override { return name_; }
  std::string id() const { return env(0).spec() != nullptr ? env(0).spec()->id : ""; }

 protected:
  void start_all() override {
    for (int j = 0; j < num_envs(); ++j) run_env(j);
  }
  void wait_all() override {}
  std::string env_context(int j, const std::string& env_name) const override {
    return "env " + std::to_string(first_ + j) + " (" + env_name + ") on worker " +
           std::to_string(worker_) + " (pid " + std::to_string(::getpid()) + ")";
  }

 private:
  int first_;
  int worker_;
  std::string name_;
  int total_;
};

// Runs `command` on `runner` (the envs of one worker, whose actions are `actions`) and returns
// the reply; `content` false when the reply says only "done" (a reset or step without infos).
Writer serve(WorkerRunner& runner, const std::string& command, const Value& actions,
             bool& content) {
  Writer reply(Status::kOk);
  content = true;
  const auto infos = [&](const Info& batched) {
    content = !batched.empty();
    if (content) reply.value(batched);
  };
  try {
    Reader in(command);
    switch (static_cast<Op>(in.u8())) {
      case Op::kReset: {
        std::optional<std::uint64_t> seed;
        if (in.u8() != 0) seed = in.u64();
        const Params options = in.params();
        if (in.u8() != 0) {
          Array mask(DType::kBool, {runner.num_envs()});
          for (int j = 0; j < runner.num_envs(); ++j) mask.data<bool>()[j] = in.u8() != 0;
          infos(runner.reset(seed, options, mask).infos);
        } else {
          infos(runner.reset(seed, options).infos);
        }
        break;
      }
      case Op::kStep:
        infos(runner.step(actions).infos);
        break;
      case Op::kRender: {
        const std::vector<Array> frames = runner.render();
        reply.u64(frames.size());
        for (const Array& frame : frames) reply.array(frame);
        break;
      }
      case Op::kClose:
        runner.close();
        break;
    }
  } catch (...) {
    content = true;
    return error_reply();
  }
  return reply;
}

}  // namespace

// The shared mapping: how a call is going, then the batch arrays the parent and the workers both
// see.
struct ProcessVectorEnv::Shared {
  // The workers still running the current call. The one that brings it to 0 wakes the parent
  // when the parent sleeps: one wakeup per call, however many workers.
  struct alignas(kAlign) Control {
    std::atomic<std::int32_t> remaining{0};
    alignas(kAlign) std::atomic<std::int32_t> parent_sleeping{0};
  };
  // Whether worker w sent a reply frame for the current call (else: done, nothing to report).
  // Also: steps ordered (a step has no arguments to send, the actions being in the batch: the
  // parent bumps `steps` instead of sending a frame) and whether the worker sleeps (the parent
  // then sends an empty frame to wake it).
  struct alignas(kAlign) Slot {
    std::atomic<std::int32_t> sent{0};
    std::atomic<std::uint32_t> steps{0};
    std::atomic<std::int32_t> sleeping{0};
  };
  static_assert(std::atomic<std::uint32_t>::is_always_lock_free);
  static_assert(std::atomic<std::int32_t>::is_always_lock_free);

  Shared(int workers, std::size_t size)
      : bytes(sizeof(Control) + static_cast<std::size_t>(workers) * sizeof(Slot) + size) {
    void* at = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
    if (at == MAP_FAILED) {
      throw std::runtime_error("ProcessVectorEnv: cannot map " + std::to_string(bytes) +
                               " bytes of shared memory: " + std::strerror(errno));
    }
    base = static_cast<std::byte*>(at);
    control = new (base) Control;
    slots = new (base + sizeof(Control)) Slot[static_cast<std::size_t>(workers)];
    data = base + sizeof(Control) + static_cast<std::size_t>(workers) * sizeof(Slot);
  }
  ~Shared() { ::munmap(base, bytes); }
  Shared(const Shared&) = delete;
  Shared& operator=(const Shared&) = delete;

  std::size_t bytes;
  std::byte* base = nullptr;
  Control* control = nullptr;
  Slot* slots = nullptr;
  std::byte* data = nullptr;  // the arrays
};

// The envs a worker runs, and where its actions are.
struct ProcessVectorEnv::Block {
  std::unique_ptr<WorkerRunner> runner;
  Value actions;  // its rows of the action batch
};

struct ProcessVectorEnv::Worker {
  int first = 0;  // its envs: [first, first + count)
  int count = 0;
  pid_t pid = -1;
  int fd = -1;       // the parent's end of its socket
  bool own = false;  // the calling process's own share: no process, no socket
  bool reaped = false;
  int status = 0;  // as waitpid says, once reaped

  std::string describe() const {
    return (own ? "this process" : "pid " + std::to_string(pid)) + ", envs " +
           std::to_string(first) + (count > 1 ? "-" + std::to_string(first + count - 1) : "");
  }
};

int ProcessVectorEnv::workers_for(int num_envs, int num_workers) {
  if (num_workers < 0) {
    throw std::invalid_argument(
        "ProcessVectorEnv: num_workers must be >= 0 (0: one per core), got " +
        std::to_string(num_workers));
  }
  if (num_workers == 0) {
    num_workers = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  }
  return std::max(1, std::min(num_workers, num_envs));
}

ProcessVectorEnv::ProcessVectorEnv(int num_envs, const WorkerFactory& make_worker_envs,
                                   std::shared_ptr<const Env> like, int num_workers,
                                   AutoresetMode autoreset, bool caller_steps_envs)
    : num_envs_(num_envs), like_(std::move(like)) {
  if (num_envs < 1) {
    throw std::invalid_argument("ProcessVectorEnv: num_envs must be >= 1, got num_envs = " +
                                std::to_string(num_envs));
  }
  if (like_ == nullptr) throw std::invalid_argument("ProcessVectorEnv: no `like` env given");
  const int workers = workers_for(num_envs, num_workers);
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  spin_ = workers <= cores;
  own_core_ = workers + (caller_steps_envs ? 0 : 1) <= cores;
  observation_space_ = batch_space(like_->observation_space(), num_envs);
  action_space_ = batch_space(like_->action_space(), num_envs);
  static_cast<Metadata&>(metadata_) = like_->metadata();
  metadata_.autoreset_mode = autoreset;

  // The batch, in memory the workers will share.
  const Value obs = observation_space_->zeros();
  const Value actions = action_space_->zeros();
  const Array flags(DType::kBool, {num_envs});
  const Array rewards(DType::kFloat64, {num_envs});
  shared_ = std::make_shared<Shared>(workers, layout_bytes(obs) + layout_bytes(actions) +
                                                  2 * aligned(flags.nbytes()) +
                                                  aligned(rewards.nbytes()));
  const std::shared_ptr<void> owner(shared_, shared_->base);
  std::byte* cursor = shared_->data;
  step_result_.obs = place(obs, cursor, owner);
  reset_result_.obs = step_result_.obs;
  actions_ = place(actions, cursor, owner);
  step_result_.rewards = place(rewards, cursor, owner).array();
  step_result_.terminated = place(flags, cursor, owner).array();
  step_result_.truncated = place(flags, cursor, owner).array();
  ended_.assign(static_cast<std::size_t>(num_envs), 0);

  workers_.resize(static_cast<std::size_t>(workers));
  for (int w = 0; w < workers; ++w) {
    Worker& worker = workers_[static_cast<std::size_t>(w)];
    worker.count = num_envs / workers + (w < num_envs % workers ? 1 : 0);
    worker.first = w == 0 ? 0
                          : workers_[static_cast<std::size_t>(w - 1)].first +
                                workers_[static_cast<std::size_t>(w - 1)].count;
  }
  const int first_child = caller_steps_envs ? 1 : 0;
  if (caller_steps_envs) {
    workers_[0].pid = ::getpid();
    workers_[0].own = true;
  }
  try {
    shared_->control->remaining.store(workers - first_child);
    for (int w = first_child; w < workers; ++w) start_worker(w, make_worker_envs);
    // The children were forked before this process builds any env of its own. Each says,
    // unasked, whether it built its envs.
    std::string own;
    if (caller_steps_envs) {
      try {
        own_ = build_block(0, make_worker_envs);
        Writer made(Status::kOk);
        made.str(own_->runner->id());
        own = made.frame();
      } catch (...) {
        own = error_reply().frame();
      }
    }
    std::vector<std::uint8_t> pending;
    for (int w = 0; w < workers; ++w) pending.push_back(w >= first_child ? 1 : 0);
    std::vector<std::string> replies = await(pending, {}, "the constructor");
    if (caller_steps_envs) replies[0] = own;
    throw_first_error(replies, false);
    id_ = Reader(replies[0]).str();
  } catch (...) {
    own_.reset();
    end_workers();
    throw;
  }
}

ProcessVectorEnv::~ProcessVectorEnv() { end_workers(); }

std::unique_ptr<ProcessVectorEnv::Block> ProcessVectorEnv::build_block(
    int w, const WorkerFactory& make_worker_envs) {
  const Worker& worker = workers_[static_cast<std::size_t>(w)];
  const EnvFactory make_env = make_worker_envs(w);
  const Env& like = *like_;
  const EnvFactory checked = [&](int i) {
    std::unique_ptr<Env> env = make_env(i);
    if (env != nullptr && (!env->observation_space().equals(like.observation_space()) ||
                           !env->action_space().equals(like.action_space()))) {
      throw std::invalid_argument(
          "its spaces " + env->observation_space().to_string() + " / " +
          env->action_space().to_string() + " differ from those the vector env was laid out for: " +
          like.observation_space().to_string() + " / " + like.action_space().to_string());
    }
    return env;
  };
  const std::int64_t begin = worker.first;
  const std::int64_t end = worker.first + worker.count;
  const BatchBuffers buffers{
      rows(step_result_.obs, begin, end), step_result_.rewards.slice(begin, end),
      step_result_.terminated.slice(begin, end), step_result_.truncated.slice(begin, end)};
  auto block = std::make_unique<Block>();
  block->runner = std::make_unique<WorkerRunner>(worker.first, worker.count, num_envs_, w, checked,
                                                 metadata_.autoreset_mode, buffers);
  block->actions = rows(actions_, begin, end);
  return block;
}

void ProcessVectorEnv::start_worker(int w, const WorkerFactory& make_worker_envs) {
  Worker& worker = workers_[static_cast<std::size_t>(w)];
  int ends[2];
  if (::socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, ends) != 0) {
    throw std::runtime_error(name() + ": cannot start worker " + std::to_string(w) +
                             ": socketpair: " + std::strerror(errno));
  }
  // Taken before fork(): the child must not lock what another thread may hold at that moment.
  const std::vector<int> inherited = parent_fds_now();
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int error = errno;
    ::close(ends[0]);
    ::close(ends[1]);
    throw std::runtime_error(name() + ": cannot start worker " + std::to_string(w) +
                             ": fork: " + std::strerror(error));
  }
  if (pid > 0) {
    ::close(ends[1]);
    worker.pid = pid;
    worker.fd = ends[0];
    add_parent_fd(worker.fd);
    return;
  }
  // The worker: whatever goes wrong, it must never return into a copy of the caller's program.
  try {
    serve_as_worker(w, ends, inherited, make_worker_envs);
  } catch (...) {
  }
  ::_exit(2);
}

void ProcessVectorEnv::serve_as_worker(int w, const int ends[2], const std::vector<int>& inherited,
                                       const WorkerFactory& make_worker_envs) {
  // It keeps only its own end of its socket: a worker that holds another's would keep the parent
  // from seeing that one die.
  ::close(ends[0]);
  for (const int fd : inherited) ::close(fd);
  const int fd = ends[1];
  Shared& shared = *shared_;
  // Answers a call: `reply` is sent unless it says only "done" (`content` false). False: the
  // parent is gone. Counts this worker done first, waking the parent when it is the last one and
  // the parent sleeps, and only then sends the reply: so any wakeup goes out while the parent still
  // watches this worker's socket (it stops once it has read the reply), and a worker that dies
  // after counting itself done is seen as the end of its socket where its reply should be.
  const auto answer = [&](const Writer& reply, bool content) {
    shared.slots[w].sent.store(content ? 1 : 0, std::memory_order_relaxed);
    if (shared.control->remaining.fetch_sub(1) == 1 &&
        shared.control->parent_sleeping.load() != 0 && !send_frame(fd, std::string())) {
      return false;
    }
    return !content || send_frame(fd, reply.frame());
  };
  {
    std::unique_ptr<Block> block;
    try {
      block = build_block(w, make_worker_envs);
      Writer made(Status::kOk);
      made.str(block->runner->id());
      if (!answer(made, true)) ::_exit(0);
    } catch (...) {
      answer(error_reply(), true);
      ::_exit(1);
    }
    Shared::Slot& slot = shared.slots[w];
    std::uint32_t steps = 0;
    std::string command;
    // The next command: a step ordered through `slot`, or a frame on the socket (empty frames
    // are wakeups). False: the parent is gone.
    const auto next_command = [&] {
      const auto ordered = [&] { return slot.steps.load(std::memory_order_acquire) != steps; };
      for (;;) {
        const auto deadline = std::chrono::steady_clock::now() + kSpin;
        bool readable = false;
        for (unsigned k = 1; spin_ && !readable && !ordered(); ++k) {
          if (k % (own_core_ ? 64 : 8) == 0) {
            readable = readable_within(fd, std::chrono::microseconds(0));
            if (std::chrono::steady_clock::now() >= deadline) break;
          }
          pause_or_yield(own_core_);
        }
        if (!readable && !ordered()) {
          slot.sleeping.store(1);
          // seq_cst, as the parent's bump and its look at `sleeping`: one of the two sees the
          // other.
          if (slot.steps.load() == steps) {
            pollfd in{fd, POLLIN, 0};
            while (::poll(&in, 1, -1) < 0 && errno == EINTR) {
            }
          }
          slot.sleeping.store(0);
        }
        if (ordered()) {
          ++steps;
          command.assign(1, static_cast<char>(Op::kStep));
          return true;
        }
        if (!receive_frame(fd, command)) return false;
        if (!command.empty()) return true;
      }
    };
    while (next_command()) {
      bool content = true;
      const Writer reply = serve(*block->runner, command, block->actions, content);
      if (!answer(reply, content) || static_cast<Op>(command.at(0)) == Op::kClose) break;
    }
  }
  // Not exit(): the parent's atexit handlers and static destructors are the parent's.
  ::_exit(0);
}

std::vector<std::string> ProcessVectorEnv::call(const std::vector<std::string>& commands,
                                                const char* method) {
  const std::size_t n = workers_.size();
  std::vector<std::uint8_t> pending(n, 0);
  std::vector<std::uint8_t> died(n, 0);
  const std::size_t first_child = own_ != nullptr ? 1 : 0;
  std::int32_t asked = 0;
  for (std::size_t w = first_child; w < n; ++w) asked += commands[w].empty() ? 0 : 1;
  shared_->control->remaining.store(asked);
  for (std::size_t w = first_child; w < n; ++w) {
    if (commands[w].empty()) continue;
    Shared::Slot& slot = shared_->slots[w];
    bool sent = true;
    if (static_cast<Op>(commands[w][0]) == Op::kStep) {
      slot.steps.fetch_add(1);
      if (slot.sleeping.load() != 0) sent = send_frame(workers_[w].fd, std::string());
    } else {
      sent = send_frame(workers_[w].fd, commands[w]);
    }
    (sent ? pending : died)[w] = 1;
  }
  // This process's own envs step while the children step theirs.
  std::string own;
  if (own_ != nullptr && !commands[0].empty()) {
    bool content = true;
    own = serve(*own_->runner, commands[0], own_->actions, content).frame();
  }
  std::vector<std::string> replies = await(std::move(pending), std::move(died), method);
  if (own_ != nullptr) replies[0] = std::move(own);
  return replies;
}

std::vector<std::string> ProcessVectorEnv::await(std::vector<std::uint8_t> pending,
                                                 std::vector<std::uint8_t> died,
                                                 const char* method) {
  const std::size_t n = workers_.size();
  std::vector<std::string> replies(n);
  died.resize(n, 0);
  Shared::Control& control = *shared_->control;
  const auto any_died = [&] {
    return std::any_of(died.begin(), died.end(), [](auto d) { return d != 0; });
  };
  // Reads one frame of worker w's: a reply is kept (and the worker is not watched again in this
  // call: one that replies and then exits, as after a failed build, has answered), a wakeup
  // ignored; the end of the connection means the worker is gone.
  const auto read_frame = [&](std::size_t w) {
    std::string frame;
    if (!receive_frame(workers_[w].fd, frame)) {
      died[w] = 1;
    } else if (!frame.empty()) {
      replies[w] = std::move(frame);
      pending[w] = 0;  // it counted itself done before it sent its reply
    }
  };
  std::vector<pollfd> fds;
  std::vector<std::size_t> which;
  // First without sleeping (see kParentSpin).
  const auto spin_until = std::chrono::steady_clock::now() + kParentSpin;
  for (unsigned k = 1; spin_ && control.remaining.load() != 0; ++k) {
    if (k % 64 == 0 && std::chrono::steady_clock::now() >= spin_until) break;
    pause_or_yield(own_core_);
  }
  while (!any_died()) {
    // Sleep until the last worker done wakes us (see Shared::Control), a worker's connection
    // ends, or kPollMs pass.
    control.parent_sleeping.store(1);
    if (control.remaining.load() == 0) {
      control.parent_sleeping.store(0);
      break;
    }
    fds.clear();
    which.clear();
    for (std::size_t w = 0; w < n; ++w) {
      if (pending[w] == 0) continue;
      fds.push_back(pollfd{workers_[w].fd, POLLIN, 0});
      which.push_back(w);
    }
    const int ready = ::poll(fds.data(), fds.size(), kPollMs);
    control.parent_sleeping.store(0);
    if (ready < 0 && errno != EINTR) {
      dead_ = true;  // the workers may still be running this call
      throw std::runtime_error(name() + ": " + method + ": poll: " + std::strerror(errno));
    }
    for (std::size_t k = 0; k < fds.size(); ++k) {
      const std::size_t w = which[k];
      if (fds[k].revents != 0) {
        read_frame(w);
      } else if (ready == 0 && !workers_[w].reaped) {
        // No word for a while: has it ended without its socket saying so?
        int status = 0;
        if (::waitpid(workers_[w].pid, &status, WNOHANG) == workers_[w].pid) {
          workers_[w].reaped = true;
          workers_[w].status = status;
          died[w] = 1;
        }
      }
    }
  }
  // Every worker is done: collect the replies still in their sockets.
  for (std::size_t w = 0; w < n && !any_died(); ++w) {
    if (pending[w] == 0 || !replies[w].empty()) continue;
    if (shared_->slots[w].sent.load(std::memory_order_relaxed) == 0) {
      replies[w] = std::string(1, static_cast<char>(Status::kOk));
      continue;
    }
    while (replies[w].empty() && died[w] == 0) read_frame(w);
  }
  for (std::size_t w = 0; w < n; ++w) {
    if (died[w] == 0) continue;
    Worker& worker = workers_[w];
    // Its socket closed as it ended: it is exiting or gone. Wait briefly to say how it ended.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
    while (!worker.reaped && std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      const pid_t got = ::waitpid(worker.pid, &status, WNOHANG);
      if (got == worker.pid || (got < 0 && errno == ECHILD)) {
        worker.reaped = true;
        worker.status = got == worker.pid ? status : 0;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    dead_ = true;
    throw std::runtime_error(
        name() + ": " + method + ": worker " + std::to_string(w) + " (" + worker.describe() + ") " +
        (worker.reaped ? describe_exit(worker.status) : "closed its connection") +
        "; the vector env cannot go on: close() it and make another");
  }
  return replies;
}

void ProcessVectorEnv::throw_first_error(std::vector<std::string>& replies, bool poison) {
  for (std::string& reply : replies) {
    if (reply.empty()) continue;
    Reader in(reply);
    if (static_cast<Status>(in.u8()) == Status::kOk) {
      reply.erase(0, 1);
      continue;
    }
    if (poison) failed_ = true;
    const auto kind = static_cast<ErrorKind>(in.u8());
    const std::string message = in.str();
    switch (kind) {
      case ErrorKind::kResetNeeded:
        throw ResetNeeded(message);
      case ErrorKind::kInvalidArgument:
        throw std::invalid_argument(message);
      case ErrorKind::kOutOfRange:
        throw std::out_of_range(message);
      case ErrorKind::kRuntime:
        break;
    }
    throw std::runtime_error(message);
  }
}

void ProcessVectorEnv::end_workers() noexcept {
  // A worker whose socket closes destroys its envs and exits.
  for (Worker& worker : workers_) {
    if (worker.fd >= 0) {
      remove_parent_fd(worker.fd);
      ::close(worker.fd);
    }
    if (worker.own) worker.reaped = true;
    worker.fd = -1;
  }
  const auto deadline = std::chrono::steady_clock::now() + kExitWait;
  for (Worker& worker : workers_) {
    if (worker.pid <= 0 || worker.reaped) continue;
    for (;;) {
      int status = 0;
      const pid_t got = ::waitpid(worker.pid, &status, WNOHANG);
      if (got == worker.pid || (got < 0 && errno != EINTR)) break;
      if (std::chrono::steady_clock::now() >= deadline) {
        ::kill(worker.pid, SIGKILL);
        while (::waitpid(worker.pid, &status, 0) < 0 && errno == EINTR) {
        }
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    worker.reaped = true;
  }
}

std::string ProcessVectorEnv::name() const { return process_name(id_, num_envs_); }

const Env& ProcessVectorEnv::env(int i) const {
  if (i < 0 || i >= num_envs_) throw std::out_of_range(name() + ": no env " + std::to_string(i));
  return *like_;
}

int ProcessVectorEnv::num_workers() const { return static_cast<int>(workers_.size()); }

int ProcessVectorEnv::worker_pid(int w) const {
  if (w < 0 || w >= num_workers()) {
    throw std::out_of_range(name() + ": no worker " + std::to_string(w));
  }
  return workers_[static_cast<std::size_t>(w)].pid;
}

void ProcessVectorEnv::require_usable(const char* method) const {
  if (closed_) throw ResetNeeded(name() + ": " + method + " called after close()");
  if (dead_) {
    throw ResetNeeded(name() + ": " + method +
                      " called after a worker died; close() this vector env and make another");
  }
}

void ProcessVectorEnv::batch_infos(const std::vector<std::string>& replies, Info& infos) {
  infos.clear();
  try {
    for (std::size_t w = 0; w < workers_.size(); ++w) {
      if (replies[w].empty()) continue;
      const Worker& worker = workers_[w];
      merge_rows(infos, Reader(replies[w]).value().dict(), worker.first, worker.count, num_envs_);
    }
  } catch (const std::invalid_argument& e) {
    failed_ = true;
    throw std::invalid_argument(name() + ": " + e.what());
  }
}

const VectorResetResult& ProcessVectorEnv::do_reset(std::optional<std::uint64_t> seed,
                                                    const Options& options,
                                                    const Array* reset_mask) {
  if (reset_mask != nullptr) check_reset_mask(*this, *reset_mask, failed_);
  require_usable("reset()");
  std::vector<std::string> commands(workers_.size());
  for (std::size_t w = 0; w < workers_.size(); ++w) {
    const Worker& worker = workers_[w];
    const bool* mask = reset_mask != nullptr ? reset_mask->data<bool>() + worker.first : nullptr;
    if (mask != nullptr && std::none_of(mask, mask + worker.count, [](bool b) { return b; })) {
      continue;
    }
    Writer command(Op::kReset);
    command.u8(seed ? 1 : 0);
    command.u64(seed ? *seed + static_cast<std::uint64_t>(worker.first) : 0);
    command.params(options);
    command.u8(mask != nullptr ? 1 : 0);
    for (int j = 0; mask != nullptr && j < worker.count; ++j) command.u8(mask[j] ? 1 : 0);
    commands[w] = command.frame();
  }
  std::vector<std::string> replies = call(commands, "reset()");
  throw_first_error(replies, true);
  if (reset_mask == nullptr) {
    failed_ = false;
    has_reset_ = true;
  }
  batch_infos(replies, reset_result_.infos);
  for (int i = 0; i < num_envs_; ++i) {
    if (reset_mask == nullptr || reset_mask->data<bool>()[i])
      ended_[static_cast<std::size_t>(i)] = 0;
  }
  return reset_result_;
}

const VectorStepResult& ProcessVectorEnv::do_step(const Value& actions) {
  require_usable("step()");
  if (failed_) throw ResetNeeded(name() + ": step() after a failed call; call reset() first");
  if (!has_reset_) throw ResetNeeded(name() + ": step() called before reset()");
  check_actions(*this, actions, "step()");
  check_none_ended(*this, ended_, "step()");
  copy_value(actions, actions_);
  const std::vector<std::string> commands(workers_.size(), Writer(Op::kStep).frame());
  std::vector<std::string> replies = call(commands, "step()");
  throw_first_error(replies, true);
  batch_infos(replies, step_result_.infos);
  const bool* terminated = step_result_.terminated.data<bool>();
  const bool* truncated = step_result_.truncated.data<bool>();
  for (std::size_t i = 0; i < ended_.size(); ++i) {
    ended_[i] = terminated[i] || truncated[i] ? 1 : 0;
  }
  return step_result_;
}

std::vector<Array> ProcessVectorEnv::render() {
  require_usable("render()");
  const std::vector<std::string> commands(workers_.size(), Writer(Op::kRender).frame());
  std::vector<std::string> replies = call(commands, "render()");
  throw_first_error(replies, false);
  std::vector<Array> frames;
  frames.reserve(static_cast<std::size_t>(num_envs_));
  for (const std::string& reply : replies) {
    Reader in(reply);
    for (std::uint64_t k = in.u64(); k > 0; --k) frames.push_back(in.array());
  }
  return frames;
}

void ProcessVectorEnv::close() {
  if (closed_) return;
  closed_ = true;
  std::vector<std::string> replies;
  std::exception_ptr error;
  if (!dead_) {
    try {
      replies =
          call(std::vector<std::string>(workers_.size(), Writer(Op::kClose).frame()), "close()");
    } catch (...) {
      error = std::current_exception();
    }
  }
  end_workers();
  if (error) std::rethrow_exception(error);
  throw_first_error(replies, false);
}

}  // namespace pixelgym::vector
