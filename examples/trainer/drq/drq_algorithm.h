// DrQ as the run's learner (pixelgym/trainer/stepped_algorithm.h): the shared off-policy step
// learner (torch_common/off_policy_step_learner.h) updating a DrQ Learner; and the factory that
// builds it from config.json's "drq".
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "examples/trainer/drq/drq.h"
#include "examples/trainer/torch_common/off_policy_factory.h"
#include "examples/trainer/torch_common/off_policy_step_learner.h"
#include "pixelgym/trainer/progress_csv.h"

namespace pixelgym::drq {

/// DrQ's side of the run's env loop: an OffPolicyStepLearner whose exploring actions are samples
/// of the policy and whose update is Learner::update (the augmentation generator seeded
/// seed + 1, the policy's samples in the update from seed + 3: blob "rng_sampling"). The
/// evaluation actor takes the tanh of the Gaussian's mean (deterministic) or a sample.
///
/// Checkpoint: the shared learner's, with "agent" (encoder, heads, actor, critics, target
/// critics, log_alpha) and the optimizers "actor_optimizer", "critic_optimizer" (with the
/// encoder) and "alpha_optimizer"; meta member "drq" (its gradient_updates also restores the
/// Learner's count, that spaces the actor's and the target's updates).
///
/// Its metrics (progress.csv's columns after the run's): critic_loss, actor_loss, q_mean,
/// target_mean (means over the iteration's updates; actor_loss over its actor updates), alpha
/// (the temperature after the last update), policy_entropy (minus the mean log-probability of
/// the actor updates' samples), then the shared replay metrics.
class DrqStepLearner final : public trainer::OffPolicyStepLearnerWith<Learner> {
 public:
  /// Throws std::invalid_argument for a config that fails validate(), an env that does not
  /// autoreset in SameStep mode or has another num_envs, and as input_layout for the spaces.
  DrqStepLearner(const vector::VectorEnv& env, const DrqConfig& config);

 private:
  trainer::UpdateSummary update(const ReplayBatch& batch, std::int64_t env_steps) override;
  std::map<std::string, double> update_metrics(std::int64_t updates, std::int64_t actor_updates,
                                               std::int64_t env_steps) override;
  std::vector<std::string> update_metric_names() const override;
  std::vector<trainer::NamedOptimizer> optimizers() override;
  void restored_updates(std::int64_t updates) override { learner().set_updates(updates); }

  double alpha_ = trainer::ProgressRow::kNone;  // after the iteration's last update
  double entropy_sum_ = 0.0;                    // over its actor updates
};

/// DrQ's AlgorithmFactory: name "drq", the config a DrqConfig (to_json / from_json).
class DrqAlgorithmFactory final
    : public trainer::OffPolicyAlgorithmFactory<DrqConfig, DrqStepLearner, Agent> {
 public:
  DrqAlgorithmFactory() : OffPolicyAlgorithmFactory("drq", "DrqConfig") {}
};

}  // namespace pixelgym::drq
