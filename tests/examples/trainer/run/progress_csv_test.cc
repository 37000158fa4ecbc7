#include "examples/trainer/run/progress_csv.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace pixelgym::trainer {
namespace {

using ::testing::HasSubstr;

constexpr const char* kBaseHeader =
    "steps,wall_time_s,fps,episode_return_mean,episode_return_std,policy_loss,value_loss,entropy,"
    "approx_kl,clip_fraction";

ProgressRow sample_row() {
  ProgressRow row;
  row.steps = 2048;
  row.wall_time_s = 12.5;
  row.fps = 163.84;
  row.episode_return_mean = 0.1 + 0.2;  // needs 17 digits to read back exactly
  row.episode_return_std = 3.0;
  row.policy_loss = -0.0125;
  row.value_loss = 1e-7;
  row.entropy = 0.693;
  row.approx_kl = 0.004;
  row.clip_fraction = 0.0;
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

TEST(ProgressCsvTest, HeaderHasTheFixedColumnsThenTheExtraOnes) {
  EXPECT_EQ(format_progress_header({}), std::string(kBaseHeader) + "\n");
  EXPECT_EQ(format_progress_header({"lr", "eval_return"}),
            std::string(kBaseHeader) + ",lr,eval_return\n");
}

TEST(ProgressCsvTest, BadExtraColumnNamesAreRejected) {
  for (const std::string& name : std::vector<std::string>{"", "a,b", "a\"b", "a\nb", "fps"}) {
    EXPECT_THROW(format_progress_header({name}), std::invalid_argument) << name;
  }
  EXPECT_THROW(format_progress_header({"lr", "lr"}), std::invalid_argument);
}

TEST(ProgressCsvTest, RowsReadBackExactlyAndNanIsAnEmptyField) {
  ProgressRow row = sample_row();
  row.episode_return_std = ProgressRow::kNone;
  row.extra = {{"lr", 2.5e-4}};
  const std::string line = format_progress_row(row, {"lr"});
  EXPECT_EQ(line, "2048,12.5,163.84,0.30000000000000004,,-0.0125,1e-07,0.693,0.004,0,0.00025\n");
  const ProgressTable table = parse_progress_csv(format_progress_header({"lr"}) + line, "p.csv");
  ASSERT_EQ(table.rows.size(), 1U);
  const std::vector<double> expected = progress_values(row, {"lr"});
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

TEST(ProgressCsvTest, ExtraValuesMustMatchTheDeclaredColumns) {
  ProgressRow row = sample_row();
  EXPECT_THROW(format_progress_row(row, {"lr"}), std::invalid_argument);  // missing
  row.extra = {{"lr", 1.0}, {"other", 2.0}};
  try {
    format_progress_row(row, {"lr"});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("expected the extra columns {lr} declared with the run, "
                                        "got {lr,other}"));
  }
  row.extra = {{"lx", 1.0}};
  EXPECT_THROW(format_progress_row(row, {"lr"}), std::invalid_argument);  // same count, renamed
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
  EXPECT_THAT(error_of(header + "1,2,3\n"),
              HasSubstr("p.csv: line 2: expected 10 fields, found 3"));
  EXPECT_THAT(error_of(header + "1,2,x,,,,,,,\n"),
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
