#include "pixelgym/trainer/run_folder.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <system_error>
#include <utility>

#include "pixelgym/trainer/atomic_file.h"
#include "pixelgym/trainer/checkpoint_file.h"
#include "pixelgym/trainer/code_version.h"
#include "pixelgym/trainer/curve_plot.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;

constexpr const char* kConfigName = "config.json";
constexpr const char* kProgressName = "progress.csv";
constexpr const char* kCurveName = "curve.png";
constexpr const char* kSummaryName = "summary.json";

std::string quoted(const fs::path& path) { return "\"" + path.string() + "\""; }

nlohmann::json read_json(const fs::path& path) {
  const std::string text = read_whole_file(path, "RunFolder");
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& error) {
    throw std::runtime_error("RunFolder: " + path.string() + " is not valid JSON: " + error.what());
  }
}

}  // namespace

void write_json_atomically(const fs::path& path, const nlohmann::json& json,
                           const std::string& what) {
  const std::string text = json.dump(2) + "\n";
  write_file_atomically(path, {text}, what);
}

RunFolder::RunFolder(fs::path folder, nlohmann::json config,
                     std::vector<std::string> metric_columns, ProgressTable progress)
    : folder_(std::move(folder)),
      config_(std::move(config)),
      metric_columns_(std::move(metric_columns)),
      progress_(std::move(progress)) {}

RunFolder::RunFolder(RunFolder&& other) noexcept
    : folder_(std::move(other.folder_)),
      config_(std::move(other.config_)),
      metric_columns_(std::move(other.metric_columns_)),
      progress_(std::move(other.progress_)),
      progress_fd_(std::exchange(other.progress_fd_, -1)) {}

RunFolder& RunFolder::operator=(RunFolder&& other) noexcept {
  if (this != &other) {
    if (progress_fd_ >= 0) ::close(progress_fd_);
    folder_ = std::move(other.folder_);
    config_ = std::move(other.config_);
    metric_columns_ = std::move(other.metric_columns_);
    progress_ = std::move(other.progress_);
    progress_fd_ = std::exchange(other.progress_fd_, -1);
  }
  return *this;
}

RunFolder::~RunFolder() {
  if (progress_fd_ >= 0) ::close(progress_fd_);
}

RunLock RunLock::acquire(const fs::path& folder, const std::string& what) {
  std::error_code error;
  fs::create_directories(folder, error);
  // The lock is on the folder itself, which cannot be unlinked from under the run while it holds
  // files: a lock on a file in it was defeated by deleting that file, after which a second run
  // locked a new one and both wrote one progress.csv. .lock only tells the second the PID.
  const fs::path pid_path = folder / ".lock";
  const int fd = error ? -1 : ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (error || fd < 0) {
    throw std::runtime_error(what + ": cannot lock the run folder " + quoted(folder) + ": " +
                             (error ? error.message() : std::string(std::strerror(errno))));
  }
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    const int reason = errno;
    ::close(fd);
    if (reason != EWOULDBLOCK) {
      throw std::runtime_error(what + ": cannot lock the run folder " + quoted(folder) + ": " +
                               std::strerror(reason));
    }
    std::string holder;
    if (std::ifstream pid_file(pid_path); pid_file) std::getline(pid_file, holder);
    holder.erase(holder.find_last_not_of(" \n") + 1);
    if (holder.size() > 20 || holder.find_first_not_of("0123456789") != std::string::npos) {
      holder.clear();
    }
    throw std::runtime_error(
        what + ": " + quoted(folder) + " is in use: another process" +
        (holder.empty() ? std::string() : " (pid " + holder + ")") +
        " is training in it; wait for it to end, or stop it, before training there");
  }
  const std::string pid = std::to_string(::getpid()) + "\n";
  const int pid_fd = ::open(pid_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (pid_fd >= 0) {
    // The lock holds without it; only the PID in the message of a second process is lost.
    const ssize_t written = ::write(pid_fd, pid.data(), pid.size());
    static_cast<void>(written);
    ::close(pid_fd);
  }
  return RunLock(fd);
}

RunLock::RunLock(RunLock&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}

