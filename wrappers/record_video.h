// RecordVideo: writes env.render() frames to .mp4 clips as gymnasium.wrappers.RecordVideo (1.x),
// streamed to an H.264 encoder and written through a temporary name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "pixelgym/envs/wrapper.h"

namespace pixelgym::wrappers {

/// Whether to record the episode with this index (0 for the first reset).
using EpisodeTrigger = std::function<bool(std::int64_t episode_id)>;
/// Whether to start a clip at the step with this index (0 for the first step, counted over every
/// episode).
using StepTrigger = std::function<bool(std::int64_t step_id)>;

/// Gymnasium's default episode trigger: true for the cubes 0, 1, 8, 27, ..., 729 below 1000, then
/// for every multiple of 1000; false for a negative id.
bool capped_cubic_video_schedule(std::int64_t episode_id);

/// A clip that was written.
struct VideoClip {
  /// "{folder}/{name}.mp4".
  std::filesystem::path path;
  /// Frames written.
  std::int64_t frames = 0;
  /// The video's size in pixels (the first frame's, rounded up to even).
  std::int64_t width = 0;
  std::int64_t height = 0;
  /// The FOURCC it was written with: "avc1" (H.264), PIXELGYM_RECORD_VIDEO_FOURCC's when set, or
  /// the fallback "mp4v".
  std::string codec;
};

/// Records `render()` frames ("rgb_array") of the episodes or steps its triggers choose to .mp4
/// files, with the semantics of gymnasium.wrappers.RecordVideo (1.x):
///
/// - A clip starts at a reset when `episode_trigger(episode_id)` is true (its first frame is the
///   reset's) and is named "{name_prefix}-episode-{episode_id}.mp4"; or after a step when
///   `step_trigger(step_id)` is true, named "{name_prefix}-step-{step_id}.mp4". With neither
///   trigger given, episodes follow `capped_cubic_video_schedule`. A trigger that fires while a
///   clip is being recorded ends that clip and starts a new one.
/// - `video_length` 0 records until the next reset (the whole episode: its reset frame and one
///   frame per step), or until `close()`. A positive `video_length` ends the clip after that many
///   frames (Gymnasium 1.x writes one frame more than it says).
/// - `fps` is `metadata().render_fps` unless given.
///
/// Where it does better than Gymnasium:
///
/// - Frames are streamed to the encoder as they are rendered; nothing is kept per frame, so
///   memory does not grow with the clip (Gymnasium keeps every frame until the clip ends).
/// - The video is H.264 ("avc1", yuv420p, playable in a browser) through OpenCV's FFmpeg backend.
///   If that encoder does not open at run time, the clip is written as MPEG-4 Part 2 ("mp4v")
///   with one warning on stderr, printed once per process. The environment variable
///   PIXELGYM_RECORD_VIDEO_FOURCC names another FOURCC to try first instead of "avc1".
/// - Each file is complete or absent: a clip is written to ".{name}.partial-XXXXXX.mp4" in the
///   same folder, then read back (opened with OpenCV's FFmpeg backend, its frame count, size and
///   last frame checked: OpenCV's VideoWriter reports no write errors, so a full disk is found
///   here) and only then renamed to "{name}.mp4". When a clip fails (a write error, a frame of
///   another size), the temporary file is removed and std::runtime_error names what failed and
///   the path; the step or reset that ended the clip throws it.
/// - A temporary file is locked (flock) by its writer while it lives, and the kernel drops the
///   lock when the writer's process dies, SIGKILL included. The constructor removes the
///   temporary files in `video_folder` that no writer holds (left by a killed recorder); those of
///   recorders still writing there are kept.
/// - `close()` finishes a clip in progress (as Gymnasium does) and throws if it cannot be
///   written; the destructor finishes it too, and when that fails it removes the temporary file
///   and prints the error to stderr (a destructor does not throw).
///
/// As Gymnasium's, it replaces a clip that exists under the same name (`pixelgym record` refuses
/// to unless given --overwrite).
///
/// The video's size is the first frame's of each clip, rounded up to even sides (4:2:0 video
/// needs even sides; an odd frame gets its last row or column repeated). A later frame of
/// another size is an error.
class RecordVideo final : public Wrapper {
 public:
  /// Creates `video_folder` (and its parents) if needed, removes the temporary files that killed
  /// recorders left in it, and checks that a file can be created in it. Throws
  /// std::invalid_argument when the env's metadata().render_modes lacks "rgb_array", `video_length`
  /// < 0, `fps` (given or from metadata) is not > 0 and finite, `video_folder` or `name_prefix` is
  /// empty, or `name_prefix` contains '/'; std::runtime_error naming the folder when it cannot be
  /// created or written.
  RecordVideo(std::unique_ptr<Env> env, const std::filesystem::path& video_folder,
              EpisodeTrigger episode_trigger = nullptr, StepTrigger step_trigger = nullptr,
              std::int64_t video_length = 0, const std::string& name_prefix = "rl-video",
              std::optional<double> fps = std::nullopt);
  /// Finishes a clip in progress; on failure removes its temporary file and prints why.
  ~RecordVideo() override;

  /// Starts a clip named `video_name` (file "{video_name}.mp4"), ending the one in progress
  /// first. Its first frame is the next one captured: the next step's, or the next reset's (a
  /// reset ends a whole-episode clip only once it has frames, so `start_recording("demo")` then
  /// `reset()` records that episode; Gymnasium would discard it). Throws std::invalid_argument
  /// for an empty name or one with '/'.
  void start_recording(const std::string& video_name);
  /// Ends the clip in progress and returns it; nullopt when no clip was in progress or it had no
  /// frame yet (no file is written then). Throws std::runtime_error when the clip cannot be
  /// written (its temporary file removed).
  std::optional<VideoClip> stop_recording();

  /// Whether a clip is in progress (started, possibly without a frame yet).
  bool recording() const { return recording_; }
  /// Where the clips are written.
  const std::filesystem::path& video_folder() const { return folder_; }
  /// The clips' frame rate, frames per second.
  double fps() const { return fps_; }
  /// The index of the current episode (-1 before the first reset) and of the latest step (-1
  /// before the first step), as the triggers saw them.
  std::int64_t episode_id() const { return episode_id_; }
  std::int64_t step_id() const { return step_id_; }

 protected:
  std::string type_name() const override { return "RecordVideo"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;
  void do_close() override;

 private:
  class Clip;  // an open clip: its writer, temporary file and frame size

  void capture_frame();
  void end_clip_if_full();
  // Removes the clip's temporary file and stops recording.
  void abort_clip() noexcept;

  std::filesystem::path folder_;
  EpisodeTrigger episode_trigger_;
  StepTrigger step_trigger_;
  std::int64_t video_length_;
  std::string name_prefix_;
  double fps_;

  bool recording_ = false;
  std::string video_name_;
  std::unique_ptr<Clip> clip_;  // null until the clip's first frame
  std::int64_t episode_id_ = -1;
  std::int64_t step_id_ = -1;
};

}  // namespace pixelgym::wrappers
