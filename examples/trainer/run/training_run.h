// A training run, shared by every algorithm: create or resume a run folder, train under a step
// and time budget, checkpoint, evaluate, write final.mp4 and summary.json.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <ostream>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "pixelgym/trainer/algorithm.h"
#include "pixelgym/trainer/checkpoint_file.h"
#include "pixelgym/trainer/evaluation.h"
#include "pixelgym/trainer/progress_line.h"
#include "pixelgym/trainer/run_folder.h"
#include "pixelgym/trainer/run_settings.h"

namespace pixelgym::trainer {

/// A request that does not fit the run (a budget below what is done, a setting that differs
/// from the run's on resume): the caller's input is at fault, not the run.
class RunRequestError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// How much to train.
struct TrainBudget {
  /// The run's length in env steps, all envs together; 0: the config's total_env_steps (a
  /// resumed run: as its latest resume left it). On resume it must exceed the steps done.
  std::int64_t steps = 0;
  /// Wall time in minutes (>= 0) on top of the run's so far, and at least one update; 0: none
  /// given (a new run has no time limit, a resumed run keeps the budget it had).
  double minutes = 0.0;
};

/// Settings given again for a resume; each must equal the run's (RunRequestError otherwise,
/// naming the flag, the value and the run's). Absent: not given.
struct ResumeChecks {
  std::optional<std::uint64_t> seed;
  std::optional<std::int64_t> num_envs;
  std::optional<int> num_threads;
  std::optional<int> torch_threads;
  std::optional<std::int64_t> checkpoint_every;
  std::optional<std::int64_t> keep_checkpoints;
  std::optional<std::int64_t> eval_episodes;
  std::optional<std::int64_t> eval_every;
  std::optional<std::int64_t> eval_every_episodes;
};

/// One evaluation during training (a row of eval.csv).
struct EvalRow {
  std::int64_t steps = 0;    // env steps when it ran
  double wall_time_s = 0.0;  // the run's wall time then (before the evaluation)
  double return_mean = 0.0;
  double return_std = 0.0;
  std::int64_t episodes = 0;
  double eval_s = 0.0;  // the evaluation's own wall time
};

/// eval.csv's text for `rows` (a header line, then one line per row).
std::string format_eval_csv(const std::vector<EvalRow>& rows);
/// Parses eval.csv text (from `source`). Throws std::runtime_error "{source}: line N: ..." for
/// a line that is not a row of six numbers or a header that is not format_eval_csv's.
std::vector<EvalRow> parse_eval_csv(const std::string& text, const std::string& source);

/// The recent episodes that progress rows summarize: (the env steps when each ended, its
/// return), oldest first.
using RecentReturns = std::deque<std::pair<std::int64_t, double>>;

/// Adds `returns` (of the episodes that ended in an iteration of `iteration_steps` env steps,
/// which brought the run to `steps`) to `recent`, then keeps the latest 100 at most that ended
/// within the last max(steps / 10, iteration_steps) env steps, and always the latest one.
void add_recent_returns(RecentReturns& recent, const std::vector<double>& returns,
                        std::int64_t steps, std::int64_t iteration_steps);

/// Where a run reports: messages and the progress line to `out`, skipped checkpoints to `errors`.
struct RunOutput {
  std::ostream& out;
  std::ostream& errors;
  ProgressLine::Mode progress_mode = ProgressLine::Mode::kPlain;  // kPlain: a line every 10 updates
  int columns = 100;                                              // the terminal's width
};

/// One training run of an algorithm, in a run folder (RunFolder): built by `create` or `resume`
/// (which read and check, and write nothing), then `train()`.
///
/// Budget: training stops once the env steps reach total_env_steps or the run's whole wall time
/// (resumed runs included, as of their latest checkpoint) reaches its time budget less the time
/// kept for the final evaluation. The time is checked within iterations too (Algorithm::iterate's
/// StopCheck, between env steps and gradient steps; in one process only): a cut iteration keeps
/// what it did and is checkpointed as any other. With a time budget the run first measures what
/// an evaluation episode costs (measure_evaluation_cost, a few dozen steps) and keeps for the
/// final evaluation what it needs, at most kEvaluationShare of the time left
/// (plan_final_evaluation: fewer episodes, or no video, when they do not fit, each said in a line
/// and in summary.json's "time_budget"); the final evaluation plays another episode only while
/// the time left holds one. One episode is always played. Checkpoints
/// are written every checkpoint_every updates and at the end, keeping the newest
/// keep_checkpoints. A resumed run restores the algorithm from the latest valid checkpoint and
/// replays the checkpoint's env actions, so that the envs continue their episodes: with the
/// same total_env_steps the result is the run that did not stop.
///
/// Evaluations during training: once the env steps pass each multiple of eval_every, the policy
/// plays eval_every_episodes deterministic seeded episodes (the final evaluation's seeds) and a
/// row goes to eval.csv (rewritten atomically; a resume drops the rows after its checkpoint).
/// An evaluation is skipped when those of this process have taken more than eval_max_share (a
/// tenth by default) of its wall time, so that they never take much more, or when it would not
/// end before the time budget stops training; each reason is said once.
///
/// Progress: the progress line (ProgressLine) once per update and within updates, so that a
/// plain line reaches a pipe at least every 10 s, evaluations included. The episodes the line
/// and progress.csv's episode_return_mean summarize: the latest 100 at most that ended within the
/// last max(a tenth of the env steps done, the latest iteration's env steps), and always the
/// latest one (a window of episodes alone spanned whole runs of long episodes).
class TrainingRun {
 public:
  /// A new run of `settings` (settings.algorithm_config as algorithm.parse_config gives it) in
  /// `folder`, which must not hold a run. budget.steps replaces total_env_steps; budget.minutes
  /// becomes settings.minutes. Throws std::invalid_argument when the config, so changed, fails
  /// algorithm.parse_config.
  static TrainingRun create(const AlgorithmFactory& algorithm, RunSettings settings,
                            std::filesystem::path folder, TrainBudget budget, RunOutput output);

