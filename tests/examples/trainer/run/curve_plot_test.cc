#include "pixelgym/trainer/curve_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "tests/examples/trainer/run/test_folders.h"

namespace pixelgym::trainer {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// A table with the curve's columns: steps, wall time, return mean and std per row.
ProgressTable table_of(const std::vector<double>& steps, const std::vector<double>& seconds,
                       const std::vector<double>& mean, const std::vector<double>& spread) {
  ProgressTable table;
  table.columns = progress_base_columns();
  for (std::size_t i = 0; i < steps.size(); ++i) {
    table.rows.push_back(
        {steps[i], seconds[i], kNan, mean[i], spread[i], kNan, kNan, kNan, kNan, kNan});
  }
  return table;
}

// 100k steps over ~7 minutes: NaN until the first episode ends, then a noisy rise to ~800.
ProgressTable realistic_run() {
  std::mt19937 random(3);
  std::normal_distribution<double> noise(0.0, 25.0);
  std::vector<double> steps, seconds, mean, spread;
  for (int update = 1; update <= 49; ++update) {
    const double step = 2048.0 * update;
    steps.push_back(step);
    seconds.push_back(step / 240.0);
    if (update < 3) {
      mean.push_back(kNan);
      spread.push_back(kNan);
      continue;
    }
    const double progress = step / 100000.0;
    mean.push_back(800.0 / (1.0 + std::exp(-8.0 * (progress - 0.45))) + noise(random));
    spread.push_back(30.0 + 120.0 * std::exp(-std::pow((progress - 0.45) / 0.2, 2.0)));
  }
  return table_of(steps, seconds, mean, spread);
}

// Where the panels start: the title and the legend (which shows both colours) are above.
constexpr int kPanelsTop = 60;

// The pixels of `image` below kPanelsTop equal to `rgb`, as (x, y) pairs.
std::vector<std::pair<int, int>> pixels_of(const render::Image& image, std::uint8_t r,
                                           std::uint8_t g, std::uint8_t b) {
  std::vector<std::pair<int, int>> found;
  for (int y = kPanelsTop; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 3];
      if (p[0] == r && p[1] == g && p[2] == b) found.emplace_back(x, y);
    }
  }
  return found;
}

// The mean's colour (RGB of the BGR (180, 100, 25) the plot draws with) and the band's.
std::vector<std::pair<int, int>> mean_pixels(const render::Image& image) {
  return pixels_of(image, 25, 100, 180);
}
std::vector<std::pair<int, int>> band_pixels(const render::Image& image) {
  return pixels_of(image, 190, 215, 240);
}

// Draws `table` into {test output}/trainer_run/curves/{name}.png (for a person to look at) and
// returns the image.
render::Image draw_and_save(const std::string& name, const ProgressTable& table,
                            const EvaluationPoints& evaluations = {}) {
  const fs::path folder = fs::path(PIXELGYM_TEST_OUTPUT_DIR) / "trainer_run" / "curves";
  fs::create_directories(folder);
  CurvePlotOptions options;
  options.title = "CartPoleBalance-v0  (" + name + ")";
  write_curve_png(folder / (name + ".png"), table, options, evaluations);
  const render::Image image = render::read_png((folder / (name + ".png")).string());
  EXPECT_EQ(image.width, 900);
  EXPECT_EQ(image.height, 450);
  EXPECT_EQ(image.channels, 3);
  return image;
}

TEST(CurvePlotTest, NiceAxesUseOneTwoFiveSteps) {
  const AxisTicks steps = nice_axis(0.0, 100000.0, 5);
  EXPECT_EQ(steps.step, 20000.0);
  EXPECT_THAT(steps.values, ElementsAre(0, 20000, 40000, 60000, 80000, 100000));
  const AxisTicks returns = nice_axis(-3.2, 7.9, 5);
  EXPECT_EQ(returns.step, 2.0);
  EXPECT_EQ(returns.low, -4.0);
  EXPECT_EQ(returns.high, 8.0);
  EXPECT_EQ(nice_axis(0.0, 800.0, 5).step, 200.0);
  EXPECT_EQ(nice_axis(0.0, 7.0, 5).step, 1.0);
  EXPECT_EQ(nice_axis(0.0, 12.0, 5).step, 2.0);
  EXPECT_EQ(nice_axis(0.0, 24.0, 5).step, 5.0);
  EXPECT_EQ(nice_axis(0.0, 35.0, 5).step, 10.0);
  EXPECT_EQ(nice_axis(0.0, 0.9, 5).step, 0.2);
  // Reversed bounds are accepted.
  EXPECT_EQ(nice_axis(800.0, 0.0, 5).high, 800.0);
}

