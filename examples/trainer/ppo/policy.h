// Policy: the actor-critic network the PPO trainer learns — an encoder per observation key (a CNN
// for each image, one MLP for the vector keys), fused by concatenation, a trunk, and a
// categorical (Discrete) or Gaussian (Box) action head beside a value head.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "examples/trainer/torch_common/observation_tensors.h"
#include "examples/trainer/torch_common/random_shift.h"
#include "pixelgym/envs/space.h"
#include "pixelgym/envs/value.h"
#include "pixelgym/trainer/settings_declaration.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::ppo {

/// The shared torch layer's observation tensors and random shift, by the names PPO's code and
/// tests use (examples/trainer/torch_common/).
using trainer::array_tensor;
using trainer::observation_tensors;
using trainer::ObservationTensors;
using trainer::random_shift;
using trainer::select_rows;
using trainer::torch_dtype;

/// The CNN that encodes each image key.
enum class CnnArchitecture : std::uint8_t {
  /// Mnih et al. 2015 ("Nature"): conv 32 8x8/4, conv 64 4x4/2, conv 64 3x3/1, linear.
  kNature,
  /// Mnih et al. 2013 (NIPS DQN): conv 16 8x8/4, conv 32 4x4/2, linear (costs:
  /// docs/design-notes.md, "The CNNs").
  kSmall,
  /// Three conv 32 3x3/2 (the first layer of DrQ's encoder, repeated): no pixel is skipped, so
  /// positions of thin things (a pole's tip) survive to the linear layer finer than in the small
  /// CNN (7x7 cells at 64x64 where every input pixel was seen, against 6x6 after 8x8/4 strides).
  kFine,
  /// The fine CNN with a last convolution of stride 1: 13x13 cells at 64x64 (a 5408-wide linear
  /// layer).
  kFiner,
};
/// "nature", "small", "fine", "finer".
const char* to_string(CnnArchitecture architecture);
/// The inverse of to_string. Throws std::invalid_argument listing the names.
CnnArchitecture parse_cnn_architecture(const std::string& name);

/// The network's shape and the observation normalization it applies.
struct PolicyConfig {
  CnnArchitecture cnn = CnnArchitecture::kSmall;
  /// Width of the linear layer closing each CNN (ReLU).
  std::int64_t cnn_features = 256;
  /// Hidden layer widths of the MLP over the concatenated vector keys (tanh); empty: the vector
  /// keys go to the trunk as they are (normalized).
  std::vector<std::int64_t> mlp_hidden = {64, 64};
  /// Width of the trunk layer over the fused features (ReLU); 0: the heads read the fused
  /// features directly.
  std::int64_t trunk_hidden = 256;
  /// The Gaussian head's log standard deviation at initialization (a parameter of its own,
  /// independent of the observation). Unused for Discrete actions.
  double initial_log_std = 0.0;
  /// Give the value head an encoder of its own (CNNs, MLP and trunk as the policy's, with their
  /// own weights) instead of sharing the policy's. Doubles the network's cost.
  bool separate_value_network = false;
  /// Normalize the vector (state) keys with running statistics (see Policy); images are always
  /// scaled to [0, 1] instead.
  bool normalize_observations = true;
  /// Normalized vector inputs are clamped to [-observation_clip, observation_clip] (> 0).
  double observation_clip = 10.0;

  /// Throws std::invalid_argument naming the field and the value when a field is out of range.
  void validate() const;
};

/// The CNNs' names, for the settings' declarations.
const trainer::ChoiceNames<CnnArchitecture>& cnn_names();

/// PolicyConfig's settings, declared once (pixelgym/trainer/settings_declaration.h): its JSON
/// form (config.json's "policy"), its ranges and `train --list-settings` come from here.
template <typename Config, typename Visit>
std::enable_if_t<std::is_same_v<std::remove_const_t<Config>, PolicyConfig>> declare_settings(
    Config& c, Visit& visit) {
  visit.choice("cnn", c.cnn, cnn_names(),
               "the CNN over each image key: nature (Mnih et al. 2015), small (NIPS DQN), fine "
               "(three 3x3/2 convolutions of 32) or finer (the last of stride 1)");
  visit.count("cnn_features", c.cnn_features, 1, "width of the linear layer closing each CNN");
  visit.counts("mlp_hidden", c.mlp_hidden, 1,
               "hidden widths of the MLP over the vector keys ([]: they go to the trunk as they "
               "are)");
  visit.count("trunk_hidden", c.trunk_hidden, 0,
              "width of the trunk layer over the fused features (0: the heads read them)");
  visit.number("initial_log_std", c.initial_log_std, -20.0, 20.0,
               "the Gaussian head's log standard deviation at the start (Box actions)");
  visit.flag("separate_value_network", c.separate_value_network,
             "give the value head an encoder of its own (doubles the network's cost)");
  visit.flag("normalize_observations", c.normalize_observations,
             "normalize the vector keys with running statistics (images are scaled to [0, 1])");
  visit.positive("observation_clip", c.observation_clip,
                 "normalized vector inputs are clamped to +-observation_clip");
}

