// PPO (Schulman et al. 2017) on a vector env: the config, the rollout storage, the clipped
// update, and a Trainer that collects rollouts and updates a Policy.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <type_traits>
#include <vector>

#include "examples/trainer/ppo/policy.h"
#include "pixelgym/envs/vector/vector_env.h"
#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/communicator.h"
#include "pixelgym/trainer/env_loop.h"
#include "pixelgym/trainer/memory_budget.h"
#include "pixelgym/wrappers/return_scaling.h"
#include "pixelgym/wrappers/running_statistics.h"

namespace pixelgym::ppo {

/// Every setting of a training run; `validate()` checks every field. The defaults are CleanRL's
/// PPO for continuous control (lr 3e-4, 10 epochs, clip 0.2, no entropy bonus, normalized
/// rewards) with 8 minibatches of 128, over CleanRL's Atari rollout shape (8 envs x 128 steps).
/// Chosen by learning curves on CartPoleBalance-v0 at action_repeat 8 (README, Training): from
/// state they reach an evaluation return of 999.7 in 200k env steps, where CleanRL's Atari
/// settings (lr 2.5e-4, 4 epochs of 4 minibatches, clip 0.1, entropy 0.01) stall near 400.
struct PpoConfig {
  /// Seeds torch (weights, action sampling, minibatch order), the augmentation generator, and
  /// the envs (env i resets with seed + i).
  std::uint64_t seed = 0;
  /// Envs stepped together (must equal the vector env's num_envs) and steps per env per
  /// rollout: a rollout is num_steps * num_envs transitions.
  std::int64_t num_envs = 8;
  std::int64_t num_steps = 128;
  /// The run's length in env steps (summed over envs): the learning rate anneals to 0 over it.
  std::int64_t total_env_steps = 1'000'000;
  /// Adam's learning rate at the start, annealed linearly to 0 over total_env_steps when
  /// anneal_learning_rate.
  double learning_rate = 3e-4;
  bool anneal_learning_rate = true;
  /// Adam's epsilon.
  double adam_epsilon = 1e-5;
  /// Discount and GAE lambda.
  double gamma = 0.99;
  double gae_lambda = 0.95;
  /// Passes over the rollout per update, and minibatches per pass (num_steps * num_envs must
  /// be a multiple of it).
  std::int64_t update_epochs = 10;
  std::int64_t num_minibatches = 8;
  /// Standardize advantages within each minibatch.
  bool normalize_advantages = true;
  /// Learn from rewards divided by the running standard deviation of the discounted returns
  /// (vector::NormalizeReward's rule, wrappers::ReturnScaling, applied inside the trainer so that
  /// Episode returns stay the env's own; see Trainer). Without it the value targets are on the
  /// env's scale (hundreds on the 1000-step control tasks), and clip_value_loss lets the value move
  /// only clip_range per update towards them.
  bool normalize_rewards = true;
  /// The surrogate's clip range epsilon: the ratio is clipped to [1 - eps, 1 + eps].
  double clip_range = 0.2;
  /// Clip the value loss around the rollout's values with the same range (CleanRL's clip_vloss).
  bool clip_value_loss = true;
  /// Loss = policy loss - entropy_coef * entropy + value_coef * value loss.
  double entropy_coef = 0.0;
  double value_coef = 0.5;
  /// Gradients are rescaled to this global L2 norm at most.
  double max_grad_norm = 0.5;
  /// Stop an update's epochs early once a minibatch's approximate KL exceeds it; 0: never. With
  /// policy.separate_value_network only the policy stops: the value network goes on through
  /// every epoch (its loss reaches none of the policy's parameters).
  double target_kl = 0.0;
  /// DrQ's random shift of every image key during updates (see Trainer::update), by up to
  /// shift_pad pixels each way.
  bool augment = false;
  std::int64_t shift_pad = 4;
  /// Straggler preemption in a distributed run, as DD-PPO (Wijmans et al. 2020) does it: once
  /// preempt_done_fraction of the ranks have finished their rollout, a rank that has collected
  /// at least preempt_min_steps_fraction of its num_steps stops its rollout there and learns
  /// from the shorter one (DD-PPO's 0.6 and 0.25). Off by default; does nothing in one process.
  bool preempt_stragglers = false;
  double preempt_done_fraction = 0.6;
  double preempt_min_steps_fraction = 0.25;
  /// The network, and the observation normalization of the vector keys
  /// (policy.normalize_observations, policy.observation_clip).
  PolicyConfig policy;

