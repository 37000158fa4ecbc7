#include "pixelgym/trainer/progress_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

using ::testing::HasSubstr;

constexpr const char* kBaseHeader = "steps,wall_time_s,fps,episode_return_mean,episode_return_std";

ProgressRow sample_row() {
  ProgressRow row;
  row.steps = 2048;
  row.wall_time_s = 12.5;
  row.fps = 163.84;
  row.episode_return_mean = 0.1 + 0.2;  // needs 17 digits to read back exactly
  row.episode_return_std = 3.0;
  return row;
}

std::string error_of(const std::string& text) {
  try {
    parse_progress_csv(text, "p.csv");
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "";
}

TEST(ProgressCsvTest, HeaderHasTheRunsColumnsThenTheMetricOnes) {
  EXPECT_EQ(format_progress_header({}), std::string(kBaseHeader) + "\n");
  EXPECT_EQ(format_progress_header({"lr", "eval_return"}),
            std::string(kBaseHeader) + ",lr,eval_return\n");
}

TEST(ProgressCsvTest, BadMetricColumnNamesAreRejected) {
  for (const std::string& name : std::vector<std::string>{"", "a,b", "a\"b", "a\nb", "fps"}) {
    EXPECT_THROW(format_progress_header({name}), std::invalid_argument) << name;
  }
  EXPECT_THROW(format_progress_header({"lr", "lr"}), std::invalid_argument);
}

TEST(ProgressCsvTest, RowsReadBackExactlyAndNanIsAnEmptyField) {
  ProgressRow row = sample_row();
  row.episode_return_std = ProgressRow::kNone;
  row.metrics = {{"lr", 2.5e-4}, {"policy_loss", -0.0125}, {"value_loss", 1e-7}};
  const std::vector<std::string> columns = {"policy_loss", "value_loss", "lr"};
  const std::string line = format_progress_row(row, columns);
  EXPECT_EQ(line, "2048,12.5,163.84,0.30000000000000004,,-0.0125,1e-07,0.00025\n");
  const ProgressTable table = parse_progress_csv(format_progress_header(columns) + line, "p.csv");
  ASSERT_EQ(table.rows.size(), 1U);
  const std::vector<double> expected = progress_values(row, columns);
  ASSERT_EQ(table.rows[0].size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (std::isnan(expected[i])) {
      EXPECT_TRUE(std::isnan(table.rows[0][i])) << i;
    } else {
      EXPECT_EQ(table.rows[0][i], expected[i]) << i;  // bit for bit
    }
  }
  EXPECT_EQ(table.column("lr"), std::vector<double>{2.5e-4});
  EXPECT_EQ(table.column("steps"), std::vector<double>{2048});
}

// A metric the run has no column for is refused by name; a column the algorithm does not report
// (an older run's, such as the loss columns of a DrQ-v2 run of bc3ad29) is an empty field.
TEST(ProgressCsvTest, MetricsMustBeColumnsAndAColumnNotReportedIsEmpty) {
  ProgressRow row = sample_row();
  row.metrics = {{"lr", 1.0}, {"other", 2.0}};
  try {
    format_progress_row(row, {"lr"});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("metric \"other\" is not a column of the run; its metric "
                                        "columns are {lr}"));
  }
  row.metrics = {{"lx", 1.0}};
  EXPECT_THROW(format_progress_row(row, {"lr"}), std::invalid_argument);  // renamed
  row.metrics = {{"lr", 0.5}};
  EXPECT_EQ(format_progress_row(row, {"policy_loss", "lr", "entropy"}),
            "2048,12.5,163.84,0.30000000000000004,3,,0.5,\n");
  row.metrics.clear();
  EXPECT_EQ(format_progress_row(row, {"lr"}), "2048,12.5,163.84,0.30000000000000004,3,\n");
}

TEST(ProgressCsvTest, ALastLineWithoutNewlineIsDropped) {
  const std::string header = format_progress_header({});
  const std::string row = format_progress_row(sample_row(), {});
  const ProgressTable table = parse_progress_csv(header + row + "4096,20,1", "p.csv");
  EXPECT_EQ(table.rows.size(), 1U);
}

TEST(ProgressCsvTest, MalformedFilesAreRefusedNamingTheLine) {
  const std::string header = format_progress_header({});
  EXPECT_THAT(error_of(""), HasSubstr("p.csv: line 1: expected a header line"));
  EXPECT_THAT(error_of("steps,fps\n"), HasSubstr("p.csv: line 1: expected a header starting with"));
  EXPECT_THAT(error_of(header + "1,2,3\n"), HasSubstr("p.csv: line 2: expected 5 fields, found 3"));
  EXPECT_THAT(error_of(header + "1,2,x,,\n"),
              HasSubstr("p.csv: line 2: column fps: expected a number, found \"x\""));
}

TEST(ProgressCsvTest, UnknownColumnNamesTheColumnsThereAre) {
  ProgressTable table;
  table.columns = {"steps", "fps"};
  try {
    table.column("return");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("no column \"return\"; the columns are steps,fps"));
  }
}

}  // namespace
}  // namespace pixelgym::trainer
