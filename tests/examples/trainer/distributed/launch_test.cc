// Launches of data-parallel runs that go wrong, and what each rank then says and how soon: a
// rank that never comes, a RANK given twice, MASTER_PORT another service's port, variables that
// are not numbers in range, a rank whose command line is not rank 0's; and what `train --nproc`
// leaves open (nothing beyond loopback) and behind (no rank, once the launcher is killed). Every
// process has a deadline, so that a hang fails its test rather than blocking ctest.
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <iostream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/trainer/progress_csv.h"
#include "tests/examples/cli_run.h"
#include "tests/examples/trainer/distributed/rank_processes.h"

namespace pixelgym::testing {
namespace {

namespace fs = std::filesystem;

// The variables of rank `rank` of `world` meeting at 127.0.0.1:`port`.
std::string rank_environment(int world, int rank, int port) {
  return "WORLD_SIZE=" + std::to_string(world) + " RANK=" + std::to_string(rank) +
         " MASTER_ADDR=127.0.0.1 MASTER_PORT=" + std::to_string(port);
}

// A socket listening on 127.0.0.1 at a port of the kernel's choosing; closed with the object.
class Listener {
 public:
  Listener() {
    fd_ = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t length = sizeof(address);
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0 ||
        ::getsockname(fd_, reinterpret_cast<sockaddr*>(&address), &length) != 0 ||
        ::listen(fd_, 16) != 0) {
      throw std::runtime_error("cannot listen on 127.0.0.1");
    }
    port_ = ntohs(address.sin_port);
  }
  ~Listener() { ::close(fd_); }
  Listener(const Listener&) = delete;
  Listener& operator=(const Listener&) = delete;
  int fd() const { return fd_; }
  int port() const { return port_; }