  /// Throws std::invalid_argument naming the first field out of range and its value.
  void validate() const;
};

/// PpoConfig's settings, declared once (pixelgym/trainer/settings_declaration.h): its JSON form
/// (config.json's "ppo"), its ranges and `train --list-settings` come from here.
template <typename Config, typename Visit>
std::enable_if_t<std::is_same_v<std::remove_const_t<Config>, PpoConfig>> declare_settings(
    Config& c, Visit& visit) {
  visit.integer("seed", c.seed, std::uint64_t{0}, std::numeric_limits<std::uint64_t>::max(),
                "seeds the weights, the action sampling, the minibatch order, the augmentation "
                "and the envs (env i resets with seed + i); --seed sets it");
  visit.count("num_envs", c.num_envs, 1, "envs stepped together; --num-envs sets it");
  visit.count("num_steps", c.num_steps, 1,
              "steps per env per rollout: a rollout is num_steps * num_envs transitions");
  visit.count("total_env_steps", c.total_env_steps, 1,
              "the run's length in env steps, all envs together (the learning rate anneals over "
              "it); --steps sets it");
  visit.positive("learning_rate", c.learning_rate, "Adam's learning rate at the start");
  visit.flag("anneal_learning_rate", c.anneal_learning_rate,
             "anneal the learning rate linearly to 0 over total_env_steps");
  visit.positive("adam_epsilon", c.adam_epsilon, "Adam's epsilon");
  visit.number("gamma", c.gamma, 0.0, 1.0, "the discount of future rewards per env step");
  visit.number("gae_lambda", c.gae_lambda, 0.0, 1.0,
               "GAE's lambda: between one-step TD (0) and Monte Carlo (1) advantages");
  visit.count("update_epochs", c.update_epochs, 1, "passes over the rollout per update");
  visit.count("num_minibatches", c.num_minibatches, 1,
              "minibatches per pass (num_steps * num_envs must be a multiple of it)");
  visit.flag("normalize_advantages", c.normalize_advantages,
             "standardize the advantages within each minibatch");
  visit.flag("normalize_rewards", c.normalize_rewards,
             "learn from rewards divided by the running standard deviation of the discounted "
             "returns (episode returns stay the env's own)");
  visit.positive("clip_range", c.clip_range,
                 "the surrogate's clip range: the ratio is clipped to [1 - it, 1 + it]");
  visit.flag("clip_value_loss", c.clip_value_loss,
             "clip the value loss around the rollout's values with the same range");
  visit.non_negative("entropy_coef", c.entropy_coef,
                     "loss = policy loss - entropy_coef * entropy + value_coef * value loss");
  visit.non_negative("value_coef", c.value_coef, "the value loss's weight");
  visit.positive("max_grad_norm", c.max_grad_norm,
                 "gradients are rescaled to this global L2 norm at most");
  visit.non_negative("target_kl", c.target_kl,
                     "stop an update's epochs once a minibatch's approximate KL exceeds it "
                     "(0: never)");
  visit.flag("augment", c.augment,
             "DrQ's random shift of every image key during updates, by up to shift_pad pixels");
  visit.integer("shift_pad", c.shift_pad, std::int64_t{0}, std::int64_t{65536},
                "the random shift's reach in pixels");
  visit.flag("preempt_stragglers", c.preempt_stragglers,
             "in a distributed run, end a rank's rollout early once preempt_done_fraction of "
             "the ranks are done (DD-PPO's straggler preemption)");
  visit.number("preempt_done_fraction", c.preempt_done_fraction, 0.0, 1.0,
               "the share of ranks done that preempts the others");
  visit.number("preempt_min_steps_fraction", c.preempt_min_steps_fraction, 0.0, 1.0,
               "the share of num_steps a rank collects before it may be preempted");
  visit.object("policy", c.policy, "PolicyConfig", "the network (its own settings)");
}

/// The memory a run of `config` on envs of these spaces needs, by the member that sets each
/// part: num_steps (the rollout storage and a minibatch's activations) and the policy's widths
/// (weights, gradients and Adam's moments). An estimate within a factor of about 2, for refusing
/// settings that cannot fit (trainer::require_memory; Trainer does), not for planning.
std::vector<trainer::MemoryUse> memory_estimate(const Space& observation_space,
                                                const Space& action_space, const PpoConfig& config);

/// JSON form of PpoConfig: an object with one member per field, named as the fields, the CNN by
/// its name (to_string(CnnArchitecture)), `policy` a nested object. from_json takes any subset of
/// the members (the rest keep their defaults) and throws std::invalid_argument for an unknown
/// member (listing the known ones), a member of the wrong type, or a config that fails validate().
void to_json(nlohmann::json& json, const PpoConfig& config);
void from_json(const nlohmann::json& json, PpoConfig& config);
void to_json(nlohmann::json& json, const PolicyConfig& config);
void from_json(const nlohmann::json& json, PolicyConfig& config);
/// The config as JSON text (2-space indent) and back (throws as from_json, or for bad JSON).
std::string config_to_json(const PpoConfig& config);
PpoConfig config_from_json(const std::string& text);

/// One rollout of num_steps x num_envs transitions, as tensors (step-major: [t][n]).
///
/// The rollout is collected under SameStep autoreset (see GaeInputs): observations[t] is what
/// step t acted in; after a step that ended an episode, observations[t + 1] is the next
/// episode's first observation.
struct RolloutStorage {
  /// Allocates everything for `policy`'s inputs and actions.
  RolloutStorage(const Policy& policy, std::int64_t num_steps, std::int64_t num_envs);

