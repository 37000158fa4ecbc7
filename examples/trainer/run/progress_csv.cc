#include "pixelgym/trainer/progress_csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <set>
#include <stdexcept>

#include "pixelgym/trainer/atomic_file.h"

namespace pixelgym::trainer {
namespace {

std::string format_number(double value) {
  if (std::isnan(value)) return "";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ",") + name;
  return text;
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> fields;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(line.substr(start, comma - start));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return fields;
}

}  // namespace

const std::vector<std::string>& progress_base_columns() {
  static const std::vector<std::string> kColumns = {"steps", "wall_time_s", "fps",
                                                    "episode_return_mean", "episode_return_std"};
  return kColumns;
}

std::vector<double> ProgressTable::column(const std::string& name) const {
  const auto found = std::find(columns.begin(), columns.end(), name);
  if (found == columns.end()) {
    throw std::invalid_argument("ProgressTable: no column \"" + name + "\"; the columns are " +
                                joined(columns));
  }
  const auto index = static_cast<std::size_t>(found - columns.begin());
  std::vector<double> values;
  values.reserve(rows.size());
  for (const std::vector<double>& row : rows) values.push_back(row[index]);
  return values;
}

std::string format_progress_header(const std::vector<std::string>& metric_columns) {
  std::set<std::string> seen(progress_base_columns().begin(), progress_base_columns().end());
  for (const std::string& name : metric_columns) {
    if (name.empty() || name.find_first_of(",\"\r\n") != std::string::npos) {
      throw std::invalid_argument(
          "progress.csv: a metric column name must be non-empty without commas, quotes or line "
          "breaks, got \"" +
          name + "\"");
    }
    if (!seen.insert(name).second) {
      throw std::invalid_argument("progress.csv: metric column \"" + name + "\" repeats a column");
    }
  }
  std::vector<std::string> columns = progress_base_columns();
  columns.insert(columns.end(), metric_columns.begin(), metric_columns.end());
  return joined(columns) + "\n";
}

std::vector<double> progress_values(const ProgressRow& row,
                                    const std::vector<std::string>& metric_columns) {
  for (const auto& [name, value] : row.metrics) {
    if (std::find(metric_columns.begin(), metric_columns.end(), name) == metric_columns.end()) {
      throw std::invalid_argument("progress.csv: metric \"" + name +
                                  "\" is not a column of the run; its metric columns are {" +
                                  joined(metric_columns) + "}");
    }
  }
  std::vector<double> values = {static_cast<double>(row.steps), row.wall_time_s, row.fps,
                                row.episode_return_mean, row.episode_return_std};
  for (const std::string& name : metric_columns) {
    const auto found = row.metrics.find(name);
    values.push_back(found == row.metrics.end() ? ProgressRow::kNone : found->second);
  }
  return values;
}

std::string format_progress_values(const std::vector<double>& values) {
  std::string line;
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) line += ",";
    line +=
        i == 0 ? std::to_string(static_cast<std::int64_t>(values[i])) : format_number(values[i]);
  }
  return line + "\n";
}

std::string format_progress_row(const ProgressRow& row,
                                const std::vector<std::string>& metric_columns) {
  return format_progress_values(progress_values(row, metric_columns));
}

ProgressTable parse_progress_csv(const std::string& text, const std::string& source) {
  const auto fail = [&](std::size_t line, const std::string& problem) {
    throw std::runtime_error(source + ": line " + std::to_string(line) + ": " + problem);
  };
  ProgressTable table;
  std::size_t start = 0;
  std::size_t line_number = 0;
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) break;  // a row cut short by a kill: dropped
    ++line_number;
    std::string line = text.substr(start, end - start);
    start = end + 1;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::vector<std::string> fields = split_fields(line);
    if (line_number == 1) {
      const std::vector<std::string>& base = progress_base_columns();
      if (fields.size() < base.size() || !std::equal(base.begin(), base.end(), fields.begin())) {
        fail(1, "expected a header starting with " + joined(base) + ", found " + line);
      }
      table.columns = std::move(fields);
      continue;
    }
    if (fields.size() != table.columns.size()) {
      fail(line_number, "expected " + std::to_string(table.columns.size()) + " fields, found " +
                            std::to_string(fields.size()));
    }
    std::vector<double> values;
    values.reserve(fields.size());
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::string& field = fields[i];
      if (field.empty()) {
        values.push_back(std::nan(""));
        continue;
      }
      char* parsed_end = nullptr;
      const double value = std::strtod(field.c_str(), &parsed_end);
      if (parsed_end != field.c_str() + field.size()) {
        fail(line_number,
             "column " + table.columns[i] + ": expected a number, found \"" + field + "\"");
      }
      values.push_back(value);
    }
    table.rows.push_back(std::move(values));
  }
  if (table.columns.empty()) fail(1, "expected a header line, found an empty file");
  return table;
}

ProgressTable read_progress_csv(const std::filesystem::path& path) {
  return parse_progress_csv(read_whole_file(path, "progress.csv"), path.string());
}

}  // namespace pixelgym::trainer
