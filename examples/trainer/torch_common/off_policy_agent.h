// What an off-policy agent does the same whatever its algorithm: it reads images and vectors as
// its input layout says, runs its encoder (under bfloat16 autocast where the CPU has it), maps
// actions between [-1, 1] and the env's bounds, and acts for evaluation through OffPolicyActor.
// DrQ's and DrQ-v2's agents derive from OffPolicyAgent and add their networks.
#pragma once

#include <ATen/core/Generator.h>
#include <torch/torch.h>

#include <cstdint>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/observation_tensors.h"
#include "examples/trainer/torch_common/off_policy_settings.h"
#include "pixelgym/trainer/algorithm.h"

namespace pixelgym::trainer {

/// A batch of observations as an agent reads them: float images (B, stack C, H, W) in [0, 255]
/// (undefined: no image key) and the vector keys side by side (B, sum of sizes; undefined: none).
struct AgentInput {
  torch::Tensor images;
  torch::Tensor vectors;
};

/// The base of an off-policy agent: the input layout, the action bounds (buffers "action_low"
/// and "action_high"), the encoder (module "encoder", which the algorithm's agent registers when
/// there is an image) and the conversions around them.
class OffPolicyAgent : public torch::nn::Module {
 public:
  /// Uses settings.bfloat16 (with cpu_has_bfloat16()) and settings.channels_last.
  OffPolicyAgent(InputLayout input, const OffPolicySettings& settings);

  /// Images uint8 (B, stack * H * W * C), as the replay buffer stores them, to float
  /// (B, stack C, H, W) (channels-last in memory when settings.channels_last).
  torch::Tensor image_input(const torch::Tensor& images) const;
  /// A batch of `batch` image stacks as the buffer stores them, each shifted by its own offset of
  /// up to `pad` pixels drawn from `generator` (edges repeated; pad 0: unshifted), as
  /// image_input gives them. `scratch` holds the shifted bytes until the next call with it.
  torch::Tensor shifted_images(const std::vector<std::uint8_t>& stacks, std::int64_t batch,
                               std::int64_t pad, at::Generator& generator,
                               std::vector<std::uint8_t>& scratch) const;
  /// The encoder over float images in [0, 255] (image_input's), centred and scaled to
  /// [-0.5, 0.5], as float32; undefined when there is no image.
  torch::Tensor convolve(const torch::Tensor& images);
  /// A vector env's observations (trainer::observation_tensors) as the agent reads them.
  AgentInput observation_input(const ObservationTensors& obs) const;
  /// Actions in [-1, 1] to the env's bounds (float32), and the env's back (clamped to [-1, 1]).
  torch::Tensor env_action(const torch::Tensor& unit_actions) const;
  torch::Tensor unit_action(const torch::Tensor& env_actions) const;

  /// Actions in [-1, 1] for a vector env's observations: the policy's deterministic action when
  /// `deterministic` or `generator` is null, else an exploring one drawn from `generator` (the
  /// stochastic evaluation's). Computes no gradients.
  virtual torch::Tensor act(const ObservationTensors& obs, bool deterministic,
                            at::Generator* generator) = 0;

  /// The MLP from the concatenated vector keys to the actor's outputs, whose first action_size
  /// are the pre-tanh mean of its action (the deterministic action is their tanh), when the
  /// policy is one; null otherwise (by default).
  virtual torch::nn::Sequential policy_mlp() const { return nullptr; }

  const InputLayout& input() const { return input_; }
  /// Whether the encoder runs under bfloat16 autocast.
  bool autocast() const { return autocast_; }

  torch::nn::Sequential encoder{nullptr};

 protected:
  /// Registers `encoder` (make_conv_encoder of `architecture` over the input's stacked frames;
  /// `who` names the algorithm in its errors) when the input has an image; returns the number of
  /// features it gives, 0 when there is no image.
  std::int64_t register_encoder(EncoderArchitecture architecture, const std::string& who);

 private:
  InputLayout input_;
  bool autocast_ = false;
  bool channels_last_ = false;
  torch::Tensor low_, high_;
};

/// Validates `config`, seeds torch's default generator with config.seed (the weights are drawn
/// from it) and builds the agent.
template <typename Agent, typename Config>
std::shared_ptr<Agent> make_agent(InputLayout input, const Config& config) {
  config.validate();
  torch::manual_seed(config.seed);
  return std::make_shared<Agent>(std::move(input), config);
}

/// The parameters of `modules` in order (null modules are skipped), for one optimizer.
std::vector<torch::Tensor> parameters_of(std::initializer_list<torch::nn::Module*> modules);

/// A tensor over a vector's memory (no copy): valid while the vector is neither resized nor
/// freed.
template <typename T>
torch::Tensor view_of(const std::vector<T>& values, std::vector<std::int64_t> shape,
                      torch::ScalarType type) {
  return torch::from_blob(const_cast<T*>(values.data()), shape, torch::TensorOptions(type));
}

/// A replay batch's vector keys side by side (B, sum of sizes), viewed when there is one key;
/// undefined when there are none.
torch::Tensor batch_vectors(const std::vector<std::vector<float>>& vectors,
                            const InputLayout& input, std::int64_t batch);

/// An off-policy agent acting for evaluation: OffPolicyAgent::act with a seeded generator of its
/// own, the actions mapped to the env's bounds.
class OffPolicyActor final : public Actor {
 public:
  /// Throws std::invalid_argument for a null agent.
  OffPolicyActor(std::shared_ptr<OffPolicyAgent> agent, std::uint64_t seed);
  ActCounts act(const Value& observations, bool deterministic, Value& actions) override;
  /// The agent's policy_mlp() with its input keys and action bounds; throws
  /// std::invalid_argument when it reads images or has no such MLP.
  nlohmann::json mlp_policy() const override;

 private:
  std::shared_ptr<OffPolicyAgent> agent_;
  at::Generator generator_;
};

/// Writes actions in [-1, 1] (B, action size) into `actions` (a vector env's action batch) at
/// the env's bounds.
void write_env_actions(const OffPolicyAgent& agent, const torch::Tensor& unit_actions,
                       Value& actions);

}  // namespace pixelgym::trainer
