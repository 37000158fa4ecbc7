// progress.csv: one row of training figures per update, a fixed header first.
#pragma once

#include <cstdint>
#include <filesystem>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace pixelgym::trainer {

/// The columns every progress.csv starts with, in this order; declared extra columns follow.
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
  double policy_loss = kNone;
  double value_loss = kNone;
  double entropy = kNone;
  double approx_kl = kNone;
  double clip_fraction = kNone;
  std::map<std::string, double> extra;  // one value per declared extra column, no others
};

/// progress.csv as read: its columns and rows (values in column order; an empty field is NaN).
struct ProgressTable {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;

  /// The values of column `name`, one per row. Throws std::invalid_argument naming the column
  /// and the columns there are.
  std::vector<double> column(const std::string& name) const;
};

/// The header line (with '\n') for the base columns and `extra_columns`. Throws
/// std::invalid_argument for an extra column that is empty, repeats a column, or holds a comma,
/// quote or line break.
std::string format_progress_header(const std::vector<std::string>& extra_columns);

/// The CSV line (with '\n') of `row`. Numbers are written in the shortest form that reads back
/// to the same double. Throws std::invalid_argument when row.extra's names are not exactly
/// `extra_columns`.
std::string format_progress_row(const ProgressRow& row,
                                const std::vector<std::string>& extra_columns);

/// The CSV line (with '\n') of a ProgressTable row: the first value (steps) as an integer, NaN
/// as an empty field.
std::string format_progress_values(const std::vector<double>& values);

/// `row` as the values of a ProgressTable row (base columns, then `extra_columns`).
std::vector<double> progress_values(const ProgressRow& row,
                                    const std::vector<std::string>& extra_columns);

/// Parses progress.csv text. A last line without its '\n' (a row cut short by a kill) is
/// dropped. Throws std::runtime_error "{source}: line N: ..." for a header that does not start
/// with the base columns, a row with the wrong number of fields, or a field that is not a number.
ProgressTable parse_progress_csv(const std::string& text, const std::string& source);

/// Reads and parses a progress.csv file (see parse_progress_csv).
ProgressTable read_progress_csv(const std::filesystem::path& path);

}  // namespace pixelgym::trainer
