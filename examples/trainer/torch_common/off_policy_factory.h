// The AlgorithmFactory of an off-policy algorithm, written once: the config parsed and checked,
// one process, a SteppedAlgorithm over the algorithm's OffPolicyStepLearner, and for evaluation
// the agent loaded from a checkpoint behind an OffPolicyActor.
#pragma once

#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>

#include "examples/trainer/torch_common/input_layout.h"
#include "examples/trainer/torch_common/off_policy_agent.h"
#include "examples/trainer/torch_common/off_policy_settings.h"
#include "examples/trainer/torch_common/torch_state.h"
#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/stepped_algorithm.h"

namespace pixelgym::trainer {

/// `Config` derives from OffPolicySettings and has from_json / to_json (and validate());
/// `Learner` is an OffPolicyStepLearner made from (const vector::VectorEnv&, Config); `Agent` an
/// OffPolicyAgent made from (InputLayout, const Config&), saved as the checkpoint's "agent".
template <typename Config, typename Learner, typename Agent>
class OffPolicyAlgorithmFactory : public AlgorithmFactory {
 public:
  /// `algorithm` as --algo names it ("drq"); `config_name` in the config's errors ("DrqConfig").
  OffPolicyAlgorithmFactory(std::string algorithm, std::string config_name)
      : algorithm_(std::move(algorithm)), config_name_(std::move(config_name)) {}

  std::string name() const override { return algorithm_; }
  nlohmann::json parse_config(const std::string& text) const override {
    return parse_off_policy_config<Config>(text, config_name_.c_str());
  }
  /// trainer::set_torch_threads.
  int set_threads(int requested) const override { return set_torch_threads(requested); }
  /// Throws std::invalid_argument for a communicator of several ranks: an off-policy learner
  /// trains in one process (its replay buffer and updates are not shared across ranks).
  std::unique_ptr<Algorithm> make(EnvLoop& loop, const nlohmann::json& config,
                                  Communicator& communicator) const override {
    require_one_process(communicator, algorithm_.c_str());
    Config parsed;
    from_json(config, parsed);
    return std::make_unique<SteppedAlgorithm>(loop, SteppedSettings{parsed.iteration_env_steps},
                                              std::make_unique<Learner>(loop.env(), parsed));
  }
  /// An Agent of the config for these spaces with the checkpoint's "agent", in eval mode.
  std::unique_ptr<Actor> load_actor(const Space& observation_space, const Space& action_space,
                                    const nlohmann::json& config,
                                    const LoadedCheckpoint& checkpoint) const override {
    Config parsed;
    from_json(config, parsed);
    auto agent =
        std::make_shared<Agent>(input_layout(observation_space, action_space, parsed.frame_stack,
                                             algorithm_, "the run's env"),
                                parsed);
    load_blob(checkpoint, "agent", agent);
    agent->eval();
    return std::make_unique<OffPolicyActor>(std::move(agent), parsed.seed + 4);
  }
  /// The config's declared settings.
  std::vector<SettingDescription> settings() const override { return describe_settings(Config{}); }

 private:
  std::string algorithm_;
  std::string config_name_;
};

}  // namespace pixelgym::trainer