TEST(CurvePlotTest, ConstantRangesAreWidened) {
  const AxisTicks zero = nice_axis(0.0, 0.0, 5);
  EXPECT_LE(zero.low, -1.0);
  EXPECT_GE(zero.high, 1.0);
  const AxisTicks five = nice_axis(500.0, 500.0, 5);
  EXPECT_LT(five.low, 500.0);
  EXPECT_GT(five.high, 500.0);
  EXPECT_GE(five.low, 440.0);  // by about 10 %, not to zero
  EXPECT_THROW(nice_axis(kNan, 1.0, 5), std::invalid_argument);
  EXPECT_THROW(nice_axis(0.0, INFINITY, 5), std::invalid_argument);
  EXPECT_THROW(nice_axis(0.0, 1.0, 0), std::invalid_argument);
}

TEST(CurvePlotTest, TickLabelsAreShortAndExact) {
  EXPECT_EQ(format_tick(20000, 20000, 100000), "20k");
  EXPECT_EQ(format_tick(0, 20000, 100000), "0");
  EXPECT_EQ(format_tick(1500000, 500000, 2000000), "1.5M");
  EXPECT_EQ(format_tick(5000000, 1000000, 5000000), "5M");
  EXPECT_EQ(format_tick(1500000, 250000, 2e7), "1.50M");
  EXPECT_EQ(format_tick(800, 200, 800), "800");
  EXPECT_EQ(format_tick(-200, 200, 800), "-200");
  EXPECT_EQ(format_tick(2.5, 0.5, 10), "2.5");
  EXPECT_EQ(format_tick(0.25, 0.05, 1), "0.25");
  EXPECT_EQ(format_tick(0.4, 0.2, 1), "0.4");
  EXPECT_EQ(format_tick(3500, 500, 5000), "3500");
  EXPECT_EQ(format_tick(-1e-17, 0.2, 1), "0.0");
}

TEST(CurvePlotTest, RealisticRunDrawsBothPanelsWithBands) {
  const render::Image image = draw_and_save("realistic", realistic_run());
  const auto mean = mean_pixels(image);
  const auto band = band_pixels(image);
  int left = 0;
  int right = 0;
  for (const auto& [x, y] : mean) (x < 450 ? left : right) += 1;
  EXPECT_GT(left, 300);
  EXPECT_GT(right, 300);
  EXPECT_GT(band.size(), 5000U);
}

// eval.csv's evaluations are drawn over the training curve, in their own colour (RGB of the BGR
// (14, 127, 255)), in both panels, at their returns: here above the training curve's range, so
// the y axis reaches them.
TEST(CurvePlotTest, EvaluationsAreDrawnOnTheCurve) {
  const auto evaluation_pixels = [](const render::Image& image) {
    return pixels_of(image, 255, 127, 14);
  };
  EXPECT_TRUE(evaluation_pixels(draw_and_save("no_evaluations", realistic_run())).empty());
  EvaluationPoints evaluations;
  for (int i = 1; i <= 5; ++i) {
    evaluations.steps.push_back(20000.0 * i);
    evaluations.wall_time_s.push_back(20000.0 * i / 240.0);
    evaluations.mean.push_back(900.0 + i);
    evaluations.std.push_back(10.0);
  }
  const render::Image image = draw_and_save("evaluations", realistic_run(), evaluations);
  int left = 0;
  int right = 0;
  int highest = image.height;
  for (const auto& [x, y] : evaluation_pixels(image)) {
    (x < 450 ? left : right) += 1;
    highest = std::min(highest, y);
  }
  EXPECT_GT(left, 5 * 20);
  EXPECT_GT(right, 5 * 20);
  // Above every training mean pixel: 900 is above the curve's ~800.
  int highest_mean = image.height;
  for (const auto& [x, y] : mean_pixels(image)) highest_mean = std::min(highest_mean, y);
  EXPECT_LT(highest, highest_mean);
  evaluations.std.pop_back();
  EXPECT_THROW(draw_curve(realistic_run(), CurvePlotOptions{}, evaluations), std::invalid_argument);
}

