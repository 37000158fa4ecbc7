#include "examples/trainer/torch_common/off_policy_settings.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/off_policy_networks.h"
#include "pixelgym/trainer/memory_budget.h"

namespace pixelgym::trainer {

void validate_off_policy_settings(const OffPolicySettings& settings, const ConfigChecks& checks) {
  checks.at_least("num_envs", settings.num_envs, 1);
  checks.at_least("total_env_steps", settings.total_env_steps, 1);
  checks.at_least("iteration_env_steps", settings.iteration_env_steps, 1);
  if (settings.iteration_env_steps % settings.num_envs != 0) {
    checks.fail("iteration_env_steps must be a multiple of num_envs (" +
                std::to_string(settings.num_envs) + "), got " +
                std::to_string(settings.iteration_env_steps));
  }
  checks.at_least("frame_stack", settings.frame_stack, 1);
  checks.at_least("batch_size", settings.batch_size, 1);
  checks.at_least("n_step", settings.n_step, 1);
  checks.at_least("replay_capacity", settings.replay_capacity,
                  settings.num_envs * (settings.n_step + settings.frame_stack + 2));
  checks.in_range("gamma", settings.gamma, 0.0, 1.0);
  if (!(settings.learning_rate > 0.0 && std::isfinite(settings.learning_rate))) {
    checks.fail("learning_rate must be positive, got " + std::to_string(settings.learning_rate));
  }
  checks.in_range("critic_tau", settings.critic_tau, 0.0, 1.0);
  checks.at_least("feature_dim", settings.feature_dim, 1);
  checks.at_least("hidden_dim", settings.hidden_dim, 1);
  checks.at_least("seed_env_steps", settings.seed_env_steps, 0);
  checks.in_range("updates_per_env_step", settings.updates_per_env_step, 0.0, 64.0);
  // Any pad is well defined (past the image's size every shifted pixel repeats an edge); the
  // bound only keeps 2 pad + 1, the count of offsets drawn, far from overflowing.
  checks.in_range("shift_pad", static_cast<double>(settings.shift_pad), 0.0, 65536.0);
}

namespace {

// Calls visit(name, field) for each member but the encoder (written by its name), in one list
// for writing and reading.
template <typename Settings, typename Visit>
void visit_members(Settings& settings, Visit&& visit) {
  visit("seed", settings.seed);
  visit("num_envs", settings.num_envs);
  visit("total_env_steps", settings.total_env_steps);
  visit("iteration_env_steps", settings.iteration_env_steps);
  visit("frame_stack", settings.frame_stack);
  visit("replay_capacity", settings.replay_capacity);
  visit("batch_size", settings.batch_size);
  visit("n_step", settings.n_step);
  visit("gamma", settings.gamma);
  visit("learning_rate", settings.learning_rate);
  visit("critic_tau", settings.critic_tau);
  visit("feature_dim", settings.feature_dim);
  visit("hidden_dim", settings.hidden_dim);
  visit("seed_env_steps", settings.seed_env_steps);
  visit("updates_per_env_step", settings.updates_per_env_step);
  visit("shift_pad", settings.shift_pad);
  visit("bfloat16", settings.bfloat16);
  visit("channels_last", settings.channels_last);
}

}  // namespace

void add_off_policy_settings(nlohmann::json& json, const OffPolicySettings& settings) {
  visit_members(settings, [&json](const char* name, const auto& field) { json[name] = field; });
  json["encoder"] = to_string(settings.encoder);
}

void read_off_policy_settings(const nlohmann::json& json, OffPolicySettings& settings,
                              const char* config_name) {
  visit_members(settings, [&](const char* name, auto& field) {
    read_member(json, name, field, config_name);
  });
  std::string encoder = to_string(settings.encoder);
  read_member(json, "encoder", encoder, config_name);
  try {
    settings.encoder = parse_encoder_architecture(encoder);
  } catch (const std::invalid_argument& error) {
    throw std::invalid_argument(std::string(config_name) + ": member \"encoder\": " + error.what());
  }
}

void require_one_process(const Communicator& communicator, const char* algorithm) {
  if (communicator.world_size() > 1) {
    throw std::invalid_argument(
        std::string("train --algo ") + algorithm + " runs in one process; it was started as " +
        std::to_string(communicator.world_size()) +
        " ranks (--nproc or WORLD_SIZE). Data-parallel training is PPO's (--algo ppo)");
  }
}

void require_off_policy_env(const OffPolicySettings& settings, const vector::VectorEnv& env,
                            const char* algorithm, std::int64_t batch_rows) {
  if (env.autoreset_mode() != vector::AutoresetMode::kSameStep) {
    throw std::invalid_argument(
        std::string(algorithm) +
        ": the vector env must autoreset in SameStep mode (an episode's last observation comes "
        "from infos[\"final_obs\"]), got " +
        vector::autoreset_mode_name(env.autoreset_mode()));
  }
  if (env.num_envs() != settings.num_envs) {
    throw std::invalid_argument(std::string(algorithm) + ": config num_envs is " +
                                std::to_string(settings.num_envs) + " but the vector env has " +
                                std::to_string(env.num_envs()));
  }
  require_memory(algorithm,
                 off_policy_memory_estimate(
                     input_layout(env.single_observation_space(), env.single_action_space(),
                                  settings.frame_stack, algorithm, env.name()),
                     {settings.replay_capacity, batch_rows, settings.hidden_dim,
                      settings.feature_dim, settings.encoder}));
}

}  // namespace pixelgym::trainer
