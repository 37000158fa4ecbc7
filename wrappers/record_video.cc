#include "pixelgym/wrappers/record_video.h"

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <random>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

namespace pixelgym::wrappers {
namespace {

namespace fs = std::filesystem;

constexpr const char* kPreferredFourcc = "avc1";  // H.264
constexpr const char* kFallbackFourcc = "mp4v";   // MPEG-4 Part 2
constexpr const char* kFourccVariable = "PIXELGYM_RECORD_VIDEO_FOURCC";

std::atomic<bool> fallback_warned{false};

std::string quoted(const fs::path& path) { return "\"" + path.string() + "\""; }

int fourcc_code(const std::string& fourcc) {
  return cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]);
}

// The FOURCC to try first: PIXELGYM_RECORD_VIDEO_FOURCC when it holds four characters.
std::string preferred_fourcc() {
  const char* value = std::getenv(kFourccVariable);
  if (value != nullptr && std::strlen(value) == 4) return value;
  return kPreferredFourcc;
}

// Free bytes on the file system holding `path`, or -1 when unknown.
long long free_bytes(const fs::path& path) {
  struct statvfs info {};
  if (statvfs(path.c_str(), &info) != 0) return -1;
  return static_cast<long long>(info.f_bavail) * static_cast<long long>(info.f_frsize);
}

void check_name(const std::string& name, const char* what) {
  if (name.empty() || name.find('/') != std::string::npos) {
    throw std::invalid_argument(std::string("RecordVideo: ") + what +
                                " must be a non-empty file name without '/', got \"" + name + "\"");
  }
}

// A file descriptor kept open for the flock on it: closing it, or the process ending in any way
// (SIGKILL included), releases the lock.
class LockedFd {
 public:
  explicit LockedFd(int fd = -1) : fd_(fd) {}
  LockedFd(LockedFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
  LockedFd& operator=(LockedFd&& other) noexcept {
    reset();
    fd_ = std::exchange(other.fd_, -1);
    return *this;
  }
  LockedFd(const LockedFd&) = delete;
  LockedFd& operator=(const LockedFd&) = delete;
  ~LockedFd() { reset(); }

  void reset() noexcept {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }

 private:
  int fd_;
};

// A clip's temporary file and the exclusive flock its writer holds on it while it lives, which
// tells remove_stale_temporaries that the file is in use.
struct TemporaryFile {
  fs::path path;  // empty once renamed or removed
  LockedFd lock;
};

// The temporary files' names: ".{name}.partial-XXXXXX.mp4", X a letter or digit.
constexpr std::string_view kTemporaryMark = ".partial-";
constexpr std::size_t kTemporaryRandom = 6;
constexpr std::string_view kTemporaryExtension = ".mp4";

bool is_temporary_name(const std::string& file_name) {
  const std::size_t tail = kTemporaryMark.size() + kTemporaryRandom + kTemporaryExtension.size();
  if (file_name.size() < 2 + tail || file_name[0] != '.') return false;
  const std::string_view end = std::string_view(file_name).substr(file_name.size() - tail);
  return end.substr(0, kTemporaryMark.size()) == kTemporaryMark &&
         end.substr(kTemporaryMark.size() + kTemporaryRandom) == kTemporaryExtension &&
         std::all_of(end.begin() + kTemporaryMark.size(),
                     end.begin() + kTemporaryMark.size() + kTemporaryRandom,
                     [](char c) { return std::isalnum(static_cast<unsigned char>(c)) != 0; });
}

// Whether `path` still names the file open as `fd`.
bool names_open_file(const fs::path& path, int fd) {
  struct stat opened {};
  struct stat named {};
  return ::fstat(fd, &opened) == 0 && ::lstat(path.c_str(), &named) == 0 &&
         opened.st_dev == named.st_dev && opened.st_ino == named.st_ino;
}

// Creates a unique empty file "{folder}/.{name}.partial-XXXXXX.mp4" (ending ".mp4", so that
// FFmpeg picks the MP4 container), with the permissions a new file gets (0666 less the umask;
// mkstemp's would be 0600), and takes an exclusive flock on it. Between the creation and the lock,
// another recorder's remove_stale_temporaries may take the file for a dead writer's and remove it;
// the path is checked once locked, and a new name drawn if it went. Throws std::runtime_error
// naming the folder.
TemporaryFile make_temporary(const fs::path& folder, const std::string& name) {
  static constexpr char kLetters[] =
      "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
  static thread_local std::mt19937_64 random{std::random_device{}()};
  int error = 0;
  for (int attempt = 0; attempt < 100; ++attempt) {
    std::string suffix(kTemporaryRandom, ' ');
    for (char& letter : suffix) letter = kLetters[random() % (sizeof(kLetters) - 1)];
    fs::path path = folder / ("." + name + std::string(kTemporaryMark) + suffix +
                              std::string(kTemporaryExtension));
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0) {
      error = errno;
      if (error != EEXIST) break;
      continue;
    }
    LockedFd lock(fd);
    // Blocks only while a remover holds the lock, which it does just to unlink the file.
    int locked = 0;
    while ((locked = ::flock(fd, LOCK_EX)) != 0 && errno == EINTR) {
    }
    if (locked != 0) {
      error = errno;
      ::unlink(path.c_str());
      break;
    }
    if (names_open_file(path, fd)) return {std::move(path), std::move(lock)};
    error = ENOENT;  // removed by another recorder before the lock: draw another name
  }
  throw std::runtime_error("RecordVideo: cannot create a file in the video folder " +
                           quoted(folder) + ": " + std::strerror(error));
}

