// The observation and action of one env as an off-policy learner reads them: one image key (a
// stack of frames) or none, float vector keys, and a bounded Box action.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "examples/trainer/torch_common/replay_buffer.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"
#include "pixelgym/envs/vector/vector_env.h"

namespace pixelgym::trainer {

/// The observation as the learner reads it: one image key (or none) and vector keys.
struct InputLayout {
  /// The image key ("" for a bare Box observation): frames of (H, W, C) (or (H, W): C = 1) in
  /// stacks of `stack`.
  bool has_image = false;
  std::string image_key;
  std::int64_t stack = 1;
  std::int64_t height = 0;
  std::int64_t width = 0;
  std::int64_t channels = 0;
  /// Float vector keys and their sizes, in key order.
  std::vector<std::string> vector_keys;
  std::vector<std::int64_t> vector_sizes;
  std::int64_t action_size = 0;
  /// The Box action's bounds (float32, finite).
  std::vector<float> action_low;
  std::vector<float> action_high;

  /// The buffer's layout of this input.
  ReplayLayout replay_layout() const;
};

/// The input layout of one env's spaces, for learner `learner` ("drqv2") on env `env_name`
/// (both for the errors). The observation is a Box or a Dict of Boxes with at most one uint8
/// image key of shape (frame_stack, H, W[, C]) (or, for frame_stack 1, (H, W[, C])), at least
/// 16x16, and any float32 keys; the action space a bounded float Box. Throws
/// std::invalid_argument "{learner} on {env_name}: ..." naming the key and the space otherwise
/// (a Discrete action space among them).
InputLayout input_layout(const Space& observation_space, const Space& action_space,
                         std::int64_t frame_stack, const std::string& learner,
                         const std::string& env_name);

/// Adds the envs' first observations (rows of a vector env's `observations` batch, laid out as
/// `input`) to `buffer`: at the start, or where a replay starts.
void add_first_observations(ReplayBuffer& buffer, const InputLayout& input,
                            const Value& observations);

/// Adds a vector env's `step` (SameStep autoreset) to `buffer`: for each env its transition
/// (the action `unit_actions` row, float32 (num_envs, action_size) in [-1, 1]; the reward; the
/// flags; the next observation, an ended episode's from infos["final_obs"]), then for an ended
/// episode the next episode's first observation. Throws std::logic_error naming `learner` when
/// an episode ended without infos["final_obs"].
void add_env_step(ReplayBuffer& buffer, const InputLayout& input, const float* unit_actions,
                  const vector::VectorStepResult& step, const std::string& learner);

}  // namespace pixelgym::trainer