/// How an image key is laid out; the network sees every layout as (C, H, W) with the frames of
/// a stack (oldest first) concatenated on the channel axis.
enum class ImageLayout : std::uint8_t {
  kHW,          // (H, W): one channel
  kHWC,         // (H, W, C), also FrameStackObservation's channels_last (H, W, C k)
  kCHW,         // (C, H, W), also ChannelFirstObservation, channels_first stacks (k C, H, W)
                // and new_axis stacks of (H, W) frames (k, H, W)
  kStackedHWC,  // (k, H, W, C): FrameStackObservation's new_axis stack of (H, W, C) frames
  kStackedCHW,  // (k, C, H, W): a new_axis stack of (C, H, W) frames
};

/// One key of the observation as the policy reads it.
struct PolicyInput {
  std::string key;  // "" for a bare Box observation
  bool image = false;
  Shape shape;  // one env's
  DType dtype = DType::kFloat32;
  // Images: the layout and the (C, H, W) the encoder sees.
  ImageLayout layout = ImageLayout::kCHW;
  std::int64_t channels = 0;
  std::int64_t height = 0;
  std::int64_t width = 0;
};

/// What `act` returns for a batch of B observations.
struct ActResult {
  /// The sampled (or, deterministic, most likely) action as the policy scores it: Discrete:
  /// int64 (B,) indices in [0, n); Box: float32 (B, *shape), unclipped. What RolloutStorage keeps
  /// and `evaluate` takes back.
  torch::Tensor action;
  /// The action to send to the env: Discrete: int64 (B,) with the space's start added; Box:
  /// `action` clipped into the Box's bounds (see Policy). Lies in the action space.
  torch::Tensor env_action;
  /// log pi(action | obs), float32 (B,).
  torch::Tensor log_prob;
  /// V(obs), float32 (B,).
  torch::Tensor value;

  /// Box: how many elements of `action` lie outside the bounds (sent to the env clipped);
  /// Discrete: 0. Over all the elements, near 1 means bang-bang control at the bounds.
  std::int64_t clipped_elements() const;
};

/// What `evaluate` returns for B observations and actions.
struct Evaluation {
  torch::Tensor log_prob;  // float32 (B,)
  torch::Tensor entropy;   // float32 (B,)
  torch::Tensor value;     // float32 (B,)
};

/// An actor-critic network built from one env's observation and action spaces (a vector env's
/// single_observation_space / single_action_space).
///
/// Inputs. The observation is a bare Box or a spaces::Dict of Boxes. A uint8 Box of rank 2, 3 or
/// 4 is an image: rank 2 is (H, W); rank 3 is (H, W, C) when its last extent is no larger than
/// its first, else (C, H, W); rank 4 is a stack of such frames on a new leading axis (k, H, W, C)
/// or (k, C, H, W) (the layouts of the image wrappers: ResizeObservation, GrayscaleObservation,
/// ChannelFirstObservation, FrameStackObservation in each layout). Each image key gets a CNN of
/// its own; its uint8 input is scaled to [0, 1] inside the network. Every other Box (any rank,
/// any dtype) is a vector key: flattened, converted to float32, normalized (see below), and all
/// vector keys are concatenated into one MLP. The encoders' outputs are concatenated (key
/// order) into the trunk. The action and value heads read the trunk; with
/// config.separate_value_network the value head reads a second copy of the CNNs, MLP and trunk
/// (its parameters named with a "value_" prefix) and nothing of the value's loss reaches the
/// policy's layers.
///
/// Observation normalization (config.normalize_observations): each vector key is standardized
/// with running statistics (wrappers::RunningStatistics: mean 0, var 1, count 1e-4 at first),
/// (x - mean) / sqrt(var + 1e-8) clamped to +-observation_clip. The statistics change only
/// through update_observation_statistics: the trainer merges a rollout's observations after the
/// update that used it, so that the observations of a rollout are normalized alike when acting
/// and when learning (the probability ratio starts at exactly 1). They are buffers of this
/// module (saved with its state by torch::save).
///
/// Actions. Discrete(n, start): a categorical head of n logits. Box (float, bounded or not): a
/// Gaussian with a state-dependent mean and a state-independent log standard deviation (a
/// parameter vector), one independent Normal per element. The Gaussian's sample is **clipped**
/// into the Box's bounds when sent to the env, not squashed by tanh: the log-probability and
/// entropy are those of the Normal itself (exact, cheap, no Jacobian correction and no atanh of
/// a boundary action), the mean can sit on a bound, and an unbounded Box needs nothing special.
/// The price is a small bias where much of the probability mass lies beyond a bound (every
/// sample there acts as the bound); this is what Stable-Baselines3's and CleanRL's PPO do, and
/// is fine for the pixel tasks' [-1, 1] torques.
///
/// Initialization (CleanRL's): orthogonal weights, gain sqrt(2) for hidden layers, 0.01 for the
/// action head, 1 for the value head; zero biases. It draws from torch's default generator:
/// call torch::manual_seed first for reproducible weights.
///
/// Throws std::invalid_argument (at construction) for an observation space that is not a Box or
/// a Dict of Boxes, an image smaller than the CNN's receptive field, a bool Box, and an action
/// space that is neither Discrete nor a float Box, naming the key and the space.
class Policy : public torch::nn::Module {
 public:
  Policy(const Space& observation_space, const Space& action_space, PolicyConfig config = {});

