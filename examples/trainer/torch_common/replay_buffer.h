// The off-policy learner's replay buffer: transitions of a vector env's episodes, each image
// frame stored once, sampled as n-step transitions with their frame stacks rebuilt.
#pragma once

#include <cstdint>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// What one observation holds, as the buffer stores it.
struct ReplayLayout {
  /// An image key observed as a stack of `stack` frames of `frame_bytes` bytes each, oldest
  /// first, contiguous (FrameStackObservation's new_axis layout, padding=reset; stack 1: a
  /// single frame). Only the newest frame of each observation is stored.
  struct Image {
    std::string key;
    std::int64_t stack = 1;
    std::int64_t frame_bytes = 0;
  };
  /// A vector key: `size` float32 values.
  struct Vector {
    std::string key;
    std::int64_t size = 0;
  };
  std::vector<Image> images;
  std::vector<Vector> vectors;
  /// Float32 elements of one action.
  std::int64_t action_size = 0;
};

/// One env's observation as the buffer reads it: per image key (layout order) its stacked
/// frames, per vector key its values.
struct ObservationView {
  std::vector<const std::uint8_t*> images;
  std::vector<const float*> vectors;
};

/// A batch of B sampled transitions, row-major, laid out as ReplayLayout (images: their whole
/// stacks). Reused across samples: ReplayBuffer::sample resizes it once.
struct ReplayBatch {
  std::int64_t size = 0;
  std::vector<std::vector<std::uint8_t>> images;  // per image key: B x stack x frame_bytes
  std::vector<std::vector<float>> vectors;        // per vector key: B x size
  std::vector<std::vector<std::uint8_t>> next_images;
  std::vector<std::vector<float>> next_vectors;
  std::vector<float> actions;    // B x action_size
  std::vector<float> rewards;    // B: the n-step discounted sum of rewards
  std::vector<float> discounts;  // B: gamma^m to bootstrap from the next observation, 0 if none
};

/// A ring buffer of the transitions of `num_envs` envs, `capacity` slots in all (capacity /
/// num_envs per env). A slot holds one observation (the newest frame of each image key, the
/// vector keys), the action taken in it, the reward that followed and the step's flags. An
/// episode of L steps takes L + 1 slots: its observations 0..L-1 with their actions, then its
/// last observation (the final_obs of a vector env's autoreset) without one.
///
/// Sampling draws a slot with an action uniformly among those that can be sampled: its n-step
/// transition (s_t, a_t, R, discount, s_{t+m}) with R = sum_{k<m} gamma^k r_{t+k} and
/// m = n_step, or fewer when the episode ends within n steps. An episode that ends by
/// `terminated` gives discount 0 (nothing to bootstrap from); one that ends by `truncated` (a
/// time limit) gives gamma^m and s_{t+m} is its last observation. A slot whose n-step window
/// runs past the newest step, or whose frame stack or window reaches slots already overwritten,
/// is not sampled. Frame stacks are rebuilt from the slots of the same episode, the first frame
/// repeated before the episode's start, exactly as FrameStackObservation(padding=reset) built
/// them; add() checks that every observation it is given is such a stack.
///
/// Determinism: sample() draws only from the generator it is given.
class ReplayBuffer {
 public:
  /// Throws std::invalid_argument naming the setting for num_envs < 1, n_step < 1, gamma
  /// outside [0, 1], a stack < 1 or frame_bytes < 1, a vector size < 1, action_size < 1, or a
  /// capacity below num_envs x (n_step + max stack + 2).
  ReplayBuffer(ReplayLayout layout, std::int64_t num_envs, std::int64_t capacity,
               std::int64_t n_step, double gamma);

  /// Starts an episode of env `env` with its first observation.
  void add_first(std::int64_t env, const ObservationView& obs);
  /// The step env `env` took from its newest observation: the action, the reward, the flags and
  /// the observation after it (its final observation when the step ended the episode; then call
  /// add_first with the next episode's first). Throws std::logic_error when the env has no
  /// observation to act from (no add_first, or an episode already ended), and
  /// std::invalid_argument (naming the key) when an image stack is not the one the episode's
  /// frames make.
  void add_step(std::int64_t env, const float* action, double reward, bool terminated,
                bool truncated, const ObservationView& next_obs);

  /// Fills `batch` with `batch_size` transitions drawn uniformly from the sampleable ones.
  /// Throws std::logic_error when there is none.
  void sample(std::int64_t batch_size, std::mt19937_64& rng, ReplayBatch& batch) const;

  /// Steps added (all envs), and whether `sample` has transitions to draw.
  std::int64_t steps_added() const { return steps_added_; }
  bool can_sample() const;
  /// Slots in use (all envs) and the capacity.
  std::int64_t slots_used() const;
  std::int64_t capacity() const { return slots_per_env_ * num_envs_; }
  /// The bytes the buffer holds allocated (all slots, full or not).
  std::int64_t bytes() const;
  const ReplayLayout& layout() const { return layout_; }
  std::int64_t n_step() const { return n_step_; }

 private:
  enum Flag : std::uint8_t { kHasAction = 1, kTerminated = 2, kTruncated = 4 };
  struct EnvSlots {
    std::vector<std::unique_ptr<std::uint8_t[]>> frames;  // per image key: slots x frame_bytes
    std::vector<std::vector<float>> vectors;              // per vector key: slots x size
    std::vector<float> actions;                           // slots x action_size
    std::vector<float> rewards;                           // slots
    std::vector<std::uint8_t> flags;                      // slots
    std::vector<std::int64_t> episode_start;              // slots: the global index of its first
    std::int64_t written = 0;  // slots ever written (the next global index)
    bool open = false;         // the newest slot awaits its action
  };
  std::int64_t ring(std::int64_t global) const { return global % slots_per_env_; }
  std::int64_t oldest(const EnvSlots& slots) const;
  // Throws std::invalid_argument when `obs`, to go into global slot `global` of env `env` (its
  // episode started at `start`), does not have the layout or stacks the buffer rebuilds.
  void check_observation(std::int64_t env, std::int64_t global, std::int64_t start,
                         const ObservationView& obs) const;
  // Writes `obs` (checked) into global slot `global` of env `env`.
  void write_observation(std::int64_t env, std::int64_t global, std::int64_t start,
                         const ObservationView& obs);
  // The n-step window from `global`: false when it cannot be sampled.
  struct Window {
    std::int64_t next = 0;  // global slot of s_{t+m}
    float reward = 0.0f;
    float discount = 0.0f;
  };
  bool window(const EnvSlots& slots, std::int64_t global, Window& out) const;
  // Copies the stack of image `i` at `global` into `dest`.
  void copy_stack(const EnvSlots& slots, std::size_t i, std::int64_t global,
                  std::uint8_t* dest) const;
  void copy_observation(const EnvSlots& slots, std::int64_t global, std::int64_t row,
                        std::vector<std::vector<std::uint8_t>>& images,
                        std::vector<std::vector<float>>& vectors) const;

  ReplayLayout layout_;
  std::int64_t num_envs_;
  std::int64_t slots_per_env_;
  std::int64_t n_step_;
  double gamma_;
  std::int64_t max_stack_ = 1;
  std::vector<EnvSlots> envs_;
  std::int64_t steps_added_ = 0;
};

}  // namespace pixelgym::trainer