 private:
  int fd_ = -1;
  int port_ = 0;
};

// Whether something accepts connections on 127.0.0.1:`port` before `deadline`.
bool wait_for_port(int port, Clock::time_point deadline) {
  while (Clock::now() < deadline) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = htons(static_cast<std::uint16_t>(port));
    const bool open = ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0;
    ::close(fd);
    if (open) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// The start of `pixelgym train` up to its rendezvous: 2 s here, 4.4 s under ASan, more on a
// loaded CI machine. Bounds measured from a process's start allow this much for it.
constexpr double kStartSlack = 20.0;

// Seconds from `start` until rank 0's store opens on `port` (at most until `deadline`).
double seconds_until_served(int port, Clock::time_point start, Clock::time_point deadline) {
  wait_for_port(port, deadline);
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// A rank other than 0 alone, or rank 0 alone: each names what it waited for, and ends within
// the join timeout instead of waiting for a rank that never comes.
TEST(LaunchTest, ARankThatNeverComesIsNamedWithinTheJoinTimeout) {
  const fs::path folder = fresh_folder("never_comes");
  const int join_s = 2;
  const std::string arguments =
      train_arguments(folder, "--steps 64 --dist-join-timeout " + std::to_string(join_s) +
                                  " --out " + (folder / "run").string());
  const int port = test_port();
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::seconds(60);
  const std::vector<Started> started = {
      {start_cli(rank_environment(2, 0, port), arguments, folder / "0.txt"), folder / "0.txt"},
      {start_cli(rank_environment(2, 1, test_port()), arguments, folder / "1.txt"),
       folder / "1.txt"}};
  const double served_at = seconds_until_served(port, start, deadline);
  const std::vector<Ended> ended = wait_all(started, start, deadline);
  const Ended& alone_zero = ended[0];
  const Ended& alone_one = ended[1];
  // Rank 0 serves its store, then waits for the others: the join timeout counts from then.
  const double waited = alone_zero.seconds - served_at;
  std::cout << "rank 0 alone ended after " << alone_zero.seconds << " s, " << waited
            << " s after its store opened; rank 1 alone after " << alone_one.seconds << " s\n";

  EXPECT_EQ(alone_zero.exit_code, 1) << alone_zero.output;
  EXPECT_NE(alone_zero.output.find("rank 0 of 2: rank 1 has not joined the rendezvous"),
            std::string::npos)
      << alone_zero.output;
  EXPECT_NE(alone_zero.output.find("within 2 s (--dist-join-timeout)"), std::string::npos)
      << alone_zero.output;
  EXPECT_GE(waited, join_s - 0.5) << alone_zero.output;
  EXPECT_LT(waited, join_s + 5.0) << alone_zero.output;
  EXPECT_LT(alone_zero.seconds, join_s + kStartSlack) << alone_zero.output;
  EXPECT_FALSE(fs::exists(folder / "run")) << "rank 0 wrote its run folder before the others came";

  EXPECT_EQ(alone_one.exit_code, 1) << alone_one.output;
  EXPECT_NE(alone_one.output.find("rank 1 of 2: nothing answered at MASTER_ADDR:MASTER_PORT"),
            std::string::npos)
      << alone_one.output;
  EXPECT_LT(alone_one.seconds, join_s + kStartSlack) << alone_one.output;
  fs::remove_all(folder);
}

// WORLD_SIZE=3 with RANK 0, 1 and 1: the second rank 1 is refused as soon as it arrives (a
// usage error), and rank 0 and the first rank 1 name rank 2, which never comes.
TEST(LaunchTest, ARankGivenTwiceIsRefusedAndTheMissingRankNamed) {
  const fs::path folder = fresh_folder("twice");
  const int port = test_port();
  const std::string arguments =
      train_arguments(folder, "--steps 64 --out " + (folder / "run").string());
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::seconds(90);
  // The two rank 1s start first and wait (up to 60 s) for rank 0's store, so that both are
  // there within rank 0's 4 s.
  std::vector<Started> started;
  for (const char* log : {"1a.txt", "1b.txt"}) {
    started.push_back({start_cli(rank_environment(3, 1, port),
                                 arguments + " --dist-join-timeout 60", folder / log),
                       folder / log});
  }
  started.push_back({start_cli(rank_environment(3, 0, port), arguments + " --dist-join-timeout 4",
                               folder / "0.txt"),
                     folder / "0.txt"});
  const double served_at = seconds_until_served(port, start, deadline);
  const std::vector<Ended> ended = wait_all(started, start, deadline);
  const Ended& ended_a = ended[0];
  const Ended& ended_b = ended[1];
  const Ended& ended_zero = ended[2];
  const double waited = ended_zero.seconds - served_at;
  std::cout << "rank 0 ended after " << ended_zero.seconds << " s (" << waited
            << " s after its store opened), the rank 1s after " << ended_a.seconds << " s and "
            << ended_b.seconds << " s\n";

  EXPECT_EQ(ended_zero.exit_code, 1) << ended_zero.output;
  EXPECT_NE(ended_zero.output.find("rank 0 of 3: rank 2 has not joined the rendezvous"),
            std::string::npos)
      << ended_zero.output;
  EXPECT_LT(waited, 4.0 + 5.0) << ended_zero.output;
  // One rank 1 joined and waits for rank 2 with rank 0; the other is refused.
  const bool a_refused = ended_a.output.find("another process") != std::string::npos;
  const Ended& refused = a_refused ? ended_a : ended_b;
  const Ended& joined = a_refused ? ended_b : ended_a;
  EXPECT_EQ(refused.exit_code, 2) << ended_a.output << "\n---\n" << ended_b.output;
  EXPECT_NE(refused.output.find("rank 1 of 3: another process has already joined the run at "
                                "MASTER_ADDR:MASTER_PORT 127.0.0.1:" +
                                std::to_string(port) + " as rank 1 (RANK=1 given to two"),
            std::string::npos)
      << refused.output;
  EXPECT_LT(refused.seconds, ended_zero.seconds) << "refused only when rank 0 gave up";
  EXPECT_EQ(joined.exit_code, 1) << joined.output;
  EXPECT_NE(joined.output.find("rank 1 of 3: rank 0 stopped waiting: rank 2 has not joined"),
            std::string::npos)
      << joined.output;
  EXPECT_LT(joined.seconds, 4.0 + kStartSlack) << joined.output;
  fs::remove_all(folder);
}

// MASTER_PORT of a program that is not rank 0's store: one that accepts connections and never
// answers (as `python3 -m http.server` does to c10d's requests, which hold no newline), and one
// that answers as an HTTP server would. Each rank 1 is refused within seconds, naming the port.
TEST(LaunchTest, AMasterPortOfAnotherServiceIsRefusedWithinSeconds) {
  const fs::path folder = fresh_folder("foreign");
  const Listener silent;  // the kernel accepts its connections; nobody reads or answers
  const Listener talkative;
  std::atomic<bool> stop{false};
  std::thread http([&] {
    while (!stop) {
      pollfd ready{talkative.fd(), POLLIN, 0};
      if (::poll(&ready, 1, 50) <= 0) continue;
      const int connection = ::accept(talkative.fd(), nullptr, nullptr);
      if (connection < 0) continue;
      const std::string reply = "HTTP/1.0 400 Bad request\r\nContent-Length: 0\r\n\r\n";
      (void)!::write(connection, reply.data(), reply.size());
      ::close(connection);
    }
  });
  const std::string arguments = train_arguments(folder, "--steps 64");
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::seconds(60);
  const std::vector<Ended> ended = wait_all(
      {{start_cli(rank_environment(2, 1, silent.port()), arguments, folder / "silent.txt"),
        folder / "silent.txt"},
       {start_cli(rank_environment(2, 1, talkative.port()), arguments, folder / "http.txt"),
        folder / "http.txt"}},
      start, deadline);
  const Ended& silent_end = ended[0];
  const Ended& http_end = ended[1];
  stop = true;
  http.join();
  std::cout << "refused after " << silent_end.seconds << " s (silent) and " << http_end.seconds
            << " s (HTTP)\n";
  for (const Ended* each : {&silent_end, &http_end}) {
    const int port = each == &silent_end ? silent.port() : talkative.port();
    EXPECT_EQ(each->exit_code, 1) << each->output;
    EXPECT_NE(each->output.find("rank 1 of 2: the program at MASTER_ADDR:MASTER_PORT 127.0.0.1:" +
                                std::to_string(port) + " is not rank 0's rendezvous store"),
              std::string::npos)
        << each->output;
    EXPECT_NE(each->output.find("is MASTER_PORT another service's port?"), std::string::npos)
        << each->output;
    // Seconds, not the 60 s join timeout: 0.5 s + 5 s of checks, and the process's start.
    EXPECT_LT(each->seconds, 5.5 + kStartSlack) << each->output;
  }
  fs::remove_all(folder);
}

TEST(LaunchTest, DistributedVariablesOutOfRangeAreUsageErrors) {
  const fs::path folder = fresh_folder("variables");
  const std::string arguments = train_arguments(folder, "--steps 64");
  const std::string port = std::to_string(test_port());
  struct Case {
    std::string environment;
    std::string message;
  };
  for (const Case& c :
       {Case{"WORLD_SIZE=two RANK=0", "WORLD_SIZE must be an integer in [1, 65536], got \"two\""},
        Case{"WORLD_SIZE=2 RANK=2 MASTER_ADDR=127.0.0.1 MASTER_PORT=" + port,
             "RANK must be an integer in [0, 1], got \"2\""},
        Case{"WORLD_SIZE=2 RANK=1 MASTER_ADDR=127.0.0.1 MASTER_PORT=70000",
             "MASTER_PORT must be an integer in [1, 65535], got \"70000\""},
        Case{"WORLD_SIZE=2 RANK=1 MASTER_ADDR=127.0.0.1", "but MASTER_PORT is not set"}}) {
    const CliRun run = run_cli(arguments, "env -u MASTER_PORT " + c.environment);
    EXPECT_EQ(run.exit_code, 2) << c.environment << "\n" << run.output;
    EXPECT_NE(run.output.find(c.message), std::string::npos) << c.environment << "\n" << run.output;
  }
  fs::remove_all(folder);
}

// Every rank runs rank 0's settings; a rank whose command line differs (--num-envs here) is
// refused before the run starts, on both ranks, naming the flag; --out and --quiet may differ.
TEST(LaunchTest, ARankWhoseCommandLineIsNotRankZerosIsRefused) {
  const fs::path folder = fresh_folder("command_line");
  const int port = test_port();
  const std::string common = "--steps 64 ";
  const std::string zero_arguments =
      train_arguments(folder, common + "--out " + (folder / "run").string());
  std::string one_arguments = train_arguments(folder, common + "--out " + (folder / "x").string());
  one_arguments.replace(one_arguments.find("--num-envs 2"), 12, "--num-envs 3");
  const auto start = Clock::now();
  const auto deadline = start + std::chrono::seconds(120);
  const std::vector<Ended> ended =
      wait_all({{start_cli(rank_environment(2, 0, port), zero_arguments, folder / "0.txt"),
                 folder / "0.txt"},
                {start_cli(rank_environment(2, 1, port), one_arguments, folder / "1.txt"),
                 folder / "1.txt"}},
               start, deadline);
  for (const Ended* each : {&ended[0], &ended[1]}) {
    EXPECT_EQ(each->exit_code, 2) << each->output;
    EXPECT_NE(each->output.find("the ranks' command lines differ (--num-envs: 3 on rank 1, 2 on "
                                "rank 0); every rank runs rank 0's settings"),
              std::string::npos)
        << each->output;
  }
  EXPECT_FALSE(fs::exists(folder / "run"));
  fs::remove_all(folder);
}

// A long `train --nproc 2` run, started; the destructor ends it.
class LocalRun {
 public:
  explicit LocalRun(const std::string& name) : folder_(fresh_folder(name)) {
    launcher_ = start_cli(
        "",
        train_arguments(folder_, "--nproc 2 --steps 10000000 --out " + (folder_ / "run").string()),
        folder_ / "log.txt");
  }
  // Ends what is left: the launcher and each rank, by pid (a rank orphaned by a launcher that
  // does not take its ranks with it included), and the launcher's folder for their store.
  ~LocalRun() {
    for (const pid_t pid : {launcher_, ranks_[0], ranks_[1]}) {
      if (pid > 0 && running(pid)) ::kill(pid, SIGKILL);
    }
    if (launcher_ > 0) ::waitpid(launcher_, nullptr, 0);
    if (!store_folder_.empty() &&
        store_folder_.filename().string().rfind("pixelgym-nproc-", 0) == 0) {
      fs::remove_all(store_folder_);
    }
    fs::remove_all(folder_);
  }
  LocalRun(const LocalRun&) = delete;
  LocalRun& operator=(const LocalRun&) = delete;

  // Waits (at most 120 s) for the first progress row: both ranks train. Finds the ranks' pids.
  bool training() {
    const auto deadline = Clock::now() + std::chrono::seconds(120);
    const fs::path progress = folder_ / "run" / "progress.csv";
    while (Clock::now() < deadline &&
           !(fs::exists(progress) && !trainer::read_progress_csv(progress).rows.empty())) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    ranks_ = {rank_pid(launcher_, 0), rank_pid(launcher_, 1)};
    std::string environ = read_text("/proc/" + std::to_string(ranks_[0]) + "/environ");
    std::replace(environ.begin(), environ.end(), '\0', '\n');
    const std::string variable = "\nPIXELGYM_RENDEZVOUS_FILE=";
    const std::size_t at = ("\n" + environ).find(variable);
    if (at != std::string::npos) {
      const std::string file = environ.substr(at + variable.size() - 1);
      store_folder_ = fs::path(file.substr(0, file.find('\n'))).parent_path();
    }
    return ranks_[0] > 0 && ranks_[1] > 0;
  }
  pid_t launcher() const { return launcher_; }
  const std::vector<pid_t>& ranks() const { return ranks_; }
  std::string log() const { return read_text(folder_ / "log.txt"); }

 private:
  fs::path folder_;
  fs::path store_folder_;
  pid_t launcher_ = -1;
  std::vector<pid_t> ranks_{-1, -1};
};

// The socket inodes that process `pid` holds open.
std::set<std::string> socket_inodes(pid_t pid) {
  std::set<std::string> inodes;
  std::error_code error;
  for (const auto& fd : fs::directory_iterator("/proc/" + std::to_string(pid) + "/fd", error)) {
    const std::string target = fs::read_symlink(fd.path(), error).string();
    if (target.rfind("socket:[", 0) == 0) inodes.insert(target.substr(8, target.size() - 9));
  }
  return inodes;
}

// The TCP sockets among `inodes`, from /proc/net/tcp and tcp6, as "STATE LOCAL" in the kernel's
// hex: "0A 0100007F:9C40" is one listening on 127.0.0.1:40000, "01 ..." one connected.
std::vector<std::string> tcp_sockets(const std::set<std::string>& inodes) {
  std::vector<std::string> sockets;
  for (const char* table : {"/proc/net/tcp", "/proc/net/tcp6"}) {
    std::istringstream lines(read_text(table));
    std::string line;
    std::getline(lines, line);  // the header
    while (std::getline(lines, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, state, queues, timer, retransmits, uid, timeout, inode;
      fields >> slot >> local >> remote >> state >> queues >> timer >> retransmits >> uid >>
          timeout >> inode;
      if (inodes.count(inode) > 0) sockets.push_back(state + " " + local);
    }
  }
  return sockets;
}

// On one machine nothing of a run needs to be reached from elsewhere: every TCP socket of the
// launcher and its ranks is on loopback (Gloo's connections), and none listens beyond it (the
// rendezvous store is a file; it listened on every interface).
TEST(LaunchTest, ALocalRunListensOnLoopbackOnly) {
  LocalRun run("loopback");
  ASSERT_TRUE(run.training()) << run.log();
  std::set<std::string> inodes;
  for (const pid_t pid : {run.launcher(), run.ranks()[0], run.ranks()[1]}) {
    const std::set<std::string> held = socket_inodes(pid);
    inodes.insert(held.begin(), held.end());
  }
  const std::vector<std::string> sockets = tcp_sockets(inodes);
  EXPECT_FALSE(sockets.empty()) << "the ranks hold no TCP socket: where are Gloo's connections?";
  for (const std::string& socket : sockets) {
    const std::string local = socket.substr(3);
    const bool loopback = local.rfind("0100007F:", 0) == 0 ||                          // 127.0.0.1
                          local.rfind("00000000000000000000000001000000:", 0) == 0 ||  // ::1
                          local.rfind("0000000000000000FFFF00000100007F:", 0) == 0;    // v4 in v6
    EXPECT_TRUE(loopback) << "a socket of the run beyond loopback: " << socket
                          << " (/proc/net/tcp's state and local address; 0A: listening)";
  }
}

// kill -9 of the launcher cannot forward anything: its ranks must end by themselves
// (PR_SET_PDEATHSIG), rather than train on as orphans.
TEST(LaunchTest, RanksEndWhenTheirLauncherIsKilled) {
  LocalRun run("orphans");
  ASSERT_TRUE(run.training()) << run.log();
  ::kill(run.launcher(), SIGKILL);
  ::waitpid(run.launcher(), nullptr, 0);
  const auto killed = Clock::now();
  const auto deadline = killed + std::chrono::seconds(20);
  while (Clock::now() < deadline && (running(run.ranks()[0]) || running(run.ranks()[1]))) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - killed).count();
  std::cout << "the ranks ended " << seconds << " s after the launcher was killed\n";
  EXPECT_FALSE(running(run.ranks()[0])) << "rank 0 trains on without its launcher";
  EXPECT_FALSE(running(run.ranks()[1])) << "rank 1 trains on without its launcher";
  EXPECT_LT(seconds, 5.0);
}

}  // namespace
}  // namespace pixelgym::testing