  std::int64_t num_steps;
  std::int64_t num_envs;
  /// Per key: (T, N, *shape) in the key's dtype (images stay uint8).
  ObservationTensors observations;
  /// ActResult::action: int64 (T, N) or float32 (T, N, *shape).
  torch::Tensor actions;
  /// float32 (T, N): log pi_old(a_t | s_t), V_old(s_t), r_t.
  torch::Tensor log_probs;
  torch::Tensor values;
  torch::Tensor rewards;
  /// uint8 (T, N): the step's flags.
  torch::Tensor terminated;
  torch::Tensor truncated;
  /// float32 (T, N): V(final observation) where truncated and not terminated, else 0.
  torch::Tensor final_values;
  /// float32 (N,): V(s_T).
  torch::Tensor last_values;
  /// float32 (T, N), filled by compute_advantages.
  torch::Tensor advantages;
  torch::Tensor returns;

  /// Copies a batch of N observations (as observation_tensors gives) into step t.
  void insert_observations(std::int64_t t, const ObservationTensors& obs);
  /// compute_gae over the first `steps` stored steps (all num_steps when < 0) into advantages
  /// and returns; last_values must then be V(s_steps).
  void compute_advantages(double gamma, double lambda, std::int64_t steps = -1);
  /// The stored observations of the first `steps` steps (all num_steps when < 0) flattened to
  /// (steps N, *shape), sharing memory.
  ObservationTensors flat_observations(std::int64_t steps = -1) const;
};

/// What an update did, averaged over the minibatches it ran (CleanRL's logged quantities).
struct UpdateStats {
  double policy_loss = 0.0;         // the clipped surrogate loss (minimized)
  double value_loss = 0.0;          // 0.5 (V - return)^2 (clipped form when clip_value_loss)
  double entropy = 0.0;             // mean policy entropy
  double approx_kl = 0.0;           // mean of (ratio - 1) - log ratio (Schulman's k3 estimator)
  double clip_fraction = 0.0;       // fraction of samples with |ratio - 1| > clip_range
  double explained_variance = 0.0;  // 1 - Var(returns - values) / Var(returns) of the rollout
  double grad_norm = 0.0;           // mean global gradient norm before clipping
  double learning_rate = 0.0;       // the learning rate used
  std::int64_t epochs = 0;          // epochs run (fewer than update_epochs after a target_kl stop)
  std::int64_t minibatches = 0;     // minibatches run (the losses above are their means)
  /// Minibatches of the value network alone after a target_kl stop (separate_value_network).
  std::int64_t value_minibatches = 0;
  /// Distributed: seconds of the update spent in collective operations (the gradients'
  /// all-reduces and the few small ones), waiting for the other ranks included; 0 alone.
  double allreduce_seconds = 0.0;
};

/// An episode that ended during a rollout: the sum of the rewards the trainer was given (after
/// any reward wrapper) and its length.
struct Episode {
  double episode_return = 0.0;
  std::int64_t length = 0;
};

/// What a rollout did.
struct RolloutStats {
  std::vector<Episode> episodes;  // in the order they ended (step, then env index)
  double env_seconds = 0.0;       // in VectorEnv::step / reset
  double policy_seconds = 0.0;    // in forward passes (act, final and last values)
};

/// The generator states a resume needs beside the model, the optimizer and the env: the
/// generator of action sampling and minibatch order, and the augmentation generator (CPU
/// generator states, as at::Generator::get_state gives).
struct TrainerRngState {
  torch::Tensor sampling;
  torch::Tensor augmentation;
};

/// The reward scaling of a Trainer (PpoConfig::normalize_rewards): the running statistics of the
/// discounted returns (one element) and each env's discounted return of its current episode.
struct RewardScaling {
  wrappers::RunningStatistics statistics = wrappers::RunningStatistics::initial(1);
  std::vector<double> returns;
};

/// Trains a Policy with PPO on a vector env: `collect()` steps the env for one rollout,
/// `update()` learns from it; `iterate()` does both.
///
/// The env is any VectorEnv (a vector wrapper over one included: the trainer learns from the
/// rewards it is given, and its Episode records sum those). It must
/// autoreset in SameStep mode (make_vec's VectorOptions::autoreset =
/// AutoresetMode::kSameStep): a truncated step's final observation comes from
/// infos["final_obs"], whose value bootstraps the step's return (see compute_gae). Its
/// num_envs must equal config.num_envs. The trainer keeps a reference to the env; the env must
/// outlive it, and nobody else may step it in between.
///
/// Determinism: the constructor calls torch::manual_seed(config.seed) before building the
/// policy (its weights come from torch's default generator); action sampling and minibatch
/// order draw from a generator of the trainer's own seeded with config.seed, augmentation
/// from another seeded with config.seed + 1; the envs reset with config.seed on the first
/// collect(). Same seed, same env, same torch thread count: same parameters.
///
/// The trainer steps the env through a trainer::EnvLoop (the run's, or one of its own), which
/// keeps the action log, the env digest and the Episode records (its RecordEpisodeStatistics sees
/// the env's rewards). With config.normalize_rewards the trainer scales the rewards it stores as
/// vector::NormalizeReward would (wrappers::ReturnScaling, gamma config.gamma, epsilon 1e-8):
/// r_i / sqrt(var + 1e-8) of the discounted returns R_i = gamma R_i + r_i, R_i restarting after a
/// step that ends env i's episode. Values, advantages and returns are on that scale;
/// RolloutStats's Episode returns are the env's.
///
/// Observation normalization: after each update the rollout's observations are merged into
/// the policy's statistics (Policy::update_observation_statistics), so the next rollout acts
/// and learns with the same statistics.
///
/// Data-parallel training (DD-PPO, Wijmans et al. 2020), with a `communicator` of world size W:
/// each rank steps its own envs (rank r's env i resets with seed + r num_envs + i, so no two
/// ranks share an env seed; its sampling and augmentation generators are seeded with
/// seed + r 1,000,003 and seed + 1 + r 1,000,003) and learns from its own rollout, and the ranks
/// stay identical: rank 0's parameters and buffers are broadcast at construction; every
/// minibatch's gradients are averaged across ranks (one all-reduce of all of them, before
/// clipping), its advantages standardized with the mean and standard deviation of every rank's
/// minibatch together, and the KL stop decided on the ranks' mean KL; after each update the
/// observation statistics and the reward scaling's statistics take in every rank's samples
/// (merge_statistics_across_ranks). A minibatch is num_steps num_envs / num_minibatches
/// transitions of each rank, so an update of W ranks of N envs is the update of one process of
/// W N envs over the same transitions, up to rounding. env_steps() counts every rank's steps;
/// the learning rate anneals over them. Each rank's episode records are its own.
class Trainer {
 public:
  /// Throws std::invalid_argument when config.validate() fails, when the env's autoreset mode
  /// is not SameStep or its num_envs differs from config.num_envs, and as Policy's constructor.
  /// This constructor trains in one process (a trainer::SingleProcessCommunicator of its own),
  /// stepping `env` through an EnvLoop of its own.
  Trainer(vector::VectorEnv& env, PpoConfig config);
  /// As one rank of `communicator`'s run, which must outlive the trainer; every rank must
  /// construct its trainer with the same config.
  Trainer(vector::VectorEnv& env, PpoConfig config, trainer::Communicator& communicator);
  /// Steps the envs of `loop` (a training run's; it must outlive the trainer). Throws
  /// std::invalid_argument, as the others, and when the loop's seed is not this rank's env seed
  /// (config.seed + rank num_envs).
  Trainer(trainer::EnvLoop& loop, PpoConfig config, trainer::Communicator& communicator);
  /// Not copied or moved: it points at its own communicator when it trains alone.
  Trainer(const Trainer&) = delete;
  Trainer& operator=(const Trainer&) = delete;