  /// More of the run in `folder`, from its config.json and its latest valid checkpoint (newer
  /// invalid ones are reported to output.errors as "train: skipping {path}: {reason}"). Without
  /// budget.steps / budget.minutes the budget is the one the latest resume left. Throws
  /// RunRequestError for a `given` setting that differs from the run's or budget.steps not
  /// above the steps done; std::runtime_error when there is no config.json or no valid
  /// checkpoint, or config.json is not a run's.
  static TrainingRun resume(const AlgorithmFactory& algorithm, std::filesystem::path folder,
                            TrainBudget budget, const ResumeChecks& given, RunOutput output);

  /// The run folder is locked (RunLock) from resume() or the start of train() until train()
  /// returns or throws: a second process is refused meanwhile.
  /// Trains until the budget is spent, writes the last checkpoint, evaluates the policy
  /// (eval_episodes deterministic episodes from seed + 1,000,000, the first recorded to
  /// final.mp4) and writes summary.json, which it returns. A resumed run whose budget is spent
  /// and whose summary.json is of its latest checkpoint has nothing to do: it says so to
  /// output.out, changes nothing and returns nullopt.
  std::optional<nlohmann::json> train();

  /// Makes this run rank 0 of `communicator`'s data-parallel run of world_size() ranks (call
  /// before train(); the communicator must outlive the run). Rank 0 alone writes the run folder
  /// and progress, evaluates and writes final.mp4 and summary.json. At train() it sends every
  /// other rank (each built by `join`) the run's settings and, on resume, its own part of the
  /// checkpoint; every rank trains (the algorithm averages across ranks) until rank 0 finds the
  /// budget spent, the episodes of every rank count in progress.csv, and the ranks' parameter
  /// digests are compared every kDigestEvery updates, at every checkpoint and at the end
  /// (DistributedError on a mismatch, naming the ranks). A checkpoint holds rank 0's blobs and,
  /// for each other rank r, its Algorithm::rank_blobs, env actions and meta as "rank{r}.*";
  /// a resume must have the run's world size (RunRequestError otherwise). summary.json gets
  /// "distributed": {"world_size", "parameter_digests"}.
  void distribute(Communicator& communicator);
  /// Rank communicator.rank() > 0 of a data-parallel run whose rank 0 runs `distribute`: its
  /// settings, budget and resume point come from rank 0 at train(), which writes no file and
  /// returns nullopt.
  static TrainingRun join(const AlgorithmFactories& algorithms, Communicator& communicator,
                          RunOutput output);

  /// Makes `flag` (set by a signal handler: Ctrl-C) stop the run: once it is true the iteration
  /// in progress ends as a time budget would end it, the last checkpoint is written, and train()
  /// returns nullopt with interrupted() true, without the final evaluation. `flag` must outlive
  /// the run.
  void stop_when(const std::atomic<bool>& flag) { interrupt_ = &flag; }
  /// Whether train() was stopped by stop_when's flag.
  bool interrupted() const { return interrupted_; }
  /// The newest checkpoint train() wrote (empty before).
  const std::filesystem::path& last_checkpoint() const { return last_checkpoint_; }

  /// The most of the time left at the start of a process with a time budget that the final
  /// evaluation may take.
  static constexpr double kEvaluationShare = 0.25;

  /// Updates between two comparisons of the ranks' parameter digests.
  static constexpr std::int64_t kDigestEvery = 10;

  const RunSettings& settings() const { return settings_; }
  const std::filesystem::path& folder() const { return folder_; }

 private:
  TrainingRun(const AlgorithmFactory& algorithm, RunSettings settings, std::filesystem::path folder,
              RunOutput output);

