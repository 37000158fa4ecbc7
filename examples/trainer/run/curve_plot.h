// curve.png: the learning curve of a run, drawn from progress.csv with OpenCV.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "pixelgym/render/image_io.h"
#include "pixelgym/trainer/progress_csv.h"

namespace pixelgym::trainer {

/// How the curve is drawn.
struct CurvePlotOptions {
  std::string title;  // drawn centred at the top, e.g. "CartPoleBalance-v0  runs/demo"
  int width = 900;    // pixels, at least 400
  int height = 450;   // pixels, at least 250
  /// draw_comparison: the left panel's x axis.
  std::string x_label = "control steps";
};

/// Evaluations to draw on a run's curve (eval.csv's rows): at env steps and wall time in
/// seconds, their mean return and its std; all of one length.
struct EvaluationPoints {
  std::vector<double> steps;
  std::vector<double> wall_time_s;
  std::vector<double> mean;
  std::vector<double> std;
};

/// One run's curve in a comparison: y against x (e.g. control steps) and against wall minutes.
struct ComparedCurve {
  std::string label;
  std::vector<double> x;
  std::vector<double> wall_minutes;
  std::vector<double> mean;
  std::vector<double> std;  // unused by the drawing (lines only), kept for the caller's tables
};

/// Curves of several runs in two panels, y against x and against wall minutes, one colour per
/// curve with a legend of their labels. Non-finite values leave gaps. Throws
/// std::invalid_argument for a size below 400x250, a curve whose columns differ in length, or
/// a legend that leaves no room for the panels.
render::Image draw_comparison(const std::vector<ComparedCurve>& curves,
                              const CurvePlotOptions& options);

/// The range and tick marks of one plot axis: ticks at multiples of `step` (1, 2 or 5 times a
/// power of ten) from `low` to `high`, which are themselves multiples of `step`.
struct AxisTicks {
  double low = 0.0;
  double high = 1.0;
  double step = 0.2;
  std::vector<double> values;
};

/// Ticks covering [low, high] with about `target_count` intervals. An empty or zero-width range
/// is widened (by 1, or 10 % of the value's magnitude) so that a constant series gets an axis.
/// Throws std::invalid_argument for a non-finite bound or target_count < 1.
AxisTicks nice_axis(double low, double high, int target_count);

/// A tick label: `value` with just enough decimals for ticks `step` apart, and a k suffix when
/// the axis reaches 10,000, M from a million, G from a billion (20000 -> "20k", 1500000 on a 2M
/// axis with 0.5M ticks -> "1.5M", 0.25 -> "0.25").
std::string format_tick(double value, double step, double axis_max_magnitude);

/// Draws the curve: two panels, episode return against env steps and against wall time (in s,
/// min or h by the run's length), each with the mean line, a band of +/- std, grid lines and
/// tick labels. Rows whose episode_return_mean is NaN (no episode ended yet) leave gaps; an
/// isolated point is drawn as a dot; with no finite return the panels say so. `evaluations`
/// (when any) are drawn over it in another colour, a marker with a +/- std bar each, joined by a
/// thin line, and named in the legend. Returns RGB pixels. Throws std::invalid_argument for a
/// size below the minimum, a table without the steps, wall_time_s, episode_return_mean and
/// episode_return_std columns, or evaluations whose members differ in length.
render::Image draw_curve(const ProgressTable& progress, const CurvePlotOptions& options,
                         const EvaluationPoints& evaluations = {});

/// draw_curve, written to `path` as a PNG atomically (render::write_png).
void write_curve_png(const std::filesystem::path& path, const ProgressTable& progress,
                     const CurvePlotOptions& options, const EvaluationPoints& evaluations = {});

}  // namespace pixelgym::trainer
