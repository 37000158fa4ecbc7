// FrameStackObservation: the last k frames of an image observation (a bare image or one key of a
// Dict), as gymnasium.wrappers.FrameStackObservation, but sharing frames instead of copying them.
//
// Why a tape. Gymnasium 1.x copies k frames into every observation, so a replay buffer that keeps
// every observation holds each frame k times (openai/baselines#295: 30 GB where 6.9 GB was
// expected); LazyFrames avoided that with a list of frames, which is not one contiguous array and
// so not what numpy's buffer protocol or torch::from_blob take. Here the frames go onto a *tape*:
// one contiguous allocation of N frame slots that the wrapper appends each new frame to. The
// observation of step t is a view of the k consecutive slots ending with frame t (for the
// kNewAxis and kChannelsFirst layouts, whose stacked array is exactly k frames back to back), so
// consecutive observations share k - 1 frames and a replay buffer keeps about one copy of each
// distinct frame alive. A slot, once in a returned observation, is never written again while
// anyone holds the tape: when the tape is full the wrapper starts a new one and copies the last
// k - 1 frames to its front (k - 1 extra frames every N - k + 1 steps: an overhead of about
// (k - 1) / N in memory and copying). When nobody but the wrapper holds the tape (no
// observation viewing it is alive: a caller that keeps nothing, or that steps into buffers of
// its own) the wrapper rewinds and reuses it instead, so such a caller costs one tape in all and
// no allocation per step. A reset appends a fresh window of k slots (k - 1 padding frames, then
// the reset frame) after the last used slot, in the same tape when it has room.
//
// Tape size N = kTapeSlotsPerFrame * k = 16 k slots (64 for k = 4: 1.3 MiB at 84x84x3): the
// smallest that keeps a 1,000-step replay buffer within 1.1x the bytes of its distinct frames
// (docs/design-notes.md, "Wrappers", has the measurement). Keeping one observation in many costs
// up to N / k times what copying would: such a caller should clone() what it keeps or step into
// buffers of its own.
//
// Tapes in use: a caller that keeps nothing (or steps into its own buffers) uses one, rewound;
// one that keeps only the latest observation uses two in turn (the wrapper keeps the previous
// tape as a spare, reused once nobody views it); a replay buffer allocates a tape per N - k + 1
// steps and keeps the spare (one it holds anyway) alive.
//
// kChannelsLast interleaves the k frames per pixel ((H, W, C k)), so its stacked array is not a
// run of whole frames: it cannot share, and copies k frames into every observation (it still
// keeps its frames on a tape, which nobody else holds, so it allocates nothing per step).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "pixelgym/envs/wrapper.h"
#include "pixelgym/wrappers/image_key.h"

namespace pixelgym::wrappers {

/// What fills the stack before an episode has k frames.
enum class FrameStackPadding : std::uint8_t {
  /// Copies of the reset frame (Gymnasium's padding_type="reset", its default).
  kReset,
  /// Zero frames (padding_type="zero").
  kZero,
};

/// How the k frames are laid out in the stacked image.
enum class FrameStackLayout : std::uint8_t {
  /// (k, *shape): a new leading axis, as Gymnasium.
  kNewAxis,
  /// (C, H, W) images concatenated on axis 0: (k C, H, W).
  kChannelsFirst,
  /// Concatenated on the last axis: (H, W, C k); an (H, W) image gives (H, W, k).
  kChannelsLast,
};

/// "reset", "zero"; "new_axis", "channels_first", "channels_last" (the text spec's names).
const char* to_string(FrameStackPadding padding);
const char* to_string(FrameStackLayout layout);

/// Stacks the last `stack_size` frames of the uint8 image under `key` (or of the bare image
/// observation), oldest first and newest last. Any uint8 image of rank 2 or 3 is accepted
/// ((H, W), (H, W, C), (C, H, W)). The output space is a uint8 Box with bounds [0, 255] laid out
/// as `layout` says; the Dict's other keys pass through untouched (the latest step's).
///
/// Frames are shared between observations through a tape (see the file comment) for kNewAxis
/// and kChannelsFirst: what `step()` and `reset()` return views the tape, and is never changed
/// by later calls. `reset_into` / `step_into` also take buffers of the caller's (a vector env's
/// batch slot), into which they copy the k frames; once warmed up that path allocates nothing.
/// They refuse (std::invalid_argument) a buffer whose image is a view of a frame-stack tape
/// other than the window the next observation goes to, e.g. an observation returned earlier
/// passed back as the buffer: writing into it would change frames other observations show (as
/// after any error in step_into, the episode must then be reset).
class FrameStackObservation final : public Wrapper {
 public:
  /// The largest stack_size accepted.
  static constexpr std::int64_t kMaxStackSize = 256;
  /// Tape slots per stacked frame: a tape holds kTapeSlotsPerFrame * stack_size frames.
  static constexpr std::int64_t kTapeSlotsPerFrame = 16;