  // Resume: the budget from config.json's latest resume, the checkpoint and its meta.
  void load_resume_point(const nlohmann::json& config);
  // Applies `budget` to the settings and the time limit; validates the config.
  void apply_budget(const TrainBudget& budget);
  // With a checkpoint: RunRequestError for too few steps; true (after saying so) when the
  // budget is spent and summary.json is of the checkpoint.
  bool nothing_to_do() const;
  // The algorithm restored from the checkpoint, its envs replayed, the run folder reopened.
  void restore_from_checkpoint();
  void replay_env_actions();
  void train_until_spent();
  // With a time budget (rank 0): measures the evaluation's cost and sets the training deadline.
  void plan_time_budget();
  void update_training_deadline();
  // What an iteration asks between its steps: progress, and whether to stop.
  bool stop_requested(std::int64_t env_steps);
  bool interrupt_requested() const;
  // Says why an evaluation during training is skipped, once per reason.
  void report_skip(const std::string& reason, const std::string& line);
  // One iterate() and its progress.csv row; returns the row.
  ProgressRow iterate_once(const StopCheck& stop);
  // An evaluation when the steps since `steps_before` passed a multiple of eval_every.
  void evaluate_when_due(std::int64_t steps_before);
  void save_checkpoint();
  nlohmann::json evaluate_and_summarize();
  double elapsed_s() const;
  // Distributed.
  bool lead() const;  // rank 0, or a single process
  bool distributed() const;
  // Rank 0: sends each rank its start (settings, budget, its part of the checkpoint); the
  // others: receive theirs. Returns false when there is nothing to do.
  void send_start(bool nothing_to_do);
  bool receive_start();
  // Rank 0's decision, shared: whether to go on training.
  bool keep_training(bool lead_says);
  // Gathers every rank's episode returns to rank 0 (rank order).
  std::vector<double> gather_returns(const std::vector<double>& mine);

  const AlgorithmFactory* factory_;
  RunSettings settings_;
  std::filesystem::path folder_;
  RunOutput output_;
  std::optional<LoadedCheckpoint> checkpoint_;
  // A resume of a run stopped before its first checkpoint: it starts afresh in its folder.
  bool restart_ = false;
  nlohmann::json meta_;          // the checkpoint's
  double budget_minutes_ = 0.0;  // of wall time over the whole run; 0: none
  double minutes_given_ = 0.0;   // TrainBudget::minutes
  double wall_before_s_ = 0.0;   // the run's wall time before this process: its checkpoint's

  // While training.
  std::unique_ptr<vector::VectorEnv> env_;
  // The env loop the algorithm steps (reset with seed + rank num_envs): its action log, replay
  // and digest go into checkpoints. Destroyed after the algorithm, which points at it.
  std::unique_ptr<EnvLoop> loop_;
  std::unique_ptr<Algorithm> algorithm_;
  // Whether the loop's action log goes back to the envs' first reset (not after a resume from a
  // checkpoint that kept no env actions).
  bool env_log_complete_ = true;
  std::optional<RunFolder> run_;
  RecentReturns returns_;       // see add_recent_returns
  std::vector<EvalRow> evals_;  // eval.csv's rows
  double eval_seconds_ = 0.0;   // spent in evaluations during training by this process
  std::chrono::steady_clock::time_point start_;
  // The communicator of one process, the run's unless distribute or join gives another (on the
  // heap: a TrainingRun is moved out of create and resume).
  std::unique_ptr<Communicator> single_process_ = std::make_unique<SingleProcessCommunicator>();
  Communicator* communicator_ = single_process_.get();  // never null
  std::vector<std::uint64_t> parameter_digests_;        // every rank's, at the last check
  std::optional<RunLock> lock_;                         // the run folder's, from resume or train
  AlgorithmFactories join_algorithms_;                  // join: the algorithm rank 0's config names
  std::string busy_cores_warning_;                      // said once the envs are made; "" when none
  // Progress and budget while training.
  std::optional<ProgressLine> progress_;
  ProgressStatus status_;
  double time_limit_s_ = 0.0;           // of the run's whole wall time; 0: none
  double training_deadline_s_ = 0.0;    // the limit less what the final evaluation needs
  double left_at_start_s_ = 0.0;        // of the time limit, when this process began training
  std::optional<EvaluationCost> cost_;  // measured when there is a time limit
  FinalEvaluationPlan planned_;         // the final evaluation the deadline keeps time for
  std::string stopped_by_;              // "steps", "time" or "interrupt"
  std::set<std::string> skip_reasons_;  // evaluations skipped, by reason (said once each)
  std::int64_t evaluations_skipped_ = 0;
  const std::atomic<bool>* interrupt_ = nullptr;
  bool interrupted_ = false;
  std::filesystem::path last_checkpoint_;
};

}  // namespace pixelgym::trainer
