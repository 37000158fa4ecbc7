#include "examples/trainer/drq/drq_algorithm.h"

#include <cmath>
#include <utility>

namespace pixelgym::drq {

DrqStepLearner::DrqStepLearner(const vector::VectorEnv& env, const DrqConfig& config)
    : OffPolicyStepLearnerWith(env, config, config.batch_size * config.augmented_copies,
                               {"drq", "rng_sampling"}) {}

trainer::UpdateSummary DrqStepLearner::update(const ReplayBatch& batch,
                                              std::int64_t /*env_steps*/) {
  const UpdateStats update = learner().update(batch, augmentation(), update_generator());
  if (!std::isnan(update.actor_loss)) entropy_sum_ += update.entropy;
  alpha_ = update.alpha;
  return {update.critic_loss, update.actor_loss, update.q_mean, update.target_mean};
}

std::map<std::string, double> DrqStepLearner::update_metrics(std::int64_t /*updates*/,
                                                             std::int64_t actor_updates,
                                                             std::int64_t /*env_steps*/) {
  return {
      {"alpha", std::exchange(alpha_, trainer::ProgressRow::kNone)},
      {"policy_entropy", trainer::mean_or_none(std::exchange(entropy_sum_, 0.0), actor_updates)}};
}

std::vector<std::string> DrqStepLearner::update_metric_names() const {
  return {"alpha", "policy_entropy"};
}

std::vector<trainer::NamedOptimizer> DrqStepLearner::optimizers() {
  return {{"actor_optimizer", &learner().actor_optimizer()},
          {"critic_optimizer", &learner().critic_optimizer()},
          {"alpha_optimizer", &learner().alpha_optimizer()}};
}

}  // namespace pixelgym::drq
