// What the distributed tests share: fresh folders, free ports, tiny `pixelgym train` command
// lines, and the processes of a run (started with an environment, waited for with a deadline,
// found by their RANK).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace pixelgym::testing {

using Clock = std::chrono::steady_clock;

/// An empty folder of the temporary folder, named after `name` and this process.
inline std::filesystem::path fresh_folder(const std::string& name) {
  const std::filesystem::path folder =
      std::filesystem::temp_directory_path() /
      ("pixelgym_distributed_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  return folder;
}

/// The whole of a file ("" when it cannot be read).
inline std::string read_text(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A free port on 127.0.0.1 for a test's rendezvous, from the kernel.
inline int test_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t length = sizeof(address);
  if (fd < 0 || ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
    if (fd >= 0) ::close(fd);
    return 29000 + static_cast<int>(::getpid() % 1000) * 2;
  }
  ::close(fd);
  return ntohs(address.sin_port);
}

constexpr const char* kTinyConfig =
    R"({"num_steps": 16, "num_minibatches": 2, "update_epochs": 2, "anneal_learning_rate": false})";

/// `train` of a tiny PPO run (32x32 pixels, 2 envs of 16-step rollouts, its config written
/// into `folder`), then `more`.
inline std::string train_arguments(const std::filesystem::path& folder, const std::string& more) {
  const std::filesystem::path config_file = folder / "tiny.json";
  std::ofstream(config_file) << kTinyConfig;
  return "train CartPoleBalance-v0 --set obs_mode=pixels+state --set width=32 --set height=32 "
         "--set max_episode_steps=24 --num-envs 2 --threads 1 --config " +
         config_file.string() + " --eval-episodes 1 --eval-every 0 --quiet " + more;
}

/// Starts `pixelgym ARGUMENTS` (PIXELGYM_CLI) with `environment` ("NAME=value ...") added to
/// this process's, its stdout and stderr into `log`. Returns its pid (pixelgym's own: the shell
/// and env exec it).
inline pid_t start_cli(const std::string& environment, const std::string& arguments,
                       const std::filesystem::path& log) {
  const std::string command = "exec env " + environment + " " + std::string(PIXELGYM_CLI) + " " +
                              arguments + " > " + log.string() + " 2>&1";
  const pid_t pid = ::fork();
  if (pid == 0) {
    ::execl("/bin/sh", "sh", "-c", command.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  return pid;
}

/// How a process started by start_cli ended.
struct Ended {
  int exit_code = -1;    // -1: killed at the deadline, or by a signal
  double seconds = 0.0;  // from `start` to its end (or the deadline)
  std::string output;    // its log
};

/// A process started by start_cli, and its log.
struct Started {
  pid_t pid = -1;
  std::filesystem::path log;
};

/// Waits for every process of `started` until `deadline`, then kills those left (a hang fails
/// the test instead of blocking it). Each one's end is timed from `start`.
inline std::vector<Ended> wait_all(const std::vector<Started>& started, Clock::time_point start,
                                   Clock::time_point deadline) {
  std::vector<Ended> ended(started.size());
  std::vector<bool> done(started.size(), false);
  std::size_t left = started.size();
  while (left > 0) {
    const bool late = Clock::now() >= deadline;
    for (std::size_t i = 0; i < started.size(); ++i) {
      if (done[i]) continue;
      int status = 0;
      if (late) {
        ::kill(started[i].pid, SIGKILL);
        ::waitpid(started[i].pid, &status, 0);
        status = -1;
      } else if (::waitpid(started[i].pid, &status, WNOHANG) == 0) {
        continue;
      }
      done[i] = true;
      --left;
      ended[i].seconds = std::chrono::duration<double>(Clock::now() - start).count();
      ended[i].exit_code = !late && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      ended[i].output = read_text(started[i].log);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return ended;
}

/// The pid of the child of `parent` whose environment has RANK=`rank`, or -1.
inline pid_t rank_pid(pid_t parent, int rank) {
  for (const auto& entry : std::filesystem::directory_iterator("/proc")) {
    const std::string name = entry.path().filename();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::istringstream stat(read_text(entry.path() / "stat"));
    std::string pid, comm, state;
    pid_t ppid = 0;
    stat >> pid >> comm >> state >> ppid;
    if (ppid != parent) continue;
    std::string environ = read_text(entry.path() / "environ");
    std::replace(environ.begin(), environ.end(), '\0', '\n');
    if (("\n" + environ).find("\nRANK=" + std::to_string(rank) + "\n") != std::string::npos) {
      return static_cast<pid_t>(std::stol(name));
    }
  }
  return -1;
}

/// Whether process `pid` still runs (a zombie, ended but not yet reaped, does not).
inline bool running(pid_t pid) {
  std::istringstream stat(read_text("/proc/" + std::to_string(pid) + "/stat"));
  std::string number, comm, state;
  stat >> number >> comm >> state;
  return !state.empty() && state != "Z" && state != "X";
}

}  // namespace pixelgym::testing