  /// Throws std::invalid_argument when `stack_size` is < 1 or > kMaxStackSize, as find_image
  /// when `key` does not name a uint8 image of rank 2 or 3 (listing the keys that do), and when
  /// `layout` is kChannelsFirst for an image of rank 2 (it has no channel axis: use kNewAxis).
  FrameStackObservation(std::unique_ptr<Env> env, std::int64_t stack_size,
                        FrameStackPadding padding = FrameStackPadding::kReset,
                        const std::string& key = "pixels",
                        FrameStackLayout layout = FrameStackLayout::kNewAxis);

  const Space& observation_space() const override { return *observation_space_; }
  /// A buffer whose image is a view of the tape where the next observation's window will be
  /// (kReset: a fresh window; kStep: the current one moved on by a frame), the Dict's other
  /// entries zeros of their own; for kChannelsLast, and before the first reset for kStep,
  /// `observation_space().zeros()`. Its image shows the stack only once the call it was asked
  /// for has filled it.
  Value observation_buffer(BufferFor call) override;

  /// k, the number of frames stacked.
  std::int64_t stack_size() const { return stack_size_; }
  /// What fills the stack before an episode has k frames.
  FrameStackPadding padding() const { return padding_; }
  /// How the stacked image is laid out.
  FrameStackLayout layout() const { return layout_; }
  /// Frame slots per tape.
  std::int64_t tape_slots() const { return tape_slots_; }
  /// Tapes allocated so far (rewinding a tape nobody else holds allocates none).
  std::int64_t tapes_allocated() const { return tapes_allocated_; }

 protected:
  std::string type_name() const override { return "FrameStackObservation"; }
  void do_reset(std::optional<std::uint64_t> seed, const Options& options,
                ResetResult& out) override;
  void do_step(const Value& action, StepResult& out) override;

 private:
  // Makes room for a reset window (k free slots) or for the next step's frame, and returns the
  // slot where the next observation's window will start; the same again until frames are
  // written. prepare_step keeps the newest k - 1 frames; so does prepare_reset with
  // `keep_window` (the buffer hook's call, after which a step may come instead of the reset).
  std::int64_t prepare_reset(bool keep_window);
  std::int64_t prepare_step();
  // Moves the last `carry` frames to the front of a tape: the same one, rewound, when nobody
  // else holds it, else the spare when nobody else holds that, else a new one; next_ = carry.
  void switch_tape(std::int64_t carry);
  std::byte* slot(std::int64_t index) const;
  // Throws unless `image` is no tape view, or the view of the window starting at `start`.
  void check_buffer(const Array& image, std::int64_t start, const char* method) const;
  // Writes the stacked window that ends at next_ into `out` (nothing when it already views it)
  // and the other entries of the inner observation.
  void emit(Value& out);
  // The stacked image viewing slots [start, start + k) of the tape.
  Array window_view(std::int64_t start) const;

  SpacePtr observation_space_;
  ImageKey image_;
  std::int64_t stack_size_;
  FrameStackPadding padding_;
  FrameStackLayout layout_;
  Shape stacked_shape_;  // the output image's shape
  std::size_t frame_bytes_;
  std::int64_t channels_;  // elements per pixel of one frame for kChannelsLast (1 for (H, W))
  std::int64_t tape_slots_;

  std::shared_ptr<void> tape_;   // tape_slots_ frames; null before the first reset
  std::shared_ptr<void> spare_;  // the tape before, reused once nobody else holds it
  // The first slot not written yet. After a reset or a step the observation's window is
  // [next_ - k, next_); when the next step's slot has been prepared, only its newest k - 1
  // frames, [next_ - k + 1, next_), are sure to be on the tape.
  std::int64_t next_ = 0;
  bool has_window_ = false;  // a reset wrote a window (false before, and while a reset runs)
  std::int64_t tapes_allocated_ = 0;
  std::optional<Value> inner_obs_;  // the inner env's observation (wrapper-owned)
};

}  // namespace pixelgym::wrappers
