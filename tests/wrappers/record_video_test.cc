// RecordVideo: clips reopened with OpenCV and ffprobe (frame count, size, fps, codec), triggers,
// names, video_length, flat memory over a 10,000-frame clip, every failure leaving no file
// under a final name (a full tmpfs, a read-only folder, a frame of another size), and temporary
// files of killed recorders removed while those of live ones are kept.
#include "pixelgym/wrappers/record_video.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/mount.h>
#include <sys/wait.h>

#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "pixelgym/envs/registry.h"
#include "pixelgym/envs/spaces/box.h"
#include "pixelgym/render/image_io.h"

namespace pixelgym::wrappers {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

// Renders (height, width, 3) frames: a gradient background with a white square that moves one
// pixel per step (or per-pixel noise, which compresses badly, with `noise`). Episodes end after
// `episode_length` steps; `render_modes`, `render_fps` and the frame size can be changed.
class FrameEnv final : public Env {
 public:
  FrameEnv(int frame_width, int frame_height, int episode_length = 10)
      : width(frame_width), height(frame_height), episode_length_(episode_length) {
    metadata_.render_fps = 25.0;
  }

  const Space& observation_space() const override { return space_; }
  const Space& action_space() const override { return space_; }
  const Metadata& metadata() const override { return metadata_; }
  Metadata& mutable_metadata() { return metadata_; }

  int width;
  int height;
  bool noise = false;
  /// When > 0, the step that makes t equal to it throws std::runtime_error.
  int throw_at_step = 0;

 protected:
  std::string type_name() const override { return "FrameEnv"; }
  void do_reset(std::optional<std::uint64_t>, const Options&, ResetResult&) override { t_ = 0; }
  void do_step(const Value&, StepResult& out) override {
    ++t_;
    if (t_ == throw_at_step) throw std::runtime_error("FrameEnv: step " + std::to_string(t_));
    out.reward = 1.0;
    out.terminated = t_ >= episode_length_;
  }
  Array do_render() override {
    Array frame(DType::kUInt8, {height, width, 3});
    auto* pixels = frame.data<std::uint8_t>();
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        std::uint8_t* pixel = pixels + (static_cast<std::ptrdiff_t>(y) * width + x) * 3;
        const bool square = std::abs(x - t_ % width) < 4 && std::abs(y - height / 2) < 4;
        if (noise) {
          state_ = state_ * 6364136223846793005ULL + 1442695040888963407ULL;
          pixel[0] = static_cast<std::uint8_t>(state_ >> 56);
          pixel[1] = static_cast<std::uint8_t>(state_ >> 48);
          pixel[2] = static_cast<std::uint8_t>(state_ >> 40);
        } else {
          pixel[0] = square ? 255 : static_cast<std::uint8_t>(x * 255 / width);
          pixel[1] = square ? 255 : static_cast<std::uint8_t>(y * 255 / height);
          pixel[2] = square ? 255 : 60;
        }
      }
    }
    return frame;
  }

 private:
  spaces::Box space_{-1.0, 1.0, {1}};
  Metadata metadata_;
  int episode_length_;
  int t_ = 0;
  std::uint64_t state_ = 1;
};

// A folder of its own for each test, emptied first.
fs::path fresh_folder() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path folder =
      fs::path(PIXELGYM_TEST_OUTPUT_DIR) / "record_video" / (std::string(info->name()));
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

// Runs one episode to its end with the zero action.
void run_episode(Env& env, std::optional<std::uint64_t> seed = std::nullopt) {
  env.reset(seed);
  const Value action = env.action_space().zeros();
  while (true) {
    const StepResult result = env.step(action);
    if (result.terminated || result.truncated) return;
  }
}

struct VideoFacts {
  bool opened = false;
  std::int64_t frames = 0;
  int width = 0;
  int height = 0;
  double fps = 0.0;
  std::int64_t decoded = 0;  // frames read one by one
};

