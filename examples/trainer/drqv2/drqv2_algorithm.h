// DrQ-v2 as the run's learner (pixelgym/trainer/stepped_algorithm.h): the shared off-policy step
// learner (torch_common/off_policy_step_learner.h) updating a DrQ-v2 Learner; and the factory
// that builds it from config.json's "drqv2".
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "examples/trainer/drqv2/drqv2.h"
#include "examples/trainer/torch_common/off_policy_factory.h"
#include "examples/trainer/torch_common/off_policy_step_learner.h"

namespace pixelgym::drqv2 {

/// DrQ-v2's side of the run's env loop: an OffPolicyStepLearner whose exploring actions are the
/// policy's with the scheduled noise and whose update is Learner::update (the augmentation
/// generator seeded seed + 1, the update's noise from seed + 3: blob "rng_noise"). The
/// evaluation actor takes the mean action (deterministic) or adds noise of std noise_end.
///
/// Checkpoint: the shared learner's, with "agent" (encoder, actor, critic, target critic) and
/// the optimizers "encoder_optimizer" (when there is an image), "actor_optimizer" and
/// "critic_optimizer"; meta member "drqv2".
///
/// Its metrics (progress.csv's columns after the run's; runs before metrics were named by their
/// algorithm also have PPO's five loss columns, left empty): critic_loss, actor_loss, q_mean,
/// target_mean (means over the iteration's updates), noise_std, then the shared replay metrics.
class DrqV2StepLearner final : public trainer::OffPolicyStepLearnerWith<Learner> {
 public:
  /// Throws std::invalid_argument for a config that fails validate(), an env that does not
  /// autoreset in SameStep mode or has another num_envs, and as input_layout for the spaces.
  DrqV2StepLearner(const vector::VectorEnv& env, const DrqV2Config& config);

 private:
  torch::Tensor explore(const trainer::ObservationTensors& obs, std::int64_t env_steps,
                        at::Generator& exploration) override;
  trainer::UpdateSummary update(const ReplayBatch& batch, std::int64_t env_steps) override;
  std::map<std::string, double> update_metrics(std::int64_t updates, std::int64_t actor_updates,
                                               std::int64_t env_steps) override;
  std::vector<std::string> update_metric_names() const override;
  std::vector<trainer::NamedOptimizer> optimizers() override;
};

/// DrQ-v2's AlgorithmFactory: name "drqv2", the config a DrqV2Config (to_json / from_json).
class DrqV2AlgorithmFactory final
    : public trainer::OffPolicyAlgorithmFactory<DrqV2Config, DrqV2StepLearner, Agent> {
 public:
  DrqV2AlgorithmFactory() : OffPolicyAlgorithmFactory("drqv2", "DrqV2Config") {}
};

}  // namespace pixelgym::drqv2
