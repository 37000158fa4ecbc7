// A policy kept as a file: an MLP over an env's vector observations, run without LibTorch. Tests
// use one to show a task solvable by a trained policy (the walker's stand and walk, trained from
// state by `pixelgym train --algo drq --set obs_mode=state`), and a user's CI can do the same.
//
//   pixelgym export runs/walker --out walker_walk.policy.json    # a drq run trained from state
//
//   const testing::MlpPolicy policy = testing::MlpPolicy::load("walker_walk.policy.json");
//   std::unique_ptr<Env> env = make(policy.env_id(), policy.env_kwargs());
//   Value obs = env->reset(seed).obs;
//   StepResult step = env->step(Value(policy.act(obs)));
//
// The file is JSON:
//   "format": "pixelgym mlp policy", "version": 1,
//   "env_id", "env_kwargs" (the run's, to make the env it was trained on), "source" (the run's
//   checkpoint and its env steps, for people),
//   "inputs": [{"key", "size"}, ...]: the observation's float keys, read in this order and laid
//     end to end (each flattened, row-major) as the first layer's input,
//   "layers": [{"inputs", "outputs", "activation" ("relu" or "none"), "weight", "bias"}, ...]:
//     y = activation(W x + b), W row-major (outputs, inputs); "weight" and "bias" are the float32
//     values' little-endian bytes in base64,
//   "action": {"size", "low", "high"}: the action is tanh of the last layer's first `size`
//     outputs (the squashed Gaussian's mean; the rest, its spread, is not used), scaled from
//     [-1, 1] to [low, high].
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/envs/array.h"
#include "pixelgym/envs/params.h"
#include "pixelgym/envs/value.h"

namespace pixelgym::testing {

class MlpPolicy {
 public:
  /// Reads a policy file. Throws std::runtime_error "MLP policy PATH: ..." naming what was
  /// expected and what the file has (not JSON, another format or version, a missing member,
  /// a key given twice, layers whose sizes do not chain, weights of the wrong length, a size over
  /// 2^24, bounds that are not finite float32 or whose low is above their high).
  static MlpPolicy load(const std::string& path);
  /// The same from the file's text; `path` names it in the errors.
  static MlpPolicy parse(const std::string& text, const std::string& path);

  /// The env it was trained on, and the kwargs to make it with.
  const std::string& env_id() const { return env_id_; }
  const Params& env_kwargs() const { return env_kwargs_; }
  /// Elements of the action.
  std::int64_t action_size() const { return action_size_; }
  /// The observation keys it reads, in order, with their sizes (elements).
  std::vector<std::pair<std::string, std::int64_t>> inputs() const {
    std::vector<std::pair<std::string, std::int64_t>> result;
    for (const Input& input : inputs_) result.emplace_back(input.key, input.size);
    return result;
  }

  /// The deterministic action (float32, shape (action_size,)) for one observation: a Dict holding
  /// each input key as a floating array of its size. Throws std::invalid_argument naming a
  /// missing key, a key of another size or dtype, or an observation that is not a Dict;
  /// std::runtime_error when the layers' sums overflow to NaN.
  Array act(const Value& observation) const;

 private:
  struct Input {
    std::string key;
    std::int64_t size = 0;
  };
  struct Layer {
    std::int64_t inputs = 0;
    std::int64_t outputs = 0;
    bool relu = false;
    std::vector<float> weight;  // row-major (outputs, inputs)
    std::vector<float> bias;
  };

  std::string path_;
  std::string env_id_;
  Params env_kwargs_;
  std::vector<Input> inputs_;
  std::vector<Layer> layers_;
  std::int64_t action_size_ = 0;
  std::vector<float> low_, high_;
};

/// The base64 text of `bytes` (RFC 4648, with padding), and the bytes of such a text (throws
/// std::invalid_argument naming the first character that is not base64). Used for the weights.
std::string encode_base64(const std::vector<std::uint8_t>& bytes);
std::vector<std::uint8_t> decode_base64(const std::string& text);

}  // namespace pixelgym::testing