// Removes the temporary files in `folder` that no writer holds: a writer locks its file until it
// renames or removes it, and the kernel drops the lock when the writer's process dies (SIGKILL,
// a crash, a power cut), so an unlocked one was left by a writer that is gone. Files of another
// form, and files it cannot open or remove, are left as they are: this is housekeeping, and
// recording goes on without it.
void remove_stale_temporaries(const fs::path& folder) noexcept {
  std::vector<fs::path> candidates;
  std::error_code error;
  for (fs::directory_iterator entry(folder, error), end; !error && entry != end;
       entry.increment(error)) {
    if (is_temporary_name(entry->path().filename().string())) candidates.push_back(entry->path());
  }
  for (const fs::path& path : candidates) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
    if (fd < 0) continue;
    struct stat opened {};
    // Locked: its writer is alive. Renamed or replaced since it was listed: not stale.
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0 && ::fstat(fd, &opened) == 0 &&
        S_ISREG(opened.st_mode) && names_open_file(path, fd)) {
      ::unlink(path.c_str());
    }
    ::close(fd);
  }
}

}  // namespace

bool capped_cubic_video_schedule(std::int64_t episode_id) {
  if (episode_id < 0) return false;
  if (episode_id < 1000) {
    const auto root = static_cast<std::int64_t>(std::llround(std::cbrt(episode_id)));
    return root * root * root == episode_id;
  }
  return episode_id % 1000 == 0;
}

// An open clip: the encoder writing its temporary file, and the frame size it was opened for.
class RecordVideo::Clip {
 public:
  Clip(const fs::path& folder, const std::string& name, int width, int height, double fps)
      : final_path_(folder / (name + ".mp4")),
        temporary_(make_temporary(folder, name)),
        width_(width),
        height_(height),
        video_width_(width + width % 2),
        video_height_(height + height % 2) {
    try {
      open_encoder(fps);
    } catch (...) {
      remove_temporary();
      throw;
    }
  }

  ~Clip() { remove_temporary(); }
  Clip(const Clip&) = delete;
  Clip& operator=(const Clip&) = delete;

 private:
  // The OS's reason why 64 kB (a video header and a first frame, or so) cannot be written to the
  // temporary file, or "" when they can.
  std::string probe_write() const {
    const int fd = ::open(temporary_.path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0) return std::strerror(errno);
    const std::string zeros(64 * 1024, '\0');
    std::size_t written = 0;
    int error = 0;
    while (written < zeros.size() && error == 0) {
      const ssize_t n = ::write(fd, zeros.data() + written, zeros.size() - written);
      if (n < 0) {
        if (errno != EINTR) error = errno;
      } else {
        written += static_cast<std::size_t>(n);
      }
    }
    if (error == 0 && ::fsync(fd) != 0) error = errno;
    ::close(fd);
    return error == 0 ? "" : std::strerror(error);
  }