TEST(CurvePlotTest, NoEpisodeYetDrawsEmptyPanels) {
  const render::Image image =
      draw_and_save("no_episode_yet", table_of({2048, 4096}, {8, 16}, {kNan, kNan}, {kNan, kNan}));
  EXPECT_TRUE(mean_pixels(image).empty());
  EXPECT_TRUE(band_pixels(image).empty());
  const render::Image empty = draw_and_save("no_rows", table_of({}, {}, {}, {}));
  EXPECT_TRUE(mean_pixels(empty).empty());
}

TEST(CurvePlotTest, OneRowIsADotInEachPanel) {
  const render::Image image = draw_and_save("one_row", table_of({2048}, {9}, {12.5}, {3}));
  const auto mean = mean_pixels(image);
  int left = 0;
  int right = 0;
  for (const auto& [x, y] : mean) (x < 450 ? left : right) += 1;
  EXPECT_GT(left, 5);
  EXPECT_GT(right, 5);
}

TEST(CurvePlotTest, EqualValuesDrawAFlatLineInsideTheAxes) {
  const render::Image image = draw_and_save(
      "all_equal",
      table_of({1000, 2000, 3000, 4000}, {1, 2, 3, 4}, {500, 500, 500, 500}, {0, 0, 0, 0}));
  const auto mean = mean_pixels(image);
  ASSERT_FALSE(mean.empty());
  int min_y = image.height;
  int max_y = 0;
  int min_x = image.width;
  int max_x = 0;
  for (const auto& [x, y] : mean) {
    if (x >= 450) continue;
    min_y = std::min(min_y, y);
    max_y = std::max(max_y, y);
    min_x = std::min(min_x, x);
    max_x = std::max(max_x, x);
  }
  EXPECT_LE(max_y - min_y, 2);    // flat
  EXPECT_GT(max_x - min_x, 200);  // from 1000 to 4000 of 0..4000 steps
  EXPECT_GT(min_y, 100);          // not on the top or bottom edge: the axis was widened
  EXPECT_LT(max_y, 350);
}

TEST(CurvePlotTest, GapsBeforeTheFirstEpisodeAndBetweenRuns) {
  const render::Image image =
      draw_and_save("gaps", table_of({1000, 2000, 3000, 4000, 5000, 6000}, {10, 20, 30, 40, 50, 60},
                                     {kNan, 10, 20, kNan, 40, 50}, {kNan, 2, kNan, kNan, 4, 5}));
  // In the left panel the line runs over 2000..3000 and 5000..6000 steps: a third of the panel
  // between them has no pixel of it.
  std::vector<bool> column(450, false);
  for (const auto& [x, y] : mean_pixels(image)) {
    if (x < 450) column[static_cast<std::size_t>(x)] = true;
  }
  const auto first = std::find(column.begin(), column.end(), true);
  const auto last = std::find(column.rbegin(), column.rend(), true).base();
  ASSERT_LT(first, last);
  int longest_gap = 0;
  int gap = 0;
  for (auto it = first; it != last; ++it) {
    gap = *it ? 0 : gap + 1;
    longest_gap = std::max(longest_gap, gap);
  }
  EXPECT_GT(longest_gap, 80);
  EXPECT_LT(longest_gap, 160);
}

TEST(CurvePlotTest, SizeAndColumnsAreChecked) {
  CurvePlotOptions small;
  small.width = 300;
  EXPECT_THROW(draw_curve(realistic_run(), small), std::invalid_argument);
  ProgressTable table;
  table.columns = {"steps"};
  try {
    draw_curve(table, {});
    FAIL() << "no exception";
  } catch (const std::invalid_argument& error) {
    EXPECT_THAT(error.what(), HasSubstr("no column \"wall_time_s\""));
  }
}

// Long runs: wall time in hours, steps in millions.
TEST(CurvePlotTest, LongRunUsesHoursAndMillions) {
  std::vector<double> steps, seconds, mean, spread;
  for (int i = 1; i <= 200; ++i) {
    steps.push_back(25000.0 * i);
    seconds.push_back(90.0 * i);
    mean.push_back(-50.0 + 0.5 * i);
    spread.push_back(10.0);
  }
  draw_and_save("long_run", table_of(steps, seconds, mean, spread));
}

}  // namespace
}  // namespace pixelgym::trainer