VideoFacts read_back(const fs::path& path) {
  VideoFacts facts;
  cv::VideoCapture capture(path.string(), cv::CAP_FFMPEG);
  facts.opened = capture.isOpened();
  if (!facts.opened) return facts;
  facts.frames = static_cast<std::int64_t>(capture.get(cv::CAP_PROP_FRAME_COUNT));
  facts.width = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_WIDTH));
  facts.height = static_cast<int>(capture.get(cv::CAP_PROP_FRAME_HEIGHT));
  facts.fps = capture.get(cv::CAP_PROP_FPS);
  cv::Mat frame;
  while (capture.read(frame)) ++facts.decoded;
  return facts;
}

// `ffprobe`'s key=value facts about the first video stream. Fails the test when ffprobe is
// missing (scripts/install-deps.sh installs it with ffmpeg).
std::map<std::string, std::string> ffprobe(const fs::path& path) {
  const std::string command =
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=codec_name,width,height,r_frame_rate,nb_frames,nb_read_frames,pix_fmt "
      "-of default=noprint_wrappers=1 '" +
      path.string() + "' 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  std::map<std::string, std::string> facts;
  if (pipe == nullptr) {
    ADD_FAILURE() << "popen failed: " << command;
    return facts;
  }
  std::string output;
  std::array<char, 512> buffer{};
  while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) output += buffer.data();
  const int status = pclose(pipe);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
      << "ffprobe failed (is it installed? scripts/install-deps.sh installs ffmpeg): " << output;
  std::istringstream lines(output);
  std::string line;
  while (std::getline(lines, line)) {
    const auto equals = line.find('=');
    if (equals != std::string::npos) facts[line.substr(0, equals)] = line.substr(equals + 1);
  }
  return facts;
}

long rss_kib() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

const EpisodeTrigger every_episode = [](std::int64_t) { return true; };

TEST(RecordVideoTest, WholeEpisodeReopensWithOpenCvAndFfprobe) {
  const fs::path folder = fresh_folder();
  auto record = RecordVideo(std::make_unique<FrameEnv>(64, 48, 10), folder, every_episode);
  EXPECT_EQ(record.fps(), 25.0);  // from metadata
  run_episode(record);
  EXPECT_TRUE(record.recording());  // until the next reset or close
  const std::optional<VideoClip> clip = record.stop_recording();
  ASSERT_TRUE(clip);
  EXPECT_EQ(clip->path, folder / "rl-video-episode-0.mp4");
  EXPECT_EQ(clip->frames, 11);  // the reset's frame and one per step
  EXPECT_EQ(clip->codec, "avc1");
  EXPECT_EQ(files_in(folder), (std::set<std::string>{"rl-video-episode-0.mp4"}));

  const VideoFacts facts = read_back(clip->path);
  ASSERT_TRUE(facts.opened);
  EXPECT_EQ(facts.frames, 11);
  EXPECT_EQ(facts.decoded, 11);
  EXPECT_EQ(facts.width, 64);
  EXPECT_EQ(facts.height, 48);
  EXPECT_DOUBLE_EQ(facts.fps, 25.0);

  auto probe = ffprobe(clip->path);
  EXPECT_EQ(probe["codec_name"], "h264");
  EXPECT_EQ(probe["pix_fmt"], "yuv420p");
  EXPECT_EQ(probe["width"], "64");
  EXPECT_EQ(probe["height"], "48");
  EXPECT_EQ(probe["r_frame_rate"], "25/1");
  EXPECT_EQ(probe["nb_frames"], "11");
  EXPECT_EQ(probe["nb_read_frames"], "11");
}

