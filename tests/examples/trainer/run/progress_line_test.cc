#include "pixelgym/trainer/progress_line.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <sstream>
#include <string>

namespace pixelgym::trainer {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

ProgressStatus status_at(std::int64_t steps) {
  ProgressStatus status;
  steps = std::max<std::int64_t>(steps, 0);
  status.steps = steps;
  status.total_steps = 100000;
  status.elapsed_s = static_cast<double>(steps) / 250.0;
  status.fps = 250.0;
  status.episode_return_mean = 123.456;
  return status;
}

TEST(ProgressLineTest, EtaIsMinutesSecondsThenHours) {
  EXPECT_EQ(format_eta(0.0), "0:00");
  EXPECT_EQ(format_eta(7.4), "0:07");
  EXPECT_EQ(format_eta(59.6), "1:00");
  EXPECT_EQ(format_eta(725.0), "12:05");
  EXPECT_EQ(format_eta(3599.0), "59:59");
  EXPECT_EQ(format_eta(3600.0), "1:00:00");
  EXPECT_EQ(format_eta(3723.0), "1:02:03");
  EXPECT_EQ(format_eta(99 * 3600.0 + 59 * 60 + 59), "99:59:59");
  EXPECT_EQ(format_eta(123 * 3600.0), "123h");
  EXPECT_EQ(format_eta(std::nan("")), "--:--");
  EXPECT_EQ(format_eta(INFINITY), "--:--");
  EXPECT_EQ(format_eta(-1.0), "--:--");
}

TEST(ProgressLineTest, EtaComesFromTheBudgetThatEndsFirst) {
  ProgressStatus status = status_at(50000);  // 50k steps left at 250 fps: 200 s
  EXPECT_DOUBLE_EQ(eta_seconds(status), 200.0);
  status.time_limit_s = 260.0;  // 200 s elapsed, 60 s left
  EXPECT_DOUBLE_EQ(eta_seconds(status), 60.0);
  status.time_limit_s = 1000.0;
  EXPECT_DOUBLE_EQ(eta_seconds(status), 200.0);
  status.fps = ProgressStatus::kNone;  // no rate yet: the time budget alone
  EXPECT_DOUBLE_EQ(eta_seconds(status), 800.0);
  status.time_limit_s = 0.0;
  EXPECT_TRUE(std::isnan(eta_seconds(status)));
}

TEST(ProgressLineTest, FractionIsTheFurtherBudget) {
  ProgressStatus status = status_at(25000);
  EXPECT_DOUBLE_EQ(progress_fraction(status), 0.25);
  status.time_limit_s = 200.0;  // 100 s of 200
  EXPECT_DOUBLE_EQ(progress_fraction(status), 0.5);
  status.steps = 150000;
  EXPECT_DOUBLE_EQ(progress_fraction(status), 1.0);
  EXPECT_DOUBLE_EQ(progress_fraction(ProgressStatus{}), 0.0);
}

TEST(ProgressLineTest, CountsAreShort) {
  EXPECT_EQ(format_count(0), "0");
  EXPECT_EQ(format_count(999), "999");
  EXPECT_EQ(format_count(1000), "1.00k");
  EXPECT_EQ(format_count(12345), "12.3k");
  EXPECT_EQ(format_count(100000), "100k");
  EXPECT_EQ(format_count(999499), "999k");
  EXPECT_EQ(format_count(999999), "1.00M");
  EXPECT_EQ(format_count(1234567), "1.23M");
  EXPECT_EQ(format_count(12345678), "12.3M");
}

TEST(ProgressLineTest, BarHasTheExactWidthAndFill) {
  EXPECT_EQ(format_bar(0.0, 12), "[..........]");
  EXPECT_EQ(format_bar(0.5, 12), "[#####.....]");
  EXPECT_EQ(format_bar(0.99, 12), "[#########.]");
  EXPECT_EQ(format_bar(1.0, 12), "[##########]");
  EXPECT_EQ(format_bar(2.0, 12), "[##########]");
  EXPECT_EQ(format_bar(-1.0, 5), "[...]");
  EXPECT_EQ(format_bar(std::nan(""), 5), "[...]");
  EXPECT_EQ(format_bar(1.0, 3), "[#]");
  EXPECT_THROW(format_bar(0.5, 2), std::invalid_argument);
  for (int width = 3; width < 60; ++width) {
    EXPECT_EQ(format_bar(0.37, width).size(), static_cast<std::size_t>(width));
  }
}

TEST(ProgressLineTest, BarLineFitsTheTerminal) {
  const ProgressStatus status = status_at(12345);
  const std::string line = format_bar_line(status, 100);
  EXPECT_THAT(line, StartsWith("[####"));
  EXPECT_THAT(line, HasSubstr("] 12.3k/100k  250 fps  return 123.5  ETA 5:51"));
  for (int columns = 20; columns <= 200; ++columns) {
    EXPECT_LE(format_bar_line(status, columns).size(), static_cast<std::size_t>(columns - 1))
        << columns;
  }
  // Too narrow for a bar: the figures alone.
  EXPECT_THAT(format_bar_line(status, 50), StartsWith("12.3k/100k"));
  // Before the first episode ends.
  ProgressStatus early = status_at(0);
  early.episode_return_mean = ProgressStatus::kNone;
  early.fps = ProgressStatus::kNone;
  EXPECT_THAT(format_bar_line(early, 100), HasSubstr("0/100k  - fps  return -  ETA --:--"));
}

TEST(ProgressLineTest, PlainLineSaysEverythingInWords) {
  ProgressStatus status = status_at(12288);
  EXPECT_EQ(format_plain_line(status),
            "steps 12288/100000 (12.3%)  fps 250  return 123.5  elapsed 0:49  ETA 5:51");
  status.total_steps = 0;
  status.time_limit_s = 600.0;
  EXPECT_EQ(format_plain_line(status),
            "steps 12288  fps 250  return 123.5  elapsed 0:49  ETA 9:11");
}

TEST(ProgressLineTest, NotATerminalWritesAPlainLineEveryNUpdates) {
  std::ostringstream out;
  ProgressLine progress(out, ProgressLine::Mode::kPlain, 3);
  for (int update = 1; update <= 7; ++update) progress.update(status_at(1000 * update));
  progress.finish(status_at(7000));
  const std::string text = out.str();
  EXPECT_THAT(text, Not(HasSubstr("\r")));
  EXPECT_THAT(text, Not(HasSubstr("\x1b")));
  EXPECT_EQ(text, format_plain_line(status_at(3000)) + "\n" + format_plain_line(status_at(6000)) +
                      "\n" + format_plain_line(status_at(7000)) + "\n");
  // Finishing right after a written line does not repeat it.
  std::ostringstream exact;
  ProgressLine every_two(exact, ProgressLine::Mode::kPlain, 2);
  every_two.update(status_at(1000));
  every_two.update(status_at(2000));
  every_two.finish(status_at(2000));
  EXPECT_EQ(exact.str(), format_plain_line(status_at(2000)) + "\n");
}

// A plain line at least every kMaxSilenceS seconds however long an update: ticks within an update
// write one once that long has passed since the last line (and not before), so does an update
// that is not the n-th, and so does a note (an evaluation's).
TEST(ProgressLineTest, PlainLinesComeAtLeastEveryFewSecondsWithinUpdates) {
  double now = 100.0;
  std::ostringstream out;
  ProgressLine progress(out, ProgressLine::Mode::kPlain, 10, 100, [&now] { return now; });
  now += ProgressLine::kMaxSilenceS - 0.5;
  EXPECT_FALSE(progress.tick(status_at(10)));
  EXPECT_EQ(out.str(), "");
  now += 0.5;
  EXPECT_TRUE(progress.tick(status_at(20)));
  EXPECT_EQ(out.str(), format_plain_line(status_at(20)) + "\n");
  now += 1.0;
  EXPECT_FALSE(progress.tick(status_at(30)));
  progress.update(status_at(40));  // not the 10th, and 1 s after the last line
  EXPECT_EQ(out.str(), format_plain_line(status_at(20)) + "\n");
  now += ProgressLine::kMaxSilenceS;
  progress.update(status_at(50));  // not the 10th, but kMaxSilenceS after the last line
  EXPECT_EQ(out.str(),
            format_plain_line(status_at(20)) + "\n" + format_plain_line(status_at(50)) + "\n");
  now += 1.0;
  EXPECT_FALSE(progress.tick_note("evaluating"));
  now += ProgressLine::kMaxSilenceS;
  EXPECT_TRUE(progress.tick_note("evaluating"));
  EXPECT_THAT(out.str(), HasSubstr("\nevaluating\n"));
  // A line of the caller's own starts the silence again.
  now += ProgressLine::kMaxSilenceS;
  progress.wrote_line();
  EXPECT_FALSE(progress.tick(status_at(60)));
  EXPECT_LE(ProgressLine::kMaxSilenceS, 10.0);
}

TEST(ProgressLineTest, TerminalRedrawsOneLineInPlace) {
  std::ostringstream out;
  ProgressLine progress(out, ProgressLine::Mode::kBar, 5, 80);
  progress.update(status_at(1000));
  progress.update(status_at(2000));
  progress.finish(status_at(3000));
  EXPECT_EQ(out.str(), "\r" + format_bar_line(status_at(1000), 80) + "\x1b[K" + "\r" +
                           format_bar_line(status_at(2000), 80) + "\x1b[K" + "\r" +
                           format_bar_line(status_at(3000), 80) + "\x1b[K\n");
}

TEST(ProgressLineTest, ModeFollowsQuietAndBadSettingsAreRefused) {
  EXPECT_EQ(ProgressLine::mode_for_stdout(true), ProgressLine::Mode::kPlain);
  // Under ctest stdout is a pipe, not a terminal; run by hand it may be one.
  if (::isatty(STDOUT_FILENO) == 1) {
    EXPECT_EQ(ProgressLine::mode_for_stdout(false), ProgressLine::Mode::kBar);
  } else {
    EXPECT_EQ(ProgressLine::mode_for_stdout(false), ProgressLine::Mode::kPlain);
    EXPECT_EQ(ProgressLine::stdout_columns(), 100);
  }
  std::ostringstream out;
  EXPECT_THROW(ProgressLine(out, ProgressLine::Mode::kPlain, 0), std::invalid_argument);
  EXPECT_THROW(ProgressLine(out, ProgressLine::Mode::kBar, 1, 19), std::invalid_argument);
}

}  // namespace
}  // namespace pixelgym::trainer