  /// Steps every env num_steps times with actions sampled from the policy (no gradients),
  /// storing the transitions and the values GAE needs, then computes advantages and returns.
  /// The first call resets the envs with config.seed (unless replay_env did). `stop` (when set) is
  /// asked after each step with the env steps done so far; once it answers true and the rollout
  /// holds at least num_minibatches transitions, the rollout ends there (a shorter one, learned
  /// from as a whole; not used with a communicator of several ranks, whose rollouts end together).
  RolloutStats collect(const trainer::StopCheck& stop = {});
  /// config.update_epochs passes of minibatch PPO over the last rollout; then merges its
  /// observations into the observation statistics. The learning rate is set first, from the
  /// env steps done before the rollout (annealing). With augmentation, one random shift per
  /// transition is drawn for the whole update and the rollout's old log-probs and values are
  /// recomputed under it (no gradients), so the ratio starts at 1 on the shifted images.
  /// Throws std::logic_error before any collect(), and std::runtime_error (naming the update,
  /// epoch and minibatch, the losses and the gradient norm) when a minibatch's loss or gradient
  /// norm is not finite; that minibatch's step is not taken. `stop` (when set) is asked after each
  /// minibatch; once it answers true the update ends there (at least one minibatch is taken),
  /// as after a target_kl stop (not with a communicator of several ranks).
  UpdateStats update(const trainer::StopCheck& stop = {});