  void open_encoder(double fps) {
    const std::string preferred = preferred_fourcc();
    if (open(preferred, fps)) return;
    if (open(kFallbackFourcc, fps)) {
      if (!fallback_warned.exchange(true)) {
        std::cerr << "pixelgym: warning: RecordVideo: the " << preferred
                  << (preferred == kPreferredFourcc ? " (H.264)" : "")
                  << " encoder did not open through OpenCV's FFmpeg backend; writing "
                  << kFallbackFourcc
                  << " (MPEG-4 Part 2) videos instead, which some browsers do not play (printed "
                     "once per process)\n";
      }
      return;
    }
    // The encoders also fail to open when the file cannot be written (a full disk): say so.
    const std::string write_error = probe_write();
    if (!write_error.empty()) {
      throw std::runtime_error("RecordVideo: cannot write " + quoted(final_path_) + ": " +
                               write_error + " (the video encoder could not open its file)");
    }
    throw std::runtime_error("RecordVideo: cannot open a video encoder for " + quoted(final_path_) +
                             ": neither " + preferred + " nor " + kFallbackFourcc +
                             " opened through OpenCV's FFmpeg backend at " +
                             std::to_string(video_width_) + "x" + std::to_string(video_height_) +
                             ", " + std::to_string(fps) + " fps");
  }

 public:
  // Writes one (height, width, 3) RGB frame. Throws std::runtime_error for another size.
  void write(const Array& frame) {
    if (frame.dtype() != DType::kUInt8 || frame.ndim() != 3 || frame.shape()[2] != 3) {
      throw std::runtime_error("RecordVideo: render() must return an (H, W, 3) uint8 frame for " +
                               quoted(final_path_) + ", got " + dtype_name(frame.dtype()) + " " +
                               shape_to_string(frame.shape()));
    }
    if (frame.shape()[0] != height_ || frame.shape()[1] != width_) {
      throw std::runtime_error(
          "RecordVideo: frame " + std::to_string(frames_) + " of " + quoted(final_path_) + " is " +
          std::to_string(frame.shape()[1]) + "x" + std::to_string(frame.shape()[0]) +
          " (width x height), but the clip's first frame was " + std::to_string(width_) + "x" +
          std::to_string(height_) + "; every frame of a clip must have the same size");
    }
    const cv::Mat rgb(height_, width_, CV_8UC3, const_cast<void*>(frame.raw_data()));
    cv::cvtColor(rgb, bgr_, cv::COLOR_RGB2BGR);  // reuses bgr_ after the first frame
    if (video_width_ != width_ || video_height_ != height_) {
      cv::copyMakeBorder(bgr_, padded_, 0, video_height_ - height_, 0, video_width_ - width_,
                         cv::BORDER_REPLICATE);
      writer_.write(padded_);
    } else {
      writer_.write(bgr_);
    }
    ++frames_;
  }

  std::int64_t frames() const { return frames_; }

  // Closes the encoder, reads the file back and renames it to its final name. Throws
  // std::runtime_error (the temporary file removed) when the file is not what was written.
  VideoClip finish() {
    writer_.release();
    verify();
    std::error_code error;
    fs::rename(temporary_.path, final_path_, error);
    if (error) {
      throw std::runtime_error("RecordVideo: cannot rename " + quoted(temporary_.path) + " to " +
                               quoted(final_path_) + ": " + error.message());
    }
    temporary_.path.clear();
    temporary_.lock.reset();
    return {final_path_, frames_, video_width_, video_height_, fourcc_};
  }

 private:
  bool open(const std::string& fourcc, double fps) {
    if (!writer_.open(temporary_.path.string(), cv::CAP_FFMPEG, fourcc_code(fourcc), fps,
                      cv::Size(video_width_, video_height_), true)) {
      return false;
    }
    fourcc_ = fourcc;
    return true;
  }