TEST(RecordVideoTest, FramesAreTheRenderedOnes) {
  const fs::path folder = fresh_folder();
  FrameEnv reference(64, 48, 10);
  reference.reset();
  const Array first = reference.render();
  {
    RecordVideo record(std::make_unique<FrameEnv>(64, 48, 10), folder, every_episode);
    run_episode(record);
  }  // the destructor finishes the clip
  cv::VideoCapture capture((folder / "rl-video-episode-0.mp4").string(), cv::CAP_FFMPEG);
  cv::Mat bgr;
  ASSERT_TRUE(capture.read(bgr));
  ASSERT_EQ(bgr.rows, 48);
  ASSERT_EQ(bgr.cols, 64);
  // Lossy: compare the mean absolute difference, RGB against the decoded BGR.
  double total = 0.0;
  const auto* expected = first.data<std::uint8_t>();
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      const auto& got = bgr.at<cv::Vec3b>(y, x);
      const std::uint8_t* want = expected + (y * 64 + x) * 3;
      for (int c = 0; c < 3; ++c) total += std::abs(int(got[2 - c]) - int(want[c]));
    }
  }
  EXPECT_LT(total / (48 * 64 * 3), 6.0);
}

TEST(RecordVideoTest, CappedCubicSchedule) {
  std::vector<std::int64_t> chosen;
  for (std::int64_t e = 0; e <= 3000; ++e) {
    if (capped_cubic_video_schedule(e)) chosen.push_back(e);
  }
  EXPECT_EQ(chosen, (std::vector<std::int64_t>{0, 1, 8, 27, 64, 125, 216, 343, 512, 729, 1000, 2000,
                                               3000}));
}

TEST(RecordVideoTest, DefaultTriggerRecordsCubeEpisodes) {
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(16, 16, 2), folder);
  for (int e = 0; e < 10; ++e) run_episode(record);
  record.close();
  EXPECT_EQ(files_in(folder),
            (std::set<std::string>{"rl-video-episode-0.mp4", "rl-video-episode-1.mp4",
                                   "rl-video-episode-8.mp4"}));
  EXPECT_EQ(read_back(folder / "rl-video-episode-8.mp4").frames, 3);
}

TEST(RecordVideoTest, StepTriggerAndVideoLength) {
  const fs::path folder = fresh_folder();
  RecordVideo record(
      std::make_unique<FrameEnv>(32, 32, 10), folder, nullptr,
      [](std::int64_t step) { return step % 8 == 0; }, 5, "eval");
  for (int e = 0; e < 2; ++e) run_episode(record);  // steps 0..19
  record.close();
  // Clips start after steps 0, 8 and 16 and cross the episode boundary (video_length > 0).
  EXPECT_EQ(files_in(folder),
            (std::set<std::string>{"eval-step-0.mp4", "eval-step-8.mp4", "eval-step-16.mp4"}));
  EXPECT_EQ(read_back(folder / "eval-step-0.mp4").frames, 5);
  EXPECT_EQ(read_back(folder / "eval-step-8.mp4").frames, 5);   // steps 8, 9, reset, 10, 11
  EXPECT_EQ(read_back(folder / "eval-step-16.mp4").frames, 4);  // steps 16..19, then close()
}

TEST(RecordVideoTest, WholeEpisodeStepClipEndsAtTheNextReset) {
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(32, 32, 10), folder, nullptr,
                     [](std::int64_t step) { return step == 3; });
  run_episode(record);
  EXPECT_TRUE(record.recording());
  record.reset();
  EXPECT_FALSE(record.recording());
  EXPECT_EQ(read_back(folder / "rl-video-step-3.mp4").frames, 7);  // steps 3..9
}

TEST(RecordVideoTest, VideoLengthEndsEpisodeClipsEarly) {
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(32, 32, 10), folder, every_episode, nullptr, 3,
                     "short", 10.0);
  EXPECT_EQ(record.fps(), 10.0);
  run_episode(record);
  EXPECT_FALSE(record.recording());
  run_episode(record);
  EXPECT_EQ(files_in(folder),
            (std::set<std::string>{"short-episode-0.mp4", "short-episode-1.mp4"}));
  const VideoFacts facts = read_back(folder / "short-episode-1.mp4");
  EXPECT_EQ(facts.frames, 3);
  EXPECT_DOUBLE_EQ(facts.fps, 10.0);
}