  /// The order in which an update visits the rollout's transitions in `epoch` (a permutation of
  /// 0 .. size - 1, int64, over this rank's flattened rollout, step-major: index t N + n); absent:
  /// torch::randperm from the sampling generator.
  using MinibatchOrder = std::function<torch::Tensor(std::int64_t epoch, std::int64_t size)>;
  /// Replaces the minibatch order (tests and comparisons of runs: see Trainer's data-parallel
  /// note); an empty function restores the default.
  void set_minibatch_order(MinibatchOrder order) { minibatch_order_ = std::move(order); }
  /// Learns from `rollout` (as collect() leaves the storage: advantages and returns computed,
  /// num_steps x num_envs) at the next update() instead of a collected one; counts its steps
  /// (of every rank) as collected. For comparisons of updates on one rollout.
  void load_rollout(const RolloutStorage& rollout);

  /// A 64-bit digest (FNV-1a) of the policy's parameters and buffers, in their order: equal on
  /// every rank of a distributed run.
  std::uint64_t parameter_digest() const;

  Policy& policy() { return *policy_; }
  const std::shared_ptr<Policy>& policy_ptr() const { return policy_; }
  torch::optim::Adam& optimizer() { return *optimizer_; }
  const RolloutStorage& storage() const { return storage_; }
  const PpoConfig& config() const { return config_; }
  /// Env steps collected so far (summed over envs) and updates done; set them on resume.
  std::int64_t env_steps() const { return env_steps_; }
  std::int64_t updates() const { return updates_; }
  void set_progress(std::int64_t env_steps, std::int64_t updates);
  /// The learning rate the next update uses.
  double learning_rate() const;