  // OpenCV's VideoWriter::write reports no error (a full disk goes unnoticed), so the file is
  // opened again and its frame count, size and last frame checked.
  void verify() {
    std::error_code error;
    const auto size = fs::file_size(temporary_.path, error);
    std::string problem;
    if (error) {
      problem = "it cannot be read: " + error.message();
    } else {
      cv::VideoCapture capture(temporary_.path.string(), cv::CAP_FFMPEG);
      const auto count =
          capture.isOpened() ? static_cast<std::int64_t>(capture.get(cv::CAP_PROP_FRAME_COUNT)) : 0;
      cv::Mat last;
      if (!capture.isOpened()) {
        problem = "it does not open as a video (" + std::to_string(size) + " bytes)";
      } else if (count != frames_) {
        problem = "it holds " + std::to_string(count) + " of " + std::to_string(frames_) +
                  " frames (" + std::to_string(size) + " bytes)";
      } else if (capture.get(cv::CAP_PROP_FRAME_WIDTH) != video_width_ ||
                 capture.get(cv::CAP_PROP_FRAME_HEIGHT) != video_height_) {
        problem = "its frames are not " + std::to_string(video_width_) + "x" +
                  std::to_string(video_height_);
      } else if (!capture.set(cv::CAP_PROP_POS_FRAMES, static_cast<double>(frames_ - 1)) ||
                 !capture.read(last) || last.empty()) {
        problem = "its last frame cannot be decoded (" + std::to_string(size) + " bytes)";
      }
    }
    if (problem.empty()) return;
    const fs::path temporary = temporary_.path;
    // Free space while the partial file still takes its room: what the encoder saw.
    const long long available = free_bytes(final_path_.parent_path());
    remove_temporary();
    std::string message = "RecordVideo: writing " + quoted(final_path_) + " failed: the encoded " +
                          "file " + quoted(temporary) + " was read back and " + problem;
    if (available >= 0) {
      message += "; its file system had " + std::to_string(available) +
                 " bytes free with that file in place";
      if (available < (1 << 20)) message += " (a full disk?)";
    }
    throw std::runtime_error(message + ". The temporary file was removed; nothing was written.");
  }

  void remove_temporary() noexcept {
    if (writer_.isOpened()) writer_.release();
    if (temporary_.path.empty()) return;
    std::error_code ignored;
    fs::remove(temporary_.path, ignored);  // then unlocked: no remover sees it unlocked first
    temporary_.path.clear();
    temporary_.lock.reset();
  }

  fs::path final_path_;
  TemporaryFile temporary_;  // locked until renamed or removed
  int width_;
  int height_;
  int video_width_;
  int video_height_;
  std::string fourcc_;
  cv::VideoWriter writer_;
  cv::Mat bgr_;
  cv::Mat padded_;
  std::int64_t frames_ = 0;
};

RecordVideo::RecordVideo(std::unique_ptr<Env> env, const fs::path& video_folder,
                         EpisodeTrigger episode_trigger, StepTrigger step_trigger,
                         std::int64_t video_length, const std::string& name_prefix,
                         std::optional<double> fps)
    : Wrapper(std::move(env)),
      folder_(video_folder),
      episode_trigger_(std::move(episode_trigger)),
      step_trigger_(std::move(step_trigger)),
      video_length_(video_length),
      name_prefix_(name_prefix),
      fps_(fps ? *fps : env_->metadata().render_fps) {
  const auto& modes = env_->metadata().render_modes;
  if (std::find(modes.begin(), modes.end(), "rgb_array") == modes.end()) {
    std::string listed;
    for (const std::string& mode : modes) listed += (listed.empty() ? "\"" : ", \"") + mode + "\"";
    throw std::invalid_argument("RecordVideo: " + env_->name() +
                                " must render \"rgb_array\" frames, but its "
                                "metadata().render_modes is [" +
                                listed + "]");
  }
  if (video_length < 0) {
    throw std::invalid_argument(
        "RecordVideo: video_length must be >= 0 (0 records whole episodes), got " +
        std::to_string(video_length));
  }
  if (!(std::isfinite(fps_) && fps_ > 0.0)) {
    throw std::invalid_argument(
        std::string("RecordVideo: fps must be > 0 and finite, got ") + std::to_string(fps_) +
        (fps ? "" : " from " + env_->name() + "'s metadata().render_fps; pass fps"));
  }
  check_name(name_prefix, "name_prefix");
  if (folder_.empty()) {
    throw std::invalid_argument("RecordVideo: video_folder must not be empty");
  }
  std::error_code error;
  fs::create_directories(folder_, error);
  if (error || !fs::is_directory(folder_)) {
    throw std::runtime_error("RecordVideo: cannot create the video folder " + quoted(folder_) +
                             ": " + (error ? error.message() : std::string("it exists as a file")));
  }
  // Temporary files left by recorders that were killed (SIGKILL, a crash) before they could
  // remove them; those of recorders writing into this folder now are kept.
  remove_stale_temporaries(folder_);
  // A probe: fail now, not at the first clip, when no file can be created in the folder.
  fs::remove(make_temporary(folder_, "write-check").path, error);
  if (!episode_trigger_ && !step_trigger_) episode_trigger_ = capped_cubic_video_schedule;
}

