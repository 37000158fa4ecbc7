// The settings that DrQ and DrQ-v2 share — the run's length, the replay buffer, the update's
// common knobs and the encoder — declared once with their checks and their JSON form. Each
// algorithm's config derives from OffPolicySettings and adds its own members.
#pragma once

#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "examples/trainer/torch_common/conv_encoder.h"
#include "pixelgym/envs/vector/vector_env.h"
#include "pixelgym/trainer/communicator.h"
#include "pixelgym/trainer/config_members.h"
#include "pixelgym/trainer/settings_declaration.h"

namespace pixelgym::trainer {

/// Counts of steps are env steps (all envs together): with action_repeat K each is K control
/// steps.
struct OffPolicySettings {
  /// Seeds torch (weights), the replay sampling, the exploration, the augmentation and the envs
  /// (env i resets with seed + i).
  std::uint64_t seed = 0;
  /// Envs stepped together, and the run's length.
  std::int64_t num_envs = 1;
  std::int64_t total_env_steps = 100'000;
  /// Env steps per iteration (a progress.csv row; checkpoints come every checkpoint_every
  /// iterations). A multiple of num_envs.
  std::int64_t iteration_env_steps = 500;
  /// Frames in each observation's stack (the env must give them: --wrap frame_stack=K, the
  /// new_axis layout; 1: single frames).
  std::int64_t frame_stack = 3;
  /// Replay buffer slots (one per env step, plus one per episode for its last observation).
  std::int64_t replay_capacity = 100'000;
  std::int64_t batch_size = 128;
  /// Steps of the return before bootstrapping.
  std::int64_t n_step = 3;
  double gamma = 0.99;
  /// Adam's learning rate of every network the algorithm trains.
  double learning_rate = 1e-3;
  /// The target critic moves this fraction towards the critic at each of its updates.
  double critic_tau = 0.01;
  /// The encoder (images only), the width of each network's head (Linear, LayerNorm, tanh over
  /// the encoder's features) and of the MLPs' hidden layers.
  EncoderArchitecture encoder = EncoderArchitecture::kMrq;
  std::int64_t feature_dim = 50;
  std::int64_t hidden_dim = 256;
  /// Env steps of uniformly random actions before the policy acts (and learning starts).
  std::int64_t seed_env_steps = 1000;
  /// Updates per env step (all envs together): 1 updates after every step of one env, 0.5
  /// after every second; fractions carry over.
  double updates_per_env_step = 1.0;
  /// Random shifts of the images during updates, by up to shift_pad pixels (0: none).
  std::int64_t shift_pad = 4;
  /// Run the encoder's convolutions under bfloat16 autocast where the CPU has AVX512-BF16 (or
  /// AMX); elsewhere it stays float32.
  bool bfloat16 = true;
  /// Lay the encoder's images out channels-last (oneDNN's preferred layout: its first
  /// convolution ran 8x faster so on this project's 2-core AVX2 machine).
  bool channels_last = true;
};

/// The encoders' names, for the settings' declarations.
inline const ChoiceNames<EncoderArchitecture>& encoder_names() {
  static const ChoiceNames<EncoderArchitecture> names = {{"drqv2", EncoderArchitecture::kDrqV2},
                                                         {"mrq", EncoderArchitecture::kMrq},
                                                         {"fine", EncoderArchitecture::kFine}};
  return names;
}

/// The shared settings, declared once (pixelgym/trainer/settings_declaration.h): DrQ's and
/// DrQ-v2's declare_settings begin with this. `Settings` is OffPolicySettings (or a config
/// derived from it), const or not.
template <typename Settings, typename Visit>
void declare_off_policy_settings(Settings& s, Visit& visit) {
  visit.integer("seed", s.seed, std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max(),
                "seeds the weights, the replay sampling, the exploration, the augmentation and "
                "the envs (env i resets with seed + i); --seed sets it");
  visit.count("num_envs", s.num_envs, 1, "envs stepped together; --num-envs sets it");
  visit.count("total_env_steps", s.total_env_steps, 1,
              "the run's length in env steps, all envs together (each is action_repeat control "
              "steps); --steps sets it");
  visit.count("iteration_env_steps", s.iteration_env_steps, 1,
              "env steps per iteration: a progress.csv row, and the unit of --checkpoint-every; "
              "a multiple of num_envs");
  visit.count("frame_stack", s.frame_stack, 1,
              "frames in each observation's stack: the env must give them (--wrap "
              "frame_stack=K); 1 for single frames");
  visit.count("replay_capacity", s.replay_capacity, 1,
              "replay buffer slots: one per env step, plus one per episode for its last "
              "observation");
  visit.count("batch_size", s.batch_size, 1, "transitions sampled for each update");
  visit.count("n_step", s.n_step, 1, "steps of the return before bootstrapping");
  visit.number("gamma", s.gamma, 0.0, 1.0, "the discount of future rewards per env step");
  visit.positive("learning_rate", s.learning_rate, "Adam's learning rate, for every network");
  visit.number("critic_tau", s.critic_tau, 0.0, 1.0,
               "the target critic moves this fraction towards the critic at each of its updates");
  visit.choice("encoder", s.encoder, encoder_names(),
               "the convolutions over images: four 3x3 of 32 channels, strides 2, 2, 2, 1 "
               "(mrq), 2, 2, 1, 1 (fine) or 2, 1, 1, 1 (drqv2)");
  visit.count("feature_dim", s.feature_dim, 1,
              "width of the head over the encoder's output (Linear, LayerNorm, tanh)");
  visit.count("hidden_dim", s.hidden_dim, 1, "width of the MLPs' hidden layers");
  visit.count("seed_env_steps", s.seed_env_steps, 0,
              "env steps of uniformly random actions before the policy acts and learning starts");
  visit.number("updates_per_env_step", s.updates_per_env_step, 0.0, 64.0,
               "updates per env step, all envs together (0.5: one every second step; fractions "
               "carry over)");
  visit.integer("shift_pad", s.shift_pad, std::int64_t{0}, std::int64_t{65536},
                "random shifts of the images in updates, by up to this many pixels (0: none)");
  visit.flag("bfloat16", s.bfloat16,
             "run the encoder under bfloat16 autocast where the CPU has AVX512-BF16 or AMX "
             "(elsewhere it stays float32)");
  visit.flag("channels_last", s.channels_last, "lay the encoder's images out channels-last");
}

/// The checks between shared members that their declared ranges cannot say (iteration_env_steps
/// a multiple of num_envs, a replay buffer that holds a stack and an n-step return of every
/// env); `checks` names the config in its errors.
void validate_off_policy_settings(const OffPolicySettings& settings, const ConfigChecks& checks);

/// `config` once config.validate() has passed (it throws naming the setting out of range), for a
/// constructor's initializer list.
template <typename Config>
const Config& validated(const Config& config) {
  config.validate();
  return config;
}

/// An AlgorithmFactory::parse_config for a config type of from_json / to_json: the JSON text
/// read (a parse error as "{config_name} JSON: ..."), completed with the defaults and checked,
/// and written back with every member.
template <typename Config>
nlohmann::json parse_off_policy_config(const std::string& text, const char* config_name) {
  nlohmann::json parsed;
  try {
    parsed = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& error) {
    throw std::invalid_argument(std::string(config_name) + " JSON: " + error.what());
  }
  Config config;
  from_json(parsed, config);
  nlohmann::json out;
  to_json(out, config);
  return out;
}

/// Throws std::invalid_argument when `communicator` has several ranks: "train --algo
/// {algorithm} runs in one process; ..." (data-parallel training is PPO's).
void require_one_process(const Communicator& communicator, const char* algorithm);

/// Checks that a learner of `settings` can train on `env`: SameStep autoreset, num_envs as the
/// settings', and the memory of a replay buffer and networks of these settings, with batches of
/// `batch_rows` images (trainer::require_memory). Errors begin "{algorithm}: ".
void require_off_policy_env(const OffPolicySettings& settings, const vector::VectorEnv& env,
                            const char* algorithm, std::int64_t batch_rows);

}  // namespace pixelgym::trainer
