#include "examples/trainer/drqv2/drqv2_algorithm.h"

#include <utility>

namespace pixelgym::drqv2 {

DrqV2StepLearner::DrqV2StepLearner(const vector::VectorEnv& env, const DrqV2Config& config)
    : OffPolicyStepLearnerWith(env, config, config.batch_size, {"drqv2", "rng_noise"}) {}

torch::Tensor DrqV2StepLearner::explore(const trainer::ObservationTensors& obs,
                                        std::int64_t env_steps, at::Generator& exploration) {
  return learner().agent().act(obs, false, learner().config().noise_std(env_steps), &exploration);
}

trainer::UpdateSummary DrqV2StepLearner::update(const ReplayBatch& batch, std::int64_t env_steps) {
  const UpdateStats update = learner().update(batch, env_steps, augmentation(), update_generator());
  return {update.critic_loss, update.actor_loss, update.q_mean, update.target_mean};
}

std::map<std::string, double> DrqV2StepLearner::update_metrics(std::int64_t /*updates*/,
                                                               std::int64_t /*actor_updates*/,
                                                               std::int64_t env_steps) {
  return {{"noise_std", learner().config().noise_std(env_steps)}};
}

std::vector<std::string> DrqV2StepLearner::update_metric_names() const { return {"noise_std"}; }

std::vector<trainer::NamedOptimizer> DrqV2StepLearner::optimizers() {
  return {{"encoder_optimizer", learner().encoder_optimizer()},
          {"actor_optimizer", &learner().actor_optimizer()},
          {"critic_optimizer", &learner().critic_optimizer()}};
}

}  // namespace pixelgym::drqv2