RecordVideo::~RecordVideo() {
  if (!recording_) return;
  try {
    stop_recording();
  } catch (const std::exception& error) {
    std::cerr << "pixelgym: error: " << error.what() << " (in ~RecordVideo)\n";
  }
}

void RecordVideo::start_recording(const std::string& video_name) {
  check_name(video_name, "video_name");
  if (recording_) stop_recording();
  recording_ = true;
  video_name_ = video_name;
}

std::optional<VideoClip> RecordVideo::stop_recording() {
  if (!recording_) return std::nullopt;
  std::unique_ptr<Clip> clip = std::move(clip_);
  recording_ = false;
  video_name_.clear();
  if (!clip) return std::nullopt;  // no frame: no file
  return clip->finish();           // on failure ~Clip removes the temporary file
}

void RecordVideo::abort_clip() noexcept {
  clip_.reset();  // removes the temporary file
  recording_ = false;
  video_name_.clear();
}

void RecordVideo::capture_frame() {
  try {
    const Array frame = env_->render();
    if (!clip_) {
      if (frame.ndim() < 2) {
        throw std::runtime_error("RecordVideo: render() returned a frame of shape " +
                                 shape_to_string(frame.shape()) + ", not (H, W, 3)");
      }
      clip_ = std::make_unique<Clip>(folder_, video_name_, static_cast<int>(frame.shape()[1]),
                                     static_cast<int>(frame.shape()[0]), fps_);
    }
    clip_->write(frame);
  } catch (...) {
    abort_clip();
    throw;
  }
}

void RecordVideo::end_clip_if_full() {
  if (video_length_ > 0 && clip_ && clip_->frames() >= video_length_) stop_recording();
}

void RecordVideo::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                           ResetResult& out) {
  Wrapper::do_reset(seed, options, out);
  ++episode_id_;
  if (recording_ && video_length_ == 0 && clip_) stop_recording();
  if (episode_trigger_ && episode_trigger_(episode_id_)) {
    start_recording(name_prefix_ + "-episode-" + std::to_string(episode_id_));
  }
  if (recording_) {
    capture_frame();
    end_clip_if_full();
  }
}

void RecordVideo::do_step(const Value& action, StepResult& out) {
  try {
    Wrapper::do_step(action, out);
  } catch (...) {
    // The episode broke off: the clip would hold part of it, so none is left (nothing truncated
    // under a final name); the error goes on to the caller.
    abort_clip();
    throw;
  }
  ++step_id_;
  if (step_trigger_ && step_trigger_(step_id_)) {
    start_recording(name_prefix_ + "-step-" + std::to_string(step_id_));
  }
  if (recording_) {
    capture_frame();
    end_clip_if_full();
  }
}

void RecordVideo::do_close() {
  try {
    stop_recording();
  } catch (...) {
    Wrapper::do_close();
    throw;
  }
  Wrapper::do_close();
}

}  // namespace pixelgym::wrappers