RunLock& RunLock::operator=(RunLock&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

RunLock::~RunLock() {
  if (fd_ >= 0) ::close(fd_);
}

RunFolder RunFolder::create(const fs::path& folder, nlohmann::json config,
                            std::vector<std::string> metric_columns) {
  if (!config.is_object()) {
    throw std::invalid_argument("RunFolder: the config must be a JSON object, got " +
                                std::string(config.type_name()));
  }
  if (config.contains("code_version")) {
    throw std::invalid_argument(
        "RunFolder: the config must not have a \"code_version\" key (RunFolder adds it), got " +
        config["code_version"].dump());
  }
  const std::string header = format_progress_header(metric_columns);
  std::error_code error;
  fs::create_directories(folder, error);
  if (error) {
    throw std::runtime_error("RunFolder: cannot create the run folder " + quoted(folder) + ": " +
                             error.message());
  }
  for (const char* name : {kConfigName, kProgressName}) {
    if (fs::exists(folder / name)) {
      throw std::runtime_error("RunFolder: " + quoted(folder) + " already holds a run (" + name +
                               "); resume it or choose another folder");
    }
  }
  config["code_version"] = code_version_json(build_code_version());
  write_json_atomically(folder / kConfigName, config, "RunFolder");
  write_file_atomically(folder / kProgressName, {header}, "RunFolder");
  ProgressTable progress;
  progress.columns = progress_base_columns();
  progress.columns.insert(progress.columns.end(), metric_columns.begin(), metric_columns.end());
  RunFolder run(folder, std::move(config), std::move(metric_columns), std::move(progress));
  run.open_progress();
  return run;
}

RunFolder RunFolder::resume(const fs::path& folder, std::int64_t resumed_steps,
                            const nlohmann::json& budget) {
  if (resumed_steps < 0) {
    throw std::invalid_argument("RunFolder: expected resumed steps >= 0, got " +
                                std::to_string(resumed_steps));
  }
  if (!budget.is_null() && !budget.is_object()) {
    throw std::invalid_argument("RunFolder: expected the resume's budget as a JSON object, got " +
                                std::string(budget.type_name()));
  }
  for (const char* reserved : {"steps", "code_version"}) {
    if (budget.is_object() && budget.contains(reserved)) {
      throw std::invalid_argument(std::string("RunFolder: the resume's budget may not set \"") +
                                  reserved + "\" (the resume's own entry)");
    }
  }
  nlohmann::json config = read_json(folder / kConfigName);
  if (!config.is_object()) {
    throw std::runtime_error("RunFolder: " + (folder / kConfigName).string() +
                             ": expected a JSON object, found " + config.type_name());
  }
  const fs::path progress_path = folder / kProgressName;
  const std::string text = read_whole_file(progress_path, "RunFolder");
  ProgressTable progress = parse_progress_csv(text, progress_path.string());
  std::vector<std::vector<double>> kept;
  for (std::vector<double>& row : progress.rows) {
    if (row[0] <= static_cast<double>(resumed_steps)) kept.push_back(std::move(row));
  }
  progress.rows = std::move(kept);
  std::vector<std::string> metric_columns(
      progress.columns.begin() + static_cast<std::ptrdiff_t>(progress_base_columns().size()),
      progress.columns.end());
  std::string rewritten = format_progress_header(metric_columns);
  for (const std::vector<double>& row : progress.rows) rewritten += format_progress_values(row);
  // Rows after the checkpoint, or a row cut short by a kill: rewrite without them.
  if (rewritten != text) write_file_atomically(progress_path, {rewritten}, "RunFolder");

  if (!config.contains("resumes") || !config["resumes"].is_array()) {
    config["resumes"] = nlohmann::json::array();
  }
  nlohmann::json entry = {{"steps", resumed_steps},
                          {"code_version", code_version_json(build_code_version())}};
  if (budget.is_object()) entry.update(budget);
  config["resumes"].push_back(std::move(entry));
  write_json_atomically(folder / kConfigName, config, "RunFolder");
  RunFolder run(folder, std::move(config), std::move(metric_columns), std::move(progress));
  run.open_progress();
  return run;
}

void RunFolder::open_progress() {
  const fs::path path = folder_ / kProgressName;
  progress_fd_ = ::open(path.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC);
  if (progress_fd_ < 0) {
    throw std::runtime_error("RunFolder: cannot open " + path.string() +
                             " to append: " + std::strerror(errno));
  }
}

void RunFolder::append_progress(const ProgressRow& row) {
  if (!progress_.rows.empty() && static_cast<double>(row.steps) <= progress_.rows.back()[0]) {
    throw std::invalid_argument(
        "RunFolder: progress rows must have increasing steps: expected "
        "more than " +
        std::to_string(static_cast<std::int64_t>(progress_.rows.back()[0])) + ", got " +
        std::to_string(row.steps));
  }
  std::vector<double> values = progress_values(row, metric_columns_);
  const std::string line = format_progress_values(values);
  // One write: a kill leaves the row whole or absent (a short write is reported, not resumed:
  // the next row would otherwise share its line).
  const ssize_t written = ::write(progress_fd_, line.data(), line.size());
  if (written != static_cast<ssize_t>(line.size())) {
    const std::string reason = written < 0 ? std::strerror(errno)
                                           : "wrote " + std::to_string(written) + " of " +
                                                 std::to_string(line.size()) + " bytes";
    throw std::runtime_error("RunFolder: cannot append to " + (folder_ / kProgressName).string() +
                             ": " + reason);
  }
  progress_.rows.push_back(std::move(values));
}

void RunFolder::write_curve(const std::string& title, const EvaluationPoints& evaluations) const {
  CurvePlotOptions options;
  options.title = title;
  write_curve_png(folder_ / kCurveName, progress_, options, evaluations);
}

void RunFolder::write_summary(const nlohmann::json& summary) const {
  write_json_atomically(folder_ / kSummaryName, summary, "RunFolder");
}

fs::path RunFolder::checkpoint_path(std::int64_t update) const {
  return folder_ / checkpoint_file_name(update);
}

}  // namespace pixelgym::trainer
