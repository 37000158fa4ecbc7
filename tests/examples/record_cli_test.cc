// Runs `pixelgym record` as a user would: the clips it says it wrote exist with those frame counts
// and the returns of the seeded random policy; a folder it cannot write exits 1 and leaves nothing;
// clips already there are replaced only with --overwrite; a run killed mid-episode leaves a
// temporary file that the next run removes.
#include <fcntl.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <stdlib.h>
#include <sys/mount.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/videoio.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/rollout.h"
#include "tests/examples/cli_run.h"

namespace pixelgym {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

using testing::CliRun;

CliRun run(const std::string& arguments) { return testing::run_cli(arguments); }

// A folder of the test's own under the test output folder, removed first.
fs::path fresh_folder() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path folder = fs::path(PIXELGYM_TEST_OUTPUT_DIR) / "record_cli" / info->name();
  fs::remove_all(folder);
  return folder;
}

std::set<std::string> files_in(const fs::path& folder) {
  std::set<std::string> names;
  if (!fs::exists(folder)) return names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    names.insert(entry.path().filename().string());
  }
  return names;
}

std::int64_t frame_count(const fs::path& path) {
  cv::VideoCapture capture(path.string(), cv::CAP_FFMPEG);
  if (!capture.isOpened()) return -1;
  return static_cast<std::int64_t>(capture.get(cv::CAP_PROP_FRAME_COUNT));
}

// What `record` prints for these episodes, from the library: the same RandomRollout.
std::string expected_lines(const std::string& id, const Params& kwargs, std::uint64_t seed,
                           int episodes, const std::function<std::string(int)>& path) {
  auto env = make(id, kwargs);
  RandomRollout random(*env, seed);
  std::ostringstream out;
  for (int episode = 0; episode < episodes; ++episode) {
    const EpisodeSummary& summary = random.finish_episode(false);
    out << "wrote " << path(episode) << " frames=" << summary.length + 1
        << " return=" << summary.episode_return << "\n";
  }
  return out.str();
}

TEST(RecordCliTest, OneClipPerEpisodeInAFolder) {
  const fs::path folder = fresh_folder() / "runs";
  const CliRun result = run("record GridWorld-v0 --episodes 3 --seed 1 --out " + folder.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  const auto path = [&](int episode) {
    return (folder / ("GridWorld-v0-episode-" + std::to_string(episode) + ".mp4")).string();
  };
  EXPECT_EQ(result.output, expected_lines("GridWorld-v0", {}, 1, 3, path));
  EXPECT_EQ(files_in(folder),
            (std::set<std::string>{"GridWorld-v0-episode-0.mp4", "GridWorld-v0-episode-1.mp4",
                                   "GridWorld-v0-episode-2.mp4"}));
  auto env = make("GridWorld-v0");
  RandomRollout random(*env, 1);
  for (int episode = 0; episode < 3; ++episode) {
    EXPECT_EQ(frame_count(path(episode)), random.finish_episode(false).length + 1) << episode;
  }
}

TEST(RecordCliTest, OneFile) {
  const fs::path folder = fresh_folder();
  const fs::path file = folder / "swing.mp4";
  const std::string sets =
      "--set render_width=64 --set render_height=48 --set max_episode_steps=30";
  const CliRun result =
      run("record CartPoleSwingup-v0 --seed 4 --out " + file.string() + " " + sets);
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output,
            expected_lines("CartPoleSwingup-v0",
                           {{"render_width", 64}, {"render_height", 48}, {"max_episode_steps", 30}},
                           4, 1, [&](int) { return file.string(); }));
  EXPECT_EQ(files_in(folder), std::set<std::string>{"swing.mp4"});
  EXPECT_EQ(frame_count(file), 31);
}

TEST(RecordCliTest, UsageErrorsExitTwo) {
  const fs::path folder = fresh_folder();
  CliRun result = run("record GridWorld-v0 --episodes 2 --out " + (folder / "a.mp4").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("is one clip, but --episodes is 2"));
  result = run("record GridWorld-v0 --policy greedy --out " + folder.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("--policy"));
  result = run("record GridWorld-v0");
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("--out is required"));
  result = run("record NoSuchEnv-v0 --out " + folder.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_FALSE(fs::exists(folder));
}