TEST(RecordVideoTest, ManualStartBeforeResetRecordsTheEpisode) {
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(32, 32, 4), folder,
                     [](std::int64_t) { return false; });
  record.start_recording("demo");
  run_episode(record);
  const auto clip = record.stop_recording();
  ASSERT_TRUE(clip);
  EXPECT_EQ(clip->path, folder / "demo.mp4");
  EXPECT_EQ(clip->frames, 5);
  EXPECT_FALSE(record.stop_recording());  // nothing in progress
}

TEST(RecordVideoTest, OddFrameSizeIsPaddedToEven) {
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(33, 21, 3), folder, every_episode);
  run_episode(record);
  const auto clip = record.stop_recording();
  ASSERT_TRUE(clip);
  EXPECT_EQ(clip->width, 34);
  EXPECT_EQ(clip->height, 22);
  const VideoFacts facts = read_back(clip->path);
  EXPECT_EQ(facts.width, 34);
  EXPECT_EQ(facts.height, 22);
  EXPECT_EQ(facts.decoded, 4);
}

TEST(RecordVideoTest, CloseFinishesTheClipAndClosesTheEnv) {
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(32, 32, 10), folder, every_episode);
  record.reset();
  for (int t = 0; t < 4; ++t) record.step(record.action_space().zeros());
  record.close();
  EXPECT_FALSE(record.recording());
  EXPECT_TRUE(record.env().closed());
  EXPECT_EQ(read_back(folder / "rl-video-episode-0.mp4").frames, 5);
  EXPECT_EQ(files_in(folder).size(), 1u);
  // The clip gets a new file's usual permissions (0666 less the umask), not a temporary's 0600.
  std::ofstream(folder / "plain") << "x";
  EXPECT_EQ(fs::status(folder / "rl-video-episode-0.mp4").permissions(),
            fs::status(folder / "plain").permissions());
}

TEST(RecordVideoTest, RefusesBadArguments) {
  const fs::path folder = fresh_folder();
  const auto env = [] { return std::make_unique<FrameEnv>(16, 16); };
  const auto expect_invalid = [](const std::function<void()>& make, const std::string& part) {
    try {
      make();
      ADD_FAILURE() << "no exception, expected one with: " << part;
    } catch (const std::invalid_argument& error) {
      EXPECT_THAT(error.what(), HasSubstr(part));
    }
  };
  expect_invalid([&] { RecordVideo(env(), folder, nullptr, nullptr, -1); },
                 "video_length must be >= 0 (0 records whole episodes), got -1");
  expect_invalid([&] { RecordVideo(env(), folder, nullptr, nullptr, 0, "rl-video", 0.0); },
                 "fps must be > 0 and finite, got 0");
  expect_invalid([&] { RecordVideo(env(), folder, nullptr, nullptr, 0, "rl-video", -5.0); },
                 "fps must be > 0 and finite, got -5");
  expect_invalid([&] { RecordVideo(env(), folder, nullptr, nullptr, 0, "rl-video", NAN); },
                 "fps must be > 0 and finite");
  expect_invalid([&] { RecordVideo(env(), folder, nullptr, nullptr, 0, ""); },
                 "name_prefix must be a non-empty file name without '/', got \"\"");
  expect_invalid([&] { RecordVideo(env(), folder, nullptr, nullptr, 0, "a/b"); }, "\"a/b\"");
  expect_invalid([&] { RecordVideo(env(), ""); }, "video_folder must not be empty");
  {
    auto no_fps = env();
    no_fps->mutable_metadata().render_fps = 0.0;
    expect_invalid([&] { RecordVideo(std::move(no_fps), folder); },
                   "fps must be > 0 and finite, got 0.000000 from FrameEnv's "
                   "metadata().render_fps; pass fps");
  }
  {
    auto no_rgb = env();
    no_rgb->mutable_metadata().render_modes = {"human", "ansi"};
    expect_invalid([&] { RecordVideo(std::move(no_rgb), folder); },
                   "RecordVideo: FrameEnv must render \"rgb_array\" frames, but its "
                   "metadata().render_modes is [\"human\", \"ansi\"]");
  }
  RecordVideo record(env(), folder);
  expect_invalid([&] { record.start_recording("x/y"); }, "video_name");
}