  /// Samples actions for a batch (or takes the mode: the argmax, or the Gaussian mean, when
  /// `deterministic`), drawing from `generator` (torch's default one when absent).
  ActResult act(const ObservationTensors& obs, bool deterministic,
                std::optional<at::Generator> generator = std::nullopt);
  /// Log-probabilities of `actions` (as ActResult::action) under the current policy, the
  /// policy's entropy, and V(obs). `shifts`, when defined, is an int64 (B, 2) tensor of random
  /// shifts by up to 2 `shift_pad` pixels (see random_shift) applied to every image key first.
  Evaluation evaluate(const ObservationTensors& obs, const torch::Tensor& actions,
                      const torch::Tensor& shifts = {}, std::int64_t shift_pad = 4);
  /// V(obs), float32 (B,).
  torch::Tensor value(const ObservationTensors& obs);
  /// `action` as the env takes it (see ActResult::env_action).
  torch::Tensor env_action(const torch::Tensor& action) const;

  /// Merges the vector keys of `obs` (B rows) into their running statistics as one batch
  /// (RunningStatistics::update_batch). Does nothing when normalization is off or there is no
  /// vector key.
  void update_observation_statistics(const ObservationTensors& obs);
  /// The running statistics of vector key `key`. Throws std::out_of_range when `key` is not a
  /// normalized vector key.
  wrappers::RunningStatistics observation_statistics(const std::string& key) const;
  /// Replaces them. Throws std::out_of_range as above, std::invalid_argument for statistics of
  /// the wrong size or invalid (RunningStatistics::invalid_reason).
  void set_observation_statistics(const std::string& key,
                                  const wrappers::RunningStatistics& statistics);

  const std::vector<PolicyInput>& inputs() const { return inputs_; }
  const PolicyConfig& config() const { return config_; }
  /// True for a Discrete action space.
  bool discrete() const { return discrete_; }
  /// Discrete: n; Box: the number of elements.
  std::int64_t action_size() const { return action_size_; }
  /// One env's action shape as ActResult::action has it (() for Discrete).
  const Shape& action_shape() const { return action_shape_; }
  /// The Gaussian's log standard deviation parameter (Box actions; undefined for Discrete).
  const torch::Tensor& log_std() const { return log_std_; }

 private:
  struct Heads {
    torch::Tensor logits_or_mean;  // (B, action_size)
    torch::Tensor value;           // (B,)
  };
  // The layers from the inputs to the features a head reads.
  struct Encoder {
    std::vector<torch::nn::Sequential> cnns;  // one per image input, in input order
    torch::nn::Sequential mlp{nullptr};       // null when there is no vector input
    torch::nn::Sequential trunk{nullptr};     // null when trunk_hidden == 0
  };
  // Builds an encoder and registers its modules as prefix + "cnn0", "cnn1", ..., "mlp", "trunk";
  // returns it with the width of its output.
  std::pair<Encoder, std::int64_t> make_encoder(const std::string& prefix);
  torch::Tensor encode(Encoder& encoder, const std::vector<torch::Tensor>& images,
                       const torch::Tensor& vectors);
  Heads forward(const ObservationTensors& obs, const torch::Tensor& shifts, std::int64_t pad);
  torch::Tensor image_input(const PolicyInput& input, const torch::Tensor& batch) const;
  torch::Tensor vector_input(std::size_t vector_index, const torch::Tensor& batch) const;

  PolicyConfig config_;
  std::vector<PolicyInput> inputs_;
  std::vector<std::size_t> vector_inputs_;  // indices into inputs_
  std::vector<std::int64_t> vector_sizes_;
  Encoder encoder_;
  std::optional<Encoder> value_encoder_;  // with separate_value_network
  torch::nn::Linear action_head_{nullptr};
  torch::nn::Linear value_head_{nullptr};
  torch::Tensor log_std_;
  // Per vector input: running statistics as float64 buffers (mean, var: (size,); count: ()).
  std::vector<torch::Tensor> statistics_mean_;
  std::vector<torch::Tensor> statistics_var_;
  std::vector<torch::Tensor> statistics_count_;
  bool discrete_ = false;
  std::int64_t action_size_ = 0;
  std::int64_t action_start_ = 0;
  Shape action_shape_;
  torch::Tensor action_low_;   // Box: float32 (action_size,), -inf where unbounded
  torch::Tensor action_high_;  // Box: float32 (action_size,), +inf where unbounded
};

}  // namespace pixelgym::ppo