  /// The reward normalization's state (checkpoints): its NormalizeReward's statistics and
  /// discounted returns. Its restore throws std::invalid_argument when the statistics are not
  /// valid statistics of one element or `returns` has not num_envs finite entries (nothing
  /// changes then).
  RewardScaling reward_scaling() const;
  void set_reward_scaling(RewardScaling scaling);

  TrainerRngState rng_state() const;
  /// Throws std::invalid_argument (from torch) for a state that is not a CPU generator state.
  void set_rng_state(const TrainerRngState& state);

  /// Every action batch the trainer has sent to the env since its first reset, in order: the
  /// raw bytes of the env's batched action arrays (env_steps() / num_envs batches). With the
  /// config's seed they determine the envs' state exactly (the envs are deterministic under a
  /// seed and their actions), which is how a checkpoint carries the envs: see replay_env. Its
  /// size is env_steps() x the bytes of one env's action (4 MB per million env steps of a
  /// one-dimensional float32 action).
  const std::string& env_action_log() const { return loop_->action_log(); }
  /// Whether env_action_log covers every env step done (false after set_progress without
  /// replay_env: a resume from a checkpoint that kept no actions).
  bool env_action_log_complete() const;
  /// Brings the envs to where they were when `env_action_log` was taken, for a resume: resets
  /// them with config.seed, as the first collect() does, and steps them with the logged
  /// batches (no policy, no gradients, no reward statistics: those come from the checkpoint),
  /// so that the next collect() continues the episodes in progress and the run goes on exactly
  /// as if it had not stopped. Call it after set_progress, before collect(). Throws
  /// std::invalid_argument, naming both sizes, when the log is not env_steps() / num_envs
  /// batches (EnvLoop::replay), and std::logic_error after a collect().
  void replay_env(const std::string& env_action_log);
  /// A 64-bit digest (FNV-1a) of where the envs are: the bytes of the current observation
  /// batch and the returns and lengths of the episodes in progress; 0 before the envs are reset.
  /// A checkpoint keeps it, so that a resume can tell whether replay_env brought the envs back
  /// to the same place (it does not when the code, Bullet or Mesa changed in between).
  std::uint64_t env_digest() const;