TEST(RecordVideoTest, FolderThatCannotBeCreated) {
  const fs::path folder = fresh_folder();
  fs::create_directories(folder);
  std::ofstream(folder / "a-file") << "x";
  const fs::path below_a_file = folder / "a-file" / "videos";
  try {
    RecordVideo record(std::make_unique<FrameEnv>(16, 16), below_a_file);
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("RecordVideo: cannot create the video folder \"" +
                                        below_a_file.string() + "\""));
  }
  EXPECT_FALSE(fs::exists(below_a_file));
}

// A tmpfs mounted for the test (read-only or tiny), unmounted at the end; `mounted` is false
// where mounting is not permitted (not root, no CAP_SYS_ADMIN).
class TmpfsMount {
 public:
  explicit TmpfsMount(const std::string& options, unsigned long flags = 0) {
    std::string pattern = (fs::temp_directory_path() / "pixelgym-record-video-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) return;
    path_ = pattern;
    mounted_ = mount("tmpfs", path_.c_str(), "tmpfs", flags, options.c_str()) == 0;
    if (!mounted_) why_ = std::strerror(errno);
  }
  ~TmpfsMount() {
    if (mounted_) umount(path_.c_str());
    std::error_code ignored;
    if (!path_.empty()) fs::remove(path_, ignored);
  }
  TmpfsMount(const TmpfsMount&) = delete;
  TmpfsMount& operator=(const TmpfsMount&) = delete;
  bool mounted() const { return mounted_; }
  const std::string& why() const { return why_; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  bool mounted_ = false;
  std::string why_ = "mkdtemp failed";
};

TEST(RecordVideoTest, ReadOnlyFolderIsRefusedAtConstruction) {
  // A read-only file system refuses root too (chmod 555 would not).
  TmpfsMount read_only("size=64k", MS_RDONLY);
  if (!read_only.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here: " << read_only.why();
  try {
    RecordVideo record(std::make_unique<FrameEnv>(16, 16), read_only.path());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(), HasSubstr("RecordVideo: cannot create a file in the video folder \"" +
                                        read_only.path().string() + "\": Read-only file system"));
  }
}

TEST(RecordVideoTest, FullDiskMidClipLeavesNoFile) {
  TmpfsMount tiny("size=64k");
  if (!tiny.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here: " << tiny.why();
  auto env = std::make_unique<FrameEnv>(64, 64, 200);
  env->noise = true;  // about 10 kB a frame: the disk fills within the clip
  RecordVideo record(std::move(env), tiny.path(), every_episode);
  std::string message;
  try {
    run_episode(record);
    record.close();
  } catch (const std::runtime_error& error) {
    message = error.what();
  }
  const std::string final_path = (tiny.path() / "rl-video-episode-0.mp4").string();
  EXPECT_THAT(message, HasSubstr("RecordVideo: writing \"" + final_path + "\" failed"));
  EXPECT_THAT(message, HasSubstr("(a full disk?)"));
  EXPECT_THAT(message, HasSubstr("nothing was written"));
  EXPECT_EQ(files_in(tiny.path()), std::set<std::string>{}) << message;
  EXPECT_FALSE(record.recording());
}

// A disk already full when a clip starts: the encoder does not open, and the error says why (it
// said "cannot open a video encoder ... neither avc1 nor mp4v opened").
TEST(RecordVideoTest, FullDiskWhenAClipStartsNamesTheFullDisk) {
  TmpfsMount tiny("size=64k");
  if (!tiny.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here: " << tiny.why();
  auto env = std::make_unique<FrameEnv>(64, 64, 20);
  RecordVideo record(std::move(env), tiny.path(), every_episode);
  {
    std::ofstream filler(tiny.path() / "filler", std::ios::binary);
    const std::string block(4096, 'x');
    while (filler.write(block.data(), static_cast<std::streamsize>(block.size())) &&
           filler.flush()) {
    }
  }
  std::string message;
  try {
    run_episode(record);
    record.close();
  } catch (const std::runtime_error& error) {
    message = error.what();
  }
  EXPECT_THAT(message, HasSubstr("No space left on device")) << message;
  EXPECT_THAT(message, Not(HasSubstr("cannot open a video encoder"))) << message;
  EXPECT_EQ(files_in(tiny.path()), std::set<std::string>{"filler"}) << message;
}

TEST(RecordVideoTest, FullDiskInTheDestructorLeavesNoFileAndSaysSo) {
  TmpfsMount tiny("size=64k");
  if (!tiny.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here: " << tiny.why();
  ::testing::internal::CaptureStderr();
  {
    auto env = std::make_unique<FrameEnv>(64, 64, 200);
    env->noise = true;
    RecordVideo record(std::move(env), tiny.path(), every_episode);
    run_episode(record);
  }  // not closed: the destructor finishes the clip, which fails
  const std::string errors = ::testing::internal::GetCapturedStderr();
  EXPECT_THAT(errors, HasSubstr("pixelgym: error: RecordVideo: writing \"" +
                                (tiny.path() / "rl-video-episode-0.mp4").string() + "\" failed"));
  EXPECT_THAT(errors, HasSubstr("(in ~RecordVideo)"));
  EXPECT_EQ(files_in(tiny.path()), std::set<std::string>{});
}

// An episode the env breaks off mid-clip leaves no clip: the file would hold part of it.
TEST(RecordVideoTest, EnvErrorMidClipLeavesNoFile) {
  const fs::path folder = fresh_folder();
  auto env = std::make_unique<FrameEnv>(32, 32, 10);
  FrameEnv* inner = env.get();
  inner->throw_at_step = 4;
  {
    RecordVideo record(std::move(env), folder, every_episode);
    record.reset();
    for (int t = 0; t < 3; ++t) record.step(record.action_space().zeros());
    EXPECT_THROW(record.step(record.action_space().zeros()), std::runtime_error);
    EXPECT_FALSE(record.recording());
    EXPECT_EQ(files_in(folder), std::set<std::string>{});
    // The next episode records as usual.
    inner->throw_at_step = 0;
    run_episode(record);
  }  // the destructor finishes it
  EXPECT_EQ(files_in(folder), std::set<std::string>{"rl-video-episode-1.mp4"});
  EXPECT_EQ(read_back(folder / "rl-video-episode-1.mp4").frames, 11);
}

// The names of the temporary files in `folder` (".{name}.partial-XXXXXX.mp4").
std::set<std::string> temporary_files_in(const fs::path& folder) {
  std::set<std::string> names;
  for (const std::string& name : files_in(folder)) {
    if (name[0] == '.' && name.find(".partial-") != std::string::npos) names.insert(name);
  }
  return names;
}

// A recorder killed mid-clip (SIGKILL) leaves its temporary file, which nothing locks any more:
// the kernel dropped its writer's lock. The next recorder into the folder removes such files,
// and only those: names of another form, and a folder of that form, are left (issue 42).
TEST(RecordVideoTest, TemporaryFilesNoWriterHoldsAreRemovedByTheNextRecorder) {
  const fs::path folder = fresh_folder();
  fs::create_directories(folder);
  const std::set<std::string> stale = {".rl-video-episode-0.partial-a1B2c3.mp4",
                                       ".demo.partial-zzzzzz.mp4",
                                       ".write-check.partial-Q9q9Q9.mp4"};
  const std::set<std::string> others = {
      "rl-video-episode-0.mp4",      ".notes.partial-abcde.mp4",  // five random letters
      "rl-video.partial-abcdef.mp4",                              // no leading dot
      ".x.partial-abcdef.mkv",       ".x.partial-ab-def.mp4",    ".partial-abcdef.mp4"};
  for (const std::string& name : stale) std::ofstream(folder / name) << "half a video";
  for (const std::string& name : others) std::ofstream(folder / name) << "not ours";
  fs::create_directory(folder / ".dir.partial-abcdef.mp4");
  std::set<std::string> left = others;
  left.insert(".dir.partial-abcdef.mp4");

  RecordVideo record(std::make_unique<FrameEnv>(16, 16, 3), folder, every_episode);
  EXPECT_EQ(files_in(folder), left);
  run_episode(record);
  record.close();
  EXPECT_EQ(files_in(folder), left);  // rl-video-episode-0.mp4 replaced, as Gymnasium's does
  EXPECT_EQ(read_back(folder / "rl-video-episode-0.mp4").frames, 4);
}

// A recorder holds its temporary file locked while it writes: a second recorder started in the
// same folder meanwhile keeps it, and both clips are written. (flock: the lock of another open
// file in the same process counts too, so this holds for two recorders in one process as well as
// in two.)
TEST(RecordVideoTest, ASecondRecorderKeepsTheTemporaryFileOfOneWriting) {
  const fs::path folder = fresh_folder();
  RecordVideo first(std::make_unique<FrameEnv>(32, 32, 10), folder, every_episode);
  first.reset();
  const Value action = first.action_space().zeros();
  for (int t = 0; t < 3; ++t) first.step(action);
  const std::set<std::string> writing = temporary_files_in(folder);
  ASSERT_EQ(writing.size(), 1U) << ::testing::PrintToString(files_in(folder));
  {
    RecordVideo second(std::make_unique<FrameEnv>(32, 32, 4), folder, every_episode, nullptr, 0,
                       "second");
    EXPECT_EQ(temporary_files_in(folder), writing);
    run_episode(second);
    second.close();
  }
  EXPECT_EQ(temporary_files_in(folder), writing);
  for (int t = 3; t < 10; ++t) first.step(action);  // the episode ends at step 10
  first.close();
  EXPECT_EQ(files_in(folder),
            (std::set<std::string>{"rl-video-episode-0.mp4", "second-episode-0.mp4"}));
  EXPECT_EQ(read_back(folder / "rl-video-episode-0.mp4").frames, 11);
  EXPECT_EQ(read_back(folder / "second-episode-0.mp4").frames, 5);
}

TEST(RecordVideoTest, FrameOfAnotherSizeFailsTheClip) {
  const fs::path folder = fresh_folder();
  auto env = std::make_unique<FrameEnv>(32, 32, 10);
  FrameEnv* inner = env.get();
  RecordVideo record(std::move(env), folder, every_episode);
  record.reset();
  record.step(record.action_space().zeros());
  inner->width = 48;
  try {
    record.step(record.action_space().zeros());
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& error) {
    EXPECT_THAT(error.what(),
                HasSubstr("frame 2 of \"" + (folder / "rl-video-episode-0.mp4").string() +
                          "\" is 48x32 (width x height), but the clip's first frame was 32x32"));
  }
  EXPECT_FALSE(record.recording());
  EXPECT_EQ(files_in(folder), std::set<std::string>{});
  // The next episode records again, at the new size.
  inner->width = 16;
  run_episode(record);
  record.close();
  EXPECT_EQ(read_back(folder / "rl-video-episode-1.mp4").width, 16);
}

TEST(RecordVideoTest, FallbackCodecWarnsOnce) {
  const fs::path folder = fresh_folder();
  setenv("PIXELGYM_RECORD_VIDEO_FOURCC", "zzzz", 1);  // no such encoder: the fallback is used
  ::testing::internal::CaptureStderr();
  std::vector<std::string> codecs;
  for (int i = 0; i < 2; ++i) {
    RecordVideo record(std::make_unique<FrameEnv>(32, 32, 3), folder, every_episode, nullptr, 0,
                       "clip" + std::to_string(i));
    run_episode(record);
    codecs.push_back(record.stop_recording()->codec);
  }
  const std::string errors = ::testing::internal::GetCapturedStderr();
  unsetenv("PIXELGYM_RECORD_VIDEO_FOURCC");
  EXPECT_EQ(codecs, (std::vector<std::string>{"mp4v", "mp4v"}));
  const std::string warning =
      "pixelgym: warning: RecordVideo: the zzzz encoder did not open through OpenCV's FFmpeg "
      "backend; writing mp4v (MPEG-4 Part 2) videos instead";
  const auto first = errors.find(warning);
  EXPECT_NE(first, std::string::npos) << errors;
  EXPECT_EQ(errors.find(warning, first + 1), std::string::npos) << errors;
  EXPECT_EQ(ffprobe(folder / "clip1-episode-0.mp4")["codec_name"], "mpeg4");
  EXPECT_EQ(read_back(folder / "clip1-episode-0.mp4").frames, 4);
}

TEST(RecordVideoTest, MemoryStaysFlatOverATenThousandFrameClip) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "resident memory is not judged under AddressSanitizer (its quarantine keeps "
                  "freed memory on purpose)";
#endif
  const fs::path folder = fresh_folder();
  RecordVideo record(std::make_unique<FrameEnv>(64, 64, 10'000), folder, every_episode);
  record.reset();
  const Value action = record.action_space().zeros();
  long at_1k = 0;
  for (int t = 1; t < 10'000; ++t) {
    record.step(action);
    if (t == 999) at_1k = rss_kib();  // 1,000 frames: the reset's and 999 steps'
  }
  const long at_10k = rss_kib();
  const auto clip = record.stop_recording();
  ASSERT_TRUE(clip);
  EXPECT_EQ(clip->frames, 10'000);
  std::printf(
      "VmRSS at 1,000 frames: %ld KiB, at 10,000 frames: %ld KiB (growth %ld KiB; the "
      "9,000 frames between are %ld KiB raw)\n",
      at_1k, at_10k, at_10k - at_1k, 9'000L * 64 * 64 * 3 / 1024);
  RecordProperty("rss_kib_1k", std::to_string(at_1k));
  RecordProperty("rss_kib_10k", std::to_string(at_10k));
  // Buffering the 9,000 frames would add 108,000 KiB.
  EXPECT_LT(at_10k - at_1k, 2'048);
  EXPECT_EQ(read_back(clip->path).frames, 10'000);
}

TEST(RecordVideoTest, RecordsARegisteredPixelEnv) {
  const fs::path folder = fresh_folder();
  RecordVideo record(make("CartPoleSwingup-v0",
                          {{"render_width", 96}, {"render_height", 64}, {"max_episode_steps", 20}}),
                     folder, every_episode, nullptr, 0, "cartpole");
  Rng rng(0);
  record.reset(std::uint64_t{0});
  for (bool done = false; !done;) {
    const StepResult result = record.step(record.action_space().sample(rng));
    done = result.terminated || result.truncated;
  }
  const auto clip = record.stop_recording();
  ASSERT_TRUE(clip);
  EXPECT_EQ(clip->frames, 21);
  EXPECT_DOUBLE_EQ(read_back(clip->path).fps, record.metadata().render_fps);
  // The middle frame, written for a person to look at; it is not blank.
  cv::VideoCapture capture(clip->path.string(), cv::CAP_FFMPEG);
  cv::Mat frame;
  for (int i = 0; i <= 10; ++i) ASSERT_TRUE(capture.read(frame));
  cv::Scalar mean;
  cv::Scalar deviation;
  cv::meanStdDev(frame, mean, deviation);
  EXPECT_GT(deviation[0] + deviation[1] + deviation[2], 10.0);
  cv::Mat rgb;
  cv::cvtColor(frame, rgb, cv::COLOR_BGR2RGB);
  render::write_png((folder / "cartpole-frame-10.png").string(), {rgb.data, rgb.rows, rgb.cols, 3});
}

}  // namespace
}  // namespace pixelgym::wrappers
