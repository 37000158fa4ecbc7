#include "examples/trainer/torch_common/off_policy_settings.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/off_policy_networks.h"
#include "pixelgym/trainer/memory_budget.h"

namespace pixelgym::trainer {

void validate_off_policy_settings(const OffPolicySettings& settings, const ConfigChecks& checks) {
  if (settings.iteration_env_steps % settings.num_envs != 0) {
    checks.fail("iteration_env_steps must be a multiple of num_envs (" +
                std::to_string(settings.num_envs) + "), got " +
                std::to_string(settings.iteration_env_steps));
  }
  checks.at_least("replay_capacity", settings.replay_capacity,
                  settings.num_envs * (settings.n_step + settings.frame_stack + 2));
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
