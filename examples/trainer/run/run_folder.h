// A training run's folder, runs/NAME/: config.json, progress.csv, curve.png, checkpoints and
// summary.json.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pixelgym/trainer/curve_plot.h"
#include "pixelgym/trainer/progress_csv.h"

namespace pixelgym::trainer {

/// The files of one training run. `create` starts a run, `resume` continues one; rows of
/// progress.csv are then appended one write per row (a kill loses at most the row being
/// written), and curve.png, summary.json and checkpoints are written atomically.
///
/// config.json is the caller's settings object plus "code_version" (see code_version.h); each
/// resume adds {"steps", "code_version"} and the caller's `budget` members to a "resumes" array,
/// so a run continued by other code, or with another budget, says so.
class RunFolder {
 public:
  /// Starts a run in `folder` (created with its parents): writes config.json and the header of
  /// progress.csv. Throws std::invalid_argument when `config` is not an object or already has a
  /// "code_version" key, or for a bad metric column name (see format_progress_header);
  /// std::runtime_error naming the folder when it already holds a run (a config.json or
  /// progress.csv) or cannot be written.
  static RunFolder create(const std::filesystem::path& folder, nlohmann::json config,
                          std::vector<std::string> metric_columns = {});

  /// Reopens the run in `folder` to continue from a checkpoint taken at `resumed_steps` env
  /// steps: rows of progress.csv after that step were logged after the checkpoint and will be
  /// logged again, so they are dropped (progress.csv is rewritten atomically without them).
  /// The metric columns are those of progress.csv's header. `budget` (an object, or null) is
  /// merged into the "resumes" entry. Throws std::runtime_error naming the file when config.json
  /// or progress.csv is missing or malformed; std::invalid_argument for a `budget` that is not
  /// an object or null.
  static RunFolder resume(const std::filesystem::path& folder, std::int64_t resumed_steps,
                          const nlohmann::json& budget = nullptr);

  RunFolder(RunFolder&&) noexcept;
  RunFolder& operator=(RunFolder&&) noexcept;
  RunFolder(const RunFolder&) = delete;
  RunFolder& operator=(const RunFolder&) = delete;
  ~RunFolder();

  const std::filesystem::path& path() const { return folder_; }
  /// config.json as written (the caller's settings, "code_version", "resumes").
  const nlohmann::json& config() const { return config_; }
  const std::vector<std::string>& metric_columns() const { return metric_columns_; }
  /// Every row of progress.csv so far, resumed ones included.
  const ProgressTable& progress() const { return progress_; }

  /// Appends `row` to progress.csv with one write (no buffering: on disk when this returns,
  /// short of a crash of the machine). Throws std::invalid_argument when its steps are not above
  /// the last row's or its metric values do not match the declared columns, std::runtime_error
  /// naming the file when the write fails.
  void append_progress(const ProgressRow& row);

  /// Draws progress() and `evaluations` (eval.csv's) into curve.png (see write_curve_png),
  /// titled `title`.
  void write_curve(const std::string& title, const EvaluationPoints& evaluations = {}) const;

  /// Writes summary.json atomically (pretty-printed).
  void write_summary(const nlohmann::json& summary) const;

  /// Where the checkpoint after `update` updates goes: {folder}/ckpt-000120.pgck.
  std::filesystem::path checkpoint_path(std::int64_t update) const;

 private:
  RunFolder(std::filesystem::path folder, nlohmann::json config,
            std::vector<std::string> metric_columns, ProgressTable progress);
  void open_progress();

  std::filesystem::path folder_;
  nlohmann::json config_;
  std::vector<std::string> metric_columns_;
  ProgressTable progress_;
  int progress_fd_ = -1;
};

/// The lock of a run folder while a process trains in it: an exclusive flock(2) on the folder
/// itself (a folder that holds files cannot be removed, where a lock file could be deleted from
/// under the run); {folder}/.lock holds the holder's PID for the message of a second process.
/// The kernel releases it when the holder exits (however it ends), so a lock left by a dead
/// process never blocks; .lock stays.
class RunLock {
 public:
  /// Takes the lock of `folder` (created with its parents). Throws std::runtime_error
  /// "{what}: {folder} is in use: another process (pid N) is training in it; ..." when another
  /// process (or another RunLock of this one) holds it, and naming the folder when the lock file
  /// cannot be made.
  static RunLock acquire(const std::filesystem::path& folder, const std::string& what);
  RunLock(RunLock&& other) noexcept;
  RunLock& operator=(RunLock&& other) noexcept;
  RunLock(const RunLock&) = delete;
  RunLock& operator=(const RunLock&) = delete;
  /// Releases it.
  ~RunLock();

 private:
  explicit RunLock(int fd) : fd_(fd) {}
  int fd_ = -1;
};

/// Writes `json` to `path` atomically, pretty-printed with a final newline. Throws
/// std::runtime_error "{what}: cannot write {path}: {reason}".
void write_json_atomically(const std::filesystem::path& path, const nlohmann::json& json,
                           const std::string& what);

}  // namespace pixelgym::trainer