// An --out that cannot take the clip is refused before any episode runs (a folder named a.mp4
// was found only after the episode, by the rename).
TEST(RecordCliTest, AnOutputFileThatIsAFolderIsRefusedBeforeAnyEpisode) {
  const fs::path folder = fresh_folder();
  fs::create_directories(folder / "a.mp4");
  const CliRun result = run("record CartPoleSwingup-v0 --out " + (folder / "a.mp4").string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("--out " + (folder / "a.mp4").string() +
                                       " is a folder; name a video file (FILE.mp4)"));
  EXPECT_THAT(result.output, Not(HasSubstr("cannot rename")));
  EXPECT_EQ(files_in(folder), std::set<std::string>{"a.mp4"});
}

std::string file_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// Clips already there are refused (exit 2, naming them and --overwrite) before any episode runs,
// and left byte for byte as they were; with --overwrite they are replaced.
TEST(RecordCliTest, ExistingClipsAreReplacedOnlyWithOverwrite) {
  const fs::path folder = fresh_folder();
  ASSERT_EQ(run("record GridWorld-v0 --episodes 2 --seed 1 --out " + folder.string()).exit_code, 0);
  std::ofstream(folder / "GridWorld-v0-episode-2.mp4") << "beyond --episodes 2";
  const fs::path clip0 = folder / "GridWorld-v0-episode-0.mp4";
  const fs::path clip1 = folder / "GridWorld-v0-episode-1.mp4";
  const std::string bytes0 = file_bytes(clip0);
  const std::string bytes1 = file_bytes(clip1);
  const std::set<std::string> before = files_in(folder);

  CliRun result = run("record GridWorld-v0 --episodes 2 --seed 2 --out " + folder.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output,
              HasSubstr("pixelgym: --out " + folder.string() +
                        " already holds 2 files that this run would write "
                        "(GridWorld-v0-episode-0.mp4, GridWorld-v0-episode-1.mp4); pass "
                        "--overwrite to replace them, or give another folder"));
  EXPECT_THAT(result.output, Not(HasSubstr("wrote")));
  result = run("record GridWorld-v0 --seed 2 --out " + clip1.string());
  EXPECT_EQ(result.exit_code, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("pixelgym: --out " + clip1.string() +
                                       " exists already; pass --overwrite to replace it"));
  EXPECT_EQ(files_in(folder), before);
  // Compared, not printed: a video's bytes would flood the failure message.
  EXPECT_TRUE(file_bytes(clip0) == bytes0) << clip0 << " changed";
  EXPECT_TRUE(file_bytes(clip1) == bytes1) << clip1 << " changed";

  result = run("record GridWorld-v0 --episodes 2 --seed 2 --overwrite --out " + folder.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_EQ(result.output, expected_lines("GridWorld-v0", {}, 2, 2, [&](int episode) {
              return (episode == 0 ? clip0 : clip1).string();
            }));
  EXPECT_TRUE(file_bytes(clip0) != bytes0) << clip0 << " was not replaced";
  EXPECT_EQ(files_in(folder), before);
  result = run("record GridWorld-v0 --seed 3 --overwrite --out " + clip1.string());
  ASSERT_EQ(result.exit_code, 0) << result.output;
  auto env = make("GridWorld-v0");
  RandomRollout random(*env, 3);
  EXPECT_EQ(frame_count(clip1), random.finish_episode(false).length + 1);
}

// A record run killed mid-episode (SIGKILL: none of its code runs after) leaves its temporary
// file; the next record into the folder removes it and writes its clip. Bounded: the run is
// killed once its file appears, or after 60 s.
TEST(RecordCliTest, ATemporaryFileLeftByAKilledRunIsRemovedByTheNext) {
  const fs::path folder = fresh_folder();
  fs::create_directories(folder);
  // A million steps: the episode is still running when it is killed.
  std::vector<std::string> arguments = {
      PIXELGYM_CLI,      "record", "CartPoleSwingup-v0",        "--out",
      folder.string(),   "--set",  "max_episode_steps=1000000", "--set",
      "render_width=32", "--set",  "render_height=32"};
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ASSERT_EQ(spawned, 0) << std::strerror(spawned);
  const std::string prefix = ".CartPoleSwingup-v0-episode-0.partial-";
  const auto partial_files = [&] {
    std::set<std::string> names;
    for (const std::string& name : files_in(folder)) {
      if (name.rfind(prefix, 0) == 0) names.insert(name);
    }
    return names;
  };
  int status = 0;
  bool exited = false;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (partial_files().empty() && std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) {
      exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (!exited) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
  }
  ASSERT_FALSE(exited) << "record ended by itself before it was killed, status " << status;
  ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << status;
  const std::set<std::string> left = partial_files();
  ASSERT_EQ(left.size(), 1U) << "no temporary file within 60 s: "
                             << ::testing::PrintToString(files_in(folder));
  EXPECT_EQ(files_in(folder), left);  // what the killed run left: its temporary file only

  const CliRun next =
      run("record CartPoleSwingup-v0 --out " + folder.string() +
          " --set max_episode_steps=20 --set render_width=32 --set render_height=32");
  ASSERT_EQ(next.exit_code, 0) << next.output;
  EXPECT_EQ(files_in(folder), std::set<std::string>{"CartPoleSwingup-v0-episode-0.mp4"});
  EXPECT_EQ(frame_count(folder / "CartPoleSwingup-v0-episode-0.mp4"), 21);
}

TEST(RecordCliTest, HelpIsTheSubcommandsOwn) {
  const CliRun help = run("record --help");
  EXPECT_EQ(help.exit_code, 0);
  EXPECT_THAT(help.output, HasSubstr("Usage: pixelgym record [OPTIONS] id"));
  EXPECT_THAT(help.output, HasSubstr("--episodes INT:>= 1=1"));
  EXPECT_THAT(help.output, HasSubstr("--seed UINT64=0"));
  EXPECT_THAT(help.output, HasSubstr("--overwrite"));
  EXPECT_THAT(help.output, HasSubstr("without it, record refuses them before any episode runs"));
  EXPECT_EQ(run("help record").output, help.output);
  EXPECT_THAT(run("help").output, HasSubstr("\n  record "));
}

TEST(RecordCliTest, FolderThatCannotBeCreatedExitsOneAndLeavesNothing) {
  const fs::path folder = fresh_folder();
  fs::create_directories(folder);
  std::ofstream(folder / "a-file") << "x";
  const fs::path out = folder / "a-file" / "videos";
  const CliRun result = run("record GridWorld-v0 --out " + out.string());
  EXPECT_EQ(result.exit_code, 1) << result.output;
  EXPECT_THAT(result.output, HasSubstr("pixelgym: error: RecordVideo: cannot create the video "
                                       "folder \"" +
                                       out.string() + "\""));
  EXPECT_EQ(files_in(folder), std::set<std::string>{"a-file"});
}

TEST(RecordCliTest, ReadOnlyFolderExitsOneAndLeavesNothing) {
  std::string pattern = (fs::temp_directory_path() / "pixelgym-record-cli-XXXXXX").string();
  ASSERT_NE(mkdtemp(pattern.data()), nullptr);
  const fs::path mount_point = pattern;
  // A read-only file system refuses root too (chmod 555 would not).
  if (mount("tmpfs", mount_point.c_str(), "tmpfs", MS_RDONLY, "size=64k") != 0) {
    const std::string why = std::strerror(errno);
    fs::remove(mount_point);
    GTEST_SKIP() << "cannot mount a tmpfs here: " << why;
  }
  const CliRun folder_run = run("record GridWorld-v0 --out " + mount_point.string());
  const CliRun file_run = run("record GridWorld-v0 --out " + (mount_point / "a.mp4").string());
  const std::set<std::string> left = files_in(mount_point);
  umount(mount_point.c_str());
  fs::remove(mount_point);
  for (const CliRun& result : {folder_run, file_run}) {
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_THAT(result.output, HasSubstr("cannot create a file in the video folder \"" +
                                         mount_point.string() + "\": Read-only file system"));
    EXPECT_THAT(result.output, Not(HasSubstr("wrote")));
  }
  EXPECT_EQ(left, std::set<std::string>{});
}

}  // namespace
}  // namespace pixelgym
