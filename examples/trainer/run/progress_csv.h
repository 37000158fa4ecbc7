// progress.csv: one row of training figures per update: the run's columns, then the metrics the
// algorithm reports, by name.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// The run's columns, which every progress.csv starts with, in this order: steps, wall_time_s,
/// fps, episode_return_mean, episode_return_std. The algorithm's metric columns follow (PPO's
/// start with policy_loss, value_loss, entropy, approx_kl, clip_fraction, the columns every run
/// had before metrics were named by their algorithm).
const std::vector<std::string>& progress_base_columns();

/// The figures of one update. NaN (the default of the optional figures) is written as an empty
/// field: "no episode has ended yet", "no loss before the first update".
struct ProgressRow {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  std::int64_t steps = 0;    // env steps so far, all envs together
  double wall_time_s = 0.0;  // since the run started, resumed runs included
  double fps = kNone;        // env steps per second over the last update
  double episode_return_mean = kNone;
  double episode_return_std = kNone;
  /// The algorithm's metrics by column name (Algorithm::metric_names); NaN: none this update.
  std::map<std::string, double> metrics;
};

/// progress.csv as read: its columns and rows (values in column order; an empty field is NaN).
struct ProgressTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  /// The values of column `name`, one per row. Throws std::invalid_argument naming the column
  /// and the columns there are.
  std::vector<double> column(const std::string& name) const;
};

/// The header line (with '\n') for the base columns and `metric_columns`. Throws
/// std::invalid_argument for a metric column that is empty, repeats a column, or holds a comma,
/// quote or line break.
std::string format_progress_header(const std::vector<std::string>& metric_columns);

/// The CSV line (with '\n') of `row` under the base columns and `metric_columns`. Numbers are
/// written in the shortest form that reads back to the same double; a metric column that
/// row.metrics does not hold is an empty field (a column of an older run's header that its
/// algorithm no longer reports). Throws std::invalid_argument naming a metric of row.metrics
/// that is not one of `metric_columns`, and the columns.
std::string format_progress_row(const ProgressRow& row,
                                const std::vector<std::string>& metric_columns);

/// The CSV line (with '\n') of a ProgressTable row: the first value (steps) as an integer, NaN
/// as an empty field.
std::string format_progress_values(const std::vector<double>& values);

/// `row` as the values of a ProgressTable row (base columns, then `metric_columns`); throws as
/// format_progress_row.
std::vector<double> progress_values(const ProgressRow& row,
                                    const std::vector<std::string>& metric_columns);

/// Parses progress.csv text. A last line without its '\n' (a row cut short by a kill) is
/// dropped. Throws std::runtime_error "{source}: line N: ..." for a header that does not start
/// with the base columns, a row with the wrong number of fields, or a field that is not a number.
ProgressTable parse_progress_csv(const std::string& text, const std::string& source);

/// Reads and parses a progress.csv file (see parse_progress_csv).
ProgressTable read_progress_csv(const std::filesystem::path& path);

}  // namespace pixelgym::trainer