 private:
  // The rollout flattened for an update, with the shifts of its augmentation (undefined
  // without) and the old log-probs and values under them.
  struct UpdateBatch {
    std::int64_t size = 0;
    std::int64_t minibatch = 0;
    ObservationTensors obs;
    torch::Tensor actions, old_log_probs, old_values, advantages, returns, shifts;
  };
  struct MinibatchPosition {
    std::int64_t epoch = 0;
    std::int64_t minibatch = 0;
  };
  UpdateBatch update_batch();
  torch::Tensor value_loss(const UpdateBatch& batch, const torch::Tensor& index,
                           const torch::Tensor& value) const;
  // Backward of `loss`, gradient clipping, then the optimizer's step; throws (naming `at` and
  // `losses`) without stepping when `checked_loss` or the gradient norm is not finite. Returns
  // the gradient norm.
  double step_optimizer(const torch::Tensor& loss, double checked_loss, const std::string& losses,
                        const MinibatchPosition& at);
  // A minibatch of the value loss alone (after the KL stop, with a separate value network).
  void step_value_only(const UpdateBatch& batch, const torch::Tensor& index,
                       const MinibatchPosition& at);
  // A minibatch of the PPO loss; adds its figures to `stats`; returns its approximate KL.
  double step_minibatch(const UpdateBatch& batch, const torch::Tensor& index,
                        const MinibatchPosition& at, UpdateStats& stats);
  // Averages the sums over the minibatches; the explained variance of the rollout.
  void finish_update_stats(UpdateStats& stats);
  // The constructors' work: steps `loop`, or an EnvLoop of its own over `env` when null.
  Trainer(vector::VectorEnv& env, trainer::EnvLoop* loop, PpoConfig config,
          trainer::Communicator& communicator);
  // This rank's env seed (config seed + rank num_envs).
  std::uint64_t env_seed() const;
  // Distributed: sums `value` over the ranks (one all-reduce); alone: `value`.
  void all_reduce(std::vector<double>& values, const std::string& what);
  // Distributed: averages every defined gradient over the ranks.
  void average_gradients(const MinibatchPosition& at);
  // Distributed: the observation and reward statistics take in every rank's samples.
  void merge_statistics(const std::map<std::string, wrappers::RunningStatistics>& observations,
                        const wrappers::RunningStatistics& rewards);
  // Whether a rollout at step `t` (steps done t + 1) should stop as a straggler.
  bool preempted(std::int64_t steps_done);
  // Whether the trainer runs alone (no communicator of several ranks).
  bool alone() const;

  // The loop the trainer steps: own_loop_ when it was given none.
  std::unique_ptr<trainer::EnvLoop> own_loop_;
  trainer::EnvLoop* loop_ = nullptr;
  PpoConfig config_;
  std::shared_ptr<Policy> policy_;
  wrappers::ReturnScaling reward_scaling_;  // config.normalize_rewards
  std::vector<double> scaled_rewards_;      // one step's, scaled (num_envs)
  std::vector<std::uint8_t> ended_;         // one step's terminated or truncated (num_envs)
  std::unique_ptr<torch::optim::Adam> optimizer_;
  RolloutStorage storage_;
  at::Generator sampling_;
  at::Generator augmentation_;
  Value actions_;                   // laid out as env_.action_space()
  ObservationTensors current_obs_;  // views of the env's observation batch
  // The one-process communicator, when the trainer was not given one.
  trainer::SingleProcessCommunicator single_process_;
  trainer::Communicator* communicator_;  // never null: &single_process_ or the one given
  MinibatchOrder minibatch_order_;
  std::int64_t collected_steps_ = 0;     // steps per env of the last rollout (<= num_steps)
  std::int64_t last_rollout_steps_ = 0;  // env steps of every rank in the last rollout
  bool log_from_start_ = true;           // the loop's action log goes back to the first reset
  double collective_seconds_ = 0.0;      // in collectives during the current update
  wrappers::RunningStatistics reward_statistics_before_;  // as of the last update (distributed)
  bool collected_ = false;
  std::int64_t env_steps_ = 0;
  std::int64_t updates_ = 0;
};

}  // namespace pixelgym::ppo
