#include "pixelgym/wrappers/frame_stack_observation.h"

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <utility>

#include "pixelgym/envs/spaces/dict.h"

namespace pixelgym::wrappers {
namespace {

// The deleter of every tape: std::get_deleter<TapeDeleter> on an array's storage tells a view of
// a frame-stack tape (whichever wrapper's) from any other memory. Tapes come from malloc so that
// their allocator size can be read back (malloc_usable_size) when memory held is accounted.
struct TapeDeleter {
  void operator()(void* memory) const noexcept { std::free(memory); }
};

bool is_tape_view(const Array& array) {
  return array.storage() != nullptr && std::get_deleter<TapeDeleter>(array.storage()) != nullptr;
}

std::string describe_key(const ImageKey& image) {
  return image.in_dict ? "key \"" + image.key + "\"" : "the observation";
}

}  // namespace

const char* to_string(FrameStackPadding padding) {
  switch (padding) {
    case FrameStackPadding::kReset:
      return "reset";
    case FrameStackPadding::kZero:
      return "zero";
  }
  return "unknown";
}

const char* to_string(FrameStackLayout layout) {
  switch (layout) {
    case FrameStackLayout::kNewAxis:
      return "new_axis";
    case FrameStackLayout::kChannelsFirst:
      return "channels_first";
    case FrameStackLayout::kChannelsLast:
      return "channels_last";
  }
  return "unknown";
}

FrameStackObservation::FrameStackObservation(std::unique_ptr<Env> env, std::int64_t stack_size,
                                             FrameStackPadding padding, const std::string& key,
                                             FrameStackLayout layout)
    : Wrapper(std::move(env)), stack_size_(stack_size), padding_(padding), layout_(layout) {
  if (stack_size < 1 || stack_size > kMaxStackSize) {
    throw std::invalid_argument("FrameStackObservation: stack_size must be between 1 and " +
                                std::to_string(kMaxStackSize) + ", got " +
                                std::to_string(stack_size) + " (key \"" + key + "\")");
  }
  if (padding != FrameStackPadding::kReset && padding != FrameStackPadding::kZero) {
    throw std::invalid_argument("FrameStackObservation: padding must be reset or zero, got " +
                                std::to_string(static_cast<int>(padding)));
  }
  const Space& inner = env_->observation_space();
  image_ = find_image(inner, key, "FrameStackObservation", ImageRequirement{{0}, true});
  const Shape& shape = image_.shape;
  const std::int64_t k = stack_size;
  switch (layout) {
    case FrameStackLayout::kNewAxis:
      stacked_shape_ = {k};
      stacked_shape_.insert(stacked_shape_.end(), shape.begin(), shape.end());
      break;
    case FrameStackLayout::kChannelsFirst:
      if (shape.size() != 3) {
        throw std::invalid_argument(
            "FrameStackObservation: layout channels_first concatenates frames on their axis 0 "
            "(channels of a (C, H, W) image), which needs an image of rank 3; " +
            describe_key(image_) + " is uint8 " + shape_to_string(shape) +
            ": use layout new_axis (giving " + shape_to_string({k, shape[0], shape[1]}) +
            ") or channels_last");
      }
      // An (H, W, C) image (channels last: C of 1, 3 or 4 behind a larger first axis) stacked on
      // axis 0 would pile frames up along the height: refuse it rather than stack nonsense.
      if (shape[2] <= 4 && shape[0] > 4) {
        throw std::invalid_argument(
            "FrameStackObservation: layout channels_first concatenates frames on axis 0, the "
            "channels of a (C, H, W) image; " +
            describe_key(image_) + " is uint8 " + shape_to_string(shape) +
            ", which looks like (H, W, C) with its channels last: apply ChannelFirstObservation "
            "(--wrap channel_first) before the frame stack, giving " +
            shape_to_string({k * shape[2], shape[0], shape[1]}) +
            ", or use layout channels_last (giving " +
            shape_to_string({shape[0], shape[1], k * shape[2]}) + ")");
      }
      stacked_shape_ = {k * shape[0], shape[1], shape[2]};
      break;
    case FrameStackLayout::kChannelsLast:
      channels_ = shape.size() == 3 ? shape[2] : 1;
      stacked_shape_ = {shape[0], shape[1], channels_ * k};
      break;
    default:
      throw std::invalid_argument(
          "FrameStackObservation: layout must be new_axis, channels_first or channels_last, got " +
          std::to_string(static_cast<int>(layout)));
  }
  frame_bytes_ = static_cast<std::size_t>(shape_size(shape));
  tape_slots_ = kTapeSlotsPerFrame * k;
  observation_space_ = replace_image(inner, image_, uint8_image_space(stacked_shape_));
}

namespace {

// After use_count() == 1 is seen: orders the releases of the last views (their reads, on any
// thread) before this wrapper's writes. ThreadSanitizer does not model fences (GCC refuses them
// under -fsanitize=thread), so a TSan build goes without; shared_ptr's own count is atomic.
inline void acquire_after_last_release() {
#if defined(__SANITIZE_THREAD__)
  // Nothing: see above.
#else
  std::atomic_thread_fence(std::memory_order_acquire);
#endif
}

}  // namespace

std::byte* FrameStackObservation::slot(std::int64_t index) const {
  return static_cast<std::byte*>(tape_.get()) + static_cast<std::size_t>(index) * frame_bytes_;
}

void FrameStackObservation::switch_tape(std::int64_t carry) {
  const std::size_t carry_bytes = static_cast<std::size_t>(carry) * frame_bytes_;
  // use_count() == 1: no observation views this tape, and none can appear but through this
  // wrapper. The fence orders the releases of the last views (their reads) before our writes.
  if (tape_ != nullptr && tape_.use_count() == 1) {
    acquire_after_last_release();
    if (carry_bytes > 0) std::memmove(slot(0), slot(next_ - carry), carry_bytes);
  } else {
    std::shared_ptr<void> old = std::move(tape_);
    const std::byte* from = old != nullptr
                                ? static_cast<const std::byte*>(old.get()) +
                                      static_cast<std::size_t>(next_ - carry) * frame_bytes_
                                : nullptr;
    if (spare_ != nullptr && spare_.use_count() == 1) {
      // The tape before the last one, which nobody views any more: no allocation.
      acquire_after_last_release();
      tape_ = std::move(spare_);
    } else {
      void* memory = std::malloc(static_cast<std::size_t>(tape_slots_) * frame_bytes_);
      if (memory == nullptr) throw std::bad_alloc();
      tape_ = std::shared_ptr<void>(memory, TapeDeleter{});
      ++tapes_allocated_;
    }
    spare_ = std::move(old);
    if (carry_bytes > 0) std::memcpy(slot(0), from, carry_bytes);
  }
  next_ = carry;
}

std::int64_t FrameStackObservation::prepare_reset(bool keep_window) {
  if (tape_ != nullptr && tape_slots_ - next_ >= stack_size_) return next_;
  // A step may still come instead of the reset: it needs the newest k - 1 frames. The tape holds
  // 16 k slots, so k more fit after them.
  switch_tape(keep_window && has_window_ ? stack_size_ - 1 : 0);
  return next_;
}

std::int64_t FrameStackObservation::prepare_step() {
  if (next_ == tape_slots_) switch_tape(stack_size_ - 1);
  return next_ - stack_size_ + 1;
}

Array FrameStackObservation::window_view(std::int64_t start) const {
  return Array::from_external(slot(start), DType::kUInt8, stacked_shape_, tape_);
}

Value FrameStackObservation::observation_buffer(BufferFor call) {
  if (layout_ == FrameStackLayout::kChannelsLast) return observation_space_->zeros();
  std::int64_t start = 0;
  if (call == BufferFor::kReset) {
    start = prepare_reset(/*keep_window=*/true);
  } else if (has_window_) {
    start = prepare_step();
  } else {
    return observation_space_->zeros();  // no episode yet: step() will refuse
  }
  Array view = window_view(start);
  if (!image_.in_dict) return view;
  const auto& dict = dynamic_cast<const spaces::Dict&>(*observation_space_);
  ValueDict values;
  for (std::size_t i = 0; i < dict.entries().size(); ++i) {
    const auto& [name, space] = dict.entries()[i];
    values.insert(name, i == image_.index ? Value(view) : space->zeros());
  }
  return values;
}

void FrameStackObservation::check_buffer(const Array& image, std::int64_t start,
                                         const char* method) const {
  if (!is_tape_view(image)) return;
  if (layout_ != FrameStackLayout::kChannelsLast && tape_ != nullptr &&
      image.raw_data() == slot(start)) {
    return;
  }
  throw std::invalid_argument(
      name() + ": " + method + " buffer: its image (" + describe_key(image_) +
      ") views stacked frames that other observations share (an observation returned by reset() "
      "or step(), or an earlier observation_buffer()), not the window the next observation goes "
      "to; writing into it would change those observations. Pass a buffer of your own "
      "(observation_space().zeros()) or a fresh observation_buffer()");
}

void FrameStackObservation::emit(Value& out) {
  Array& image = image_of(out, image_);
  const std::int64_t start = next_ - stack_size_;
  if (layout_ != FrameStackLayout::kChannelsLast) {
    if (image.raw_data() != slot(start)) {
      std::memcpy(image.raw_data(), slot(start),
                  static_cast<std::size_t>(stack_size_) * frame_bytes_);
    }
  } else {
    // out[p][j * C + c] = frame_j[p][c]: the frames interleave per pixel.
    auto* target = static_cast<std::uint8_t*>(image.raw_data());
    const auto channels = static_cast<std::size_t>(channels_);
    const std::size_t pixels = frame_bytes_ / channels;
    const std::size_t stride = channels * static_cast<std::size_t>(stack_size_);
    for (std::int64_t j = 0; j < stack_size_; ++j) {
      const auto* source = reinterpret_cast<const std::uint8_t*>(slot(start + j));
      std::uint8_t* column = target + static_cast<std::size_t>(j) * channels;
      for (std::size_t p = 0; p < pixels; ++p) {
        for (std::size_t c = 0; c < channels; ++c)
          column[p * stride + c] = source[p * channels + c];
      }
    }
  }
  copy_other_entries(*inner_obs_, out, image_);
}

void FrameStackObservation::do_reset(std::optional<std::uint64_t> seed, const Options& options,
                                     ResetResult& out) {
  has_window_ = false;  // until the reset's window is written
  const std::int64_t start = prepare_reset(/*keep_window=*/false);
  check_buffer(image_of(out.obs, image_), start, "reset_into()");
  if (!inner_obs_) inner_obs_ = env_->observation_space().zeros();
  {
    SwapBack swap(out.obs, *inner_obs_);
    env_->reset_into(out, seed, options);
  }
  const void* frame = image_of(*inner_obs_, image_).raw_data();
  for (std::int64_t i = 0; i + 1 < stack_size_; ++i) {
    if (padding_ == FrameStackPadding::kReset) {
      std::memcpy(slot(start + i), frame, frame_bytes_);
    } else {
      std::memset(slot(start + i), 0, frame_bytes_);
    }
  }
  std::memcpy(slot(start + stack_size_ - 1), frame, frame_bytes_);
  next_ = start + stack_size_;
  has_window_ = true;
  emit(out.obs);
}

void FrameStackObservation::do_step(const Value& action, StepResult& out) {
  if (!has_window_) throw std::logic_error(name() + ": step without a stacked window");
  const std::int64_t start = prepare_step();
  check_buffer(image_of(out.obs, image_), start, "step_into()");
  {
    SwapBack swap(out.obs, *inner_obs_);
    env_->step_into(action, out);
  }
  std::memcpy(slot(next_), image_of(*inner_obs_, image_).raw_data(), frame_bytes_);
  ++next_;
  emit(out.obs);
}

}  // namespace pixelgym::wrappers
