#include "pixelgym/trainer/curve_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <stdexcept>

namespace pixelgym::trainer {
namespace {

// Colours, BGR.
const cv::Scalar kBackground(255, 255, 255);
const cv::Scalar kGrid(228, 228, 228);
const cv::Scalar kAxis(60, 60, 60);
const cv::Scalar kText(30, 30, 30);
const cv::Scalar kMean(180, 100, 25);   // a strong blue
const cv::Scalar kBand(240, 215, 190);  // the same blue, pale
const cv::Scalar kNote(120, 120, 120);
const cv::Scalar kEvaluation(14, 127, 255);  // orange

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickScale = 0.42;
constexpr double kLabelScale = 0.48;
constexpr double kTitleScale = 0.62;
constexpr int kShift = 3;  // sub-pixel bits of line coordinates
constexpr double kSubPixel = 1 << kShift;

cv::Size text_size(const std::string& text, double scale, int thickness, int* baseline) {
  return cv::getTextSize(text, kFont, scale, thickness, baseline);
}

// Draws `text` with its left end at x (or centred on x, or right-aligned at x) and its baseline
// at y.
enum class Align { kLeft, kCentre, kRight };
void put_text(cv::Mat& image, const std::string& text, int x, int y, double scale,
              const cv::Scalar& colour, Align align, int thickness = 1) {
  int baseline = 0;
  const cv::Size size = text_size(text, scale, thickness, &baseline);
  if (align == Align::kCentre) x -= size.width / 2;
  if (align == Align::kRight) x -= size.width;
  cv::putText(image, text, {x, y}, kFont, scale, colour, thickness, cv::LINE_AA);
}

// A series to plot in one panel: x, the mean and the std per row.
struct Series {
  std::vector<double> x;
  std::vector<double> mean;
  std::vector<double> std;
};

// One panel: the rectangle it plots in, its axes and labels.
struct Panel {
  cv::Rect area;  // the plotting area, inside the axes
  AxisTicks x_axis;
  AxisTicks y_axis;
  std::string x_label;
  double x_magnitude = 0.0;
  double y_magnitude = 0.0;

  cv::Point point(double x, double y) const {
    const double u = (x - x_axis.low) / (x_axis.high - x_axis.low);
    const double v = (y - y_axis.low) / (y_axis.high - y_axis.low);
    const double px = area.x + u * area.width;
    const double py = area.y + area.height - v * area.height;
    return {static_cast<int>(std::lround(px * kSubPixel)),
            static_cast<int>(std::lround(py * kSubPixel))};
  }
};

bool finite(double value) { return std::isfinite(value); }

void draw_axes(cv::Mat& image, const Panel& panel) {
  const cv::Rect& area = panel.area;
  int baseline = 0;
  const int tick_height = text_size("0", kTickScale, 1, &baseline).height;
  for (const double x : panel.x_axis.values) {
    const cv::Point p = panel.point(x, panel.y_axis.low);
    const int px = p.x / static_cast<int>(kSubPixel);
    cv::line(image, {px, area.y}, {px, area.y + area.height}, kGrid, 1);
    cv::line(image, {px, area.y + area.height}, {px, area.y + area.height + 4}, kAxis, 1);
    put_text(image, format_tick(x, panel.x_axis.step, panel.x_magnitude), px,
             area.y + area.height + 8 + tick_height, kTickScale, kText, Align::kCentre);
  }
  for (const double y : panel.y_axis.values) {
    const cv::Point p = panel.point(panel.x_axis.low, y);
    const int py = p.y / static_cast<int>(kSubPixel);
    cv::line(image, {area.x, py}, {area.x + area.width, py}, kGrid, 1);
    cv::line(image, {area.x - 4, py}, {area.x, py}, kAxis, 1);
    put_text(image, format_tick(y, panel.y_axis.step, panel.y_magnitude), area.x - 7,
             py + tick_height / 2, kTickScale, kText, Align::kRight);
  }
  const int label_height = text_size("0", kLabelScale, 1, &baseline).height;
  put_text(image, panel.x_label, area.x + area.width / 2,
           area.y + area.height + 16 + tick_height + label_height + 4, kLabelScale, kText,
           Align::kCentre);
  put_text(image, "episode return", area.x, area.y - 8, kLabelScale, kText, Align::kLeft);
}

// The runs of consecutive rows with a finite x and mean, as [begin, end) index pairs: a NaN
// mean (no episode ended yet) leaves a gap.
std::vector<std::pair<std::size_t, std::size_t>> finite_runs(const Series& series) {
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  const std::size_t n = series.x.size();
  std::size_t begin = 0;
  while (begin < n) {
    if (!finite(series.x[begin]) || !finite(series.mean[begin])) {
      ++begin;
      continue;
    }
    std::size_t end = begin;
    while (end < n && finite(series.x[end]) && finite(series.mean[end])) ++end;
    runs.emplace_back(begin, end);
    begin = end;
  }
  return runs;
}

// The +/- std band: a polygon per run (a bar for a lone row); a NaN std counts as 0.
void draw_band(cv::Mat& image, const Panel& panel, const Series& series,
               const cv::Scalar& colour = kBand) {
  const auto spread = [&](std::size_t i) { return finite(series.std[i]) ? series.std[i] : 0.0; };
  for (const auto& [begin, end] : finite_runs(series)) {
    std::vector<cv::Point> outline;
    for (std::size_t i = begin; i < end; ++i) {
      outline.push_back(panel.point(series.x[i], series.mean[i] + spread(i)));
    }
    for (std::size_t i = end; i-- > begin;) {
      outline.push_back(panel.point(series.x[i], series.mean[i] - spread(i)));
    }
    if (end - begin >= 2) {
      cv::fillPoly(image, std::vector<std::vector<cv::Point>>{outline}, colour, cv::LINE_AA,
                   kShift);
    } else if (spread(begin) > 0.0) {
      cv::line(image, outline[0], outline[1], colour, 7, cv::LINE_AA, kShift);
    }
  }
}

// The mean: a line per run, a dot for a lone row.
void draw_mean(cv::Mat& image, const Panel& panel, const Series& series,
               const cv::Scalar& colour = kMean) {
  for (const auto& [begin, end] : finite_runs(series)) {
    for (std::size_t i = begin + 1; i < end; ++i) {
      cv::line(image, panel.point(series.x[i - 1], series.mean[i - 1]),
               panel.point(series.x[i], series.mean[i]), colour, 2, cv::LINE_AA, kShift);
    }
    if (end - begin == 1) {
      cv::circle(image, panel.point(series.x[begin], series.mean[begin]),
                 static_cast<int>(3 * kSubPixel), colour, cv::FILLED, cv::LINE_AA, kShift);
    }
  }
}

// Where the two panels go: room on the left of each for the y tick labels, `top` under the
// legend, room on the right for half the last x tick label.
struct PanelLayout {
  int left_margin = 0;
  int top = 0;
  int gap = 30;
  int panel_width = 0;
  int panel_height = 0;
};

PanelLayout panel_layout(const AxisTicks& y_axis, double y_magnitude, int legend_y,
                         const CurvePlotOptions& options) {
  int baseline = 0;
  const int y_label_width = std::max(
      text_size(format_tick(y_axis.low, y_axis.step, y_magnitude), kTickScale, 1, &baseline).width,
      text_size(format_tick(y_axis.high, y_axis.step, y_magnitude), kTickScale, 1, &baseline)
          .width);
  PanelLayout layout;
  layout.left_margin = y_label_width + 16;
  layout.top = legend_y + 34;
  const int bottom_margin = 52;
  const int right_margin = 24;
  layout.panel_width = (options.width - 2 * layout.left_margin - layout.gap - right_margin) / 2;
  layout.panel_height = options.height - layout.top - bottom_margin;
  return layout;
}

// A BGR drawing as an RGB image.
render::Image rgb_image(const cv::Mat& image) {
  cv::Mat rgb;
  cv::cvtColor(image, rgb, cv::COLOR_BGR2RGB);
  render::Image result;
  result.height = rgb.rows;
  result.width = rgb.cols;
  result.channels = 3;
  result.pixels.assign(rgb.data, rgb.data + rgb.total() * rgb.elemSize());
  return result;
}

// Wall time in the unit that suits the run's length: its values, its axis label.
std::pair<std::vector<double>, std::string> wall_time_axis(const std::vector<double>& seconds) {
  double longest = 0.0;
  for (const double value : seconds) {
    if (finite(value)) longest = std::max(longest, value);
  }
  double unit = 1.0;
  std::string label = "wall time (s)";
  if (longest >= 2 * 3600.0) {
    unit = 3600.0;
    label = "wall time (h)";
  } else if (longest >= 120.0) {
    unit = 60.0;
    label = "wall time (min)";
  }
  std::vector<double> values;
  values.reserve(seconds.size());
  for (const double value : seconds) values.push_back(value / unit);
  return {values, label};
}

}  // namespace

AxisTicks nice_axis(double low, double high, int target_count) {
  if (!finite(low) || !finite(high) || target_count < 1) {
    throw std::invalid_argument("nice_axis: expected finite bounds and target_count >= 1, got [" +
                                std::to_string(low) + ", " + std::to_string(high) + "] and " +
                                std::to_string(target_count));
  }
  if (low > high) std::swap(low, high);
  if (high - low <= 1e-12 * std::max(1.0, std::abs(high))) {
    const double pad = std::abs(high) > 0.0 ? 0.1 * std::abs(high) : 1.0;
    low -= pad;
    high += pad;
  }
  const double raw = (high - low) / target_count;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double normalized = raw / magnitude;
  const double factor = normalized < 1.5   ? 1.0
                        : normalized < 3.0 ? 2.0
                        : normalized < 7.0 ? 5.0
                                           : 10.0;
  AxisTicks ticks;
  ticks.step = factor * magnitude;
  // Snap the bounds out to multiples of the step (with a little slack for rounding).
  ticks.low = std::floor(low / ticks.step + 1e-9) * ticks.step;
  ticks.high = std::ceil(high / ticks.step - 1e-9) * ticks.step;
  const auto count = static_cast<int>(std::lround((ticks.high - ticks.low) / ticks.step));
  for (int i = 0; i <= count; ++i) {
    double value = ticks.low + i * ticks.step;
    if (std::abs(value) < 1e-9 * ticks.step) value = 0.0;  // no "-0"
    ticks.values.push_back(value);
  }
  return ticks;
}

std::string format_tick(double value, double step, double axis_max_magnitude) {
  double unit = 1.0;
  const char* suffix = "";
  if (axis_max_magnitude >= 1e9) {
    unit = 1e9;
    suffix = "G";
  } else if (axis_max_magnitude >= 1e6) {
    unit = 1e6;
    suffix = "M";
  } else if (axis_max_magnitude >= 1e4) {
    unit = 1e3;
    suffix = "k";
  }
  const double scaled_step = step / unit;
  int decimals = 0;
  if (scaled_step > 0.0 && scaled_step < 1.0) {
    decimals = static_cast<int>(std::ceil(-std::log10(scaled_step) - 1e-9));
    // 0.25 and 2.5: one more digit than the power of ten says.
    const double rest = scaled_step * std::pow(10.0, decimals);
    if (std::abs(rest - std::round(rest)) > 1e-6) ++decimals;
  }
  decimals = std::min(decimals, 6);
  double scaled = value / unit;
  if (std::abs(scaled) < 0.5 * std::pow(10.0, -decimals)) scaled = 0.0;  // no "-0"
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.*f%s", decimals, scaled, scaled == 0.0 ? "" : suffix);
  return buffer;
}

namespace {

// The evaluations: a marker with a +/- std bar each, joined by a thin line.
void draw_evaluations(cv::Mat& image, const Panel& panel, const std::vector<double>& x,
                      const EvaluationPoints& evaluations) {
  std::optional<cv::Point> previous;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double mean = evaluations.mean[i];
    if (!finite(x[i]) || !finite(mean)) continue;
    const double s = finite(evaluations.std[i]) ? evaluations.std[i] : 0.0;
    const cv::Point at = panel.point(x[i], mean);
    if (s > 0.0) {
      cv::line(image, panel.point(x[i], mean - s), panel.point(x[i], mean + s), kEvaluation, 1,
               cv::LINE_AA, kShift);
    }
    if (previous) cv::line(image, *previous, at, kEvaluation, 1, cv::LINE_AA, kShift);
    previous = at;
  }
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (!finite(x[i]) || !finite(evaluations.mean[i])) continue;
    cv::circle(image, panel.point(x[i], evaluations.mean[i]), static_cast<int>(4 * kSubPixel),
               kEvaluation, cv::FILLED, cv::LINE_AA, kShift);
  }
}

}  // namespace

render::Image draw_curve(const ProgressTable& progress, const CurvePlotOptions& options,
                         const EvaluationPoints& evaluations) {
  if (options.width < 400 || options.height < 250) {
    throw std::invalid_argument("draw_curve: expected a size of at least 400x250, got " +
                                std::to_string(options.width) + "x" +
                                std::to_string(options.height));
  }
  const std::size_t evaluation_count = evaluations.steps.size();
  if (evaluations.wall_time_s.size() != evaluation_count ||
      evaluations.mean.size() != evaluation_count || evaluations.std.size() != evaluation_count) {
    throw std::invalid_argument("draw_curve: the evaluations' members differ in length");
  }
  const std::vector<double> steps = progress.column("steps");
  const std::vector<double> wall_time_s = progress.column("wall_time_s");
  const std::vector<double> mean = progress.column("episode_return_mean");
  const std::vector<double> spread = progress.column("episode_return_std");

  cv::Mat image(options.height, options.width, CV_8UC3, kBackground);
  int baseline = 0;
  const int title_height = text_size("Ag", kTitleScale, 1, &baseline).height;
  const int title_y = 10 + title_height;
  put_text(image, options.title, options.width / 2, title_y, kTitleScale, kText, Align::kCentre);

  // The y range: every finite mean +/- std.
  double y_low = INFINITY;
  double y_high = -INFINITY;
  for (std::size_t i = 0; i < mean.size(); ++i) {
    if (!finite(mean[i])) continue;
    const double s = finite(spread[i]) ? spread[i] : 0.0;
    y_low = std::min(y_low, mean[i] - s);
    y_high = std::max(y_high, mean[i] + s);
  }
  for (std::size_t i = 0; i < evaluation_count; ++i) {
    if (!finite(evaluations.mean[i])) continue;
    const double s = finite(evaluations.std[i]) ? evaluations.std[i] : 0.0;
    y_low = std::min(y_low, evaluations.mean[i] - s);
    y_high = std::max(y_high, evaluations.mean[i] + s);
  }
  const bool any_return = finite(y_low);
  if (!any_return) {
    y_low = 0.0;
    y_high = 1.0;
  }
  const AxisTicks y_axis = nice_axis(y_low, y_high, 5);
  const double y_magnitude = std::max(std::abs(y_axis.low), std::abs(y_axis.high));

  // The legend, under the title.
  const int legend_y = title_y + 22;
  const int legend_x = options.width / 2 - (evaluation_count > 0 ? 200 : 110);
  cv::line(image, {legend_x, legend_y - 4}, {legend_x + 24, legend_y - 4}, kMean, 2, cv::LINE_AA);
  put_text(image, "mean over recent episodes", legend_x + 30, legend_y, kTickScale, kText,
           Align::kLeft);
  const int band_x =
      legend_x + 30 + text_size("mean over recent episodes", kTickScale, 1, &baseline).width + 16;
  cv::rectangle(image, cv::Rect(band_x, legend_y - 10, 24, 12), kBand, cv::FILLED);
  put_text(image, "+/- std", band_x + 30, legend_y, kTickScale, kText, Align::kLeft);
  if (evaluation_count > 0) {
    const int eval_x = band_x + 30 + text_size("+/- std", kTickScale, 1, &baseline).width + 16;
    cv::circle(image, {eval_x + 12, legend_y - 4}, 4, kEvaluation, cv::FILLED, cv::LINE_AA);
    put_text(image, "evaluations (eval.csv)", eval_x + 30, legend_y, kTickScale, kText,
             Align::kLeft);
  }

  // Two panels side by side; room on the left of each for the y tick labels.
  const PanelLayout layout = panel_layout(y_axis, y_magnitude, legend_y, options);
  const int left_margin = layout.left_margin;
  const int top = layout.top;
  const int gap = layout.gap;
  const int panel_width = layout.panel_width;
  const int panel_height = layout.panel_height;

  // The wall time axis in one unit for the rows and the evaluations.
  std::vector<double> all_wall = wall_time_s;
  all_wall.insert(all_wall.end(), evaluations.wall_time_s.begin(), evaluations.wall_time_s.end());
  const std::string wall_label = wall_time_axis(all_wall).second;
  const double wall_unit = wall_label == "wall time (h)"     ? 3600.0
                           : wall_label == "wall time (min)" ? 60.0
                                                             : 1.0;
  std::vector<double> wall_time;
  for (const double value : wall_time_s) wall_time.push_back(value / wall_unit);
  std::vector<double> evaluation_wall;
  for (const double value : evaluations.wall_time_s) evaluation_wall.push_back(value / wall_unit);
  const std::vector<std::pair<std::vector<double>, std::string>> xs = {{steps, "env steps"},
                                                                       {wall_time, wall_label}};
  for (std::size_t p = 0; p < xs.size(); ++p) {
    const std::vector<double>& x = xs[p].first;
    const std::vector<double>& evaluation_x = p == 0 ? evaluations.steps : evaluation_wall;
    double x_high = 0.0;
    for (const double value : x) {
      if (finite(value)) x_high = std::max(x_high, value);
    }
    for (const double value : evaluation_x) {
      if (finite(value)) x_high = std::max(x_high, value);
    }
    if (x_high <= 0.0) x_high = 1.0;
    Panel panel;
    panel.area = cv::Rect(left_margin + static_cast<int>(p) * (panel_width + gap + left_margin),
                          top, panel_width, panel_height);
    panel.x_axis = nice_axis(0.0, x_high, 5);
    panel.y_axis = y_axis;
    panel.x_label = xs[p].second;
    panel.x_magnitude = panel.x_axis.high;
    panel.y_magnitude = y_magnitude;
    const Series series{x, mean, spread};
    draw_band(image, panel, series);
    draw_axes(image, panel);  // grid lines over the band, under the mean
    draw_mean(image, panel, series);
    draw_evaluations(image, panel, evaluation_x, evaluations);
    cv::rectangle(image, panel.area, kAxis, 1);
    if (!any_return) {
      put_text(image, "no episode has ended yet", panel.area.x + panel.area.width / 2,
               panel.area.y + panel.area.height / 2, kLabelScale, kNote, Align::kCentre);
    }
  }

  return rgb_image(image);
}

render::Image draw_comparison(const std::vector<ComparedCurve>& curves,
                              const CurvePlotOptions& options) {
  if (options.width < 400 || options.height < 250) {
    throw std::invalid_argument("draw_comparison: expected a size of at least 400x250, got " +
                                std::to_string(options.width) + "x" +
                                std::to_string(options.height));
  }
  // Distinct colours (BGR), one per curve in order, repeating past the tenth.
  const std::vector<cv::Scalar> colours = {
      {180, 100, 25}, {14, 127, 255},  {44, 160, 44},   {40, 39, 214},  {189, 103, 148},
      {75, 86, 140},  {194, 119, 227}, {127, 127, 127}, {34, 189, 188}, {207, 190, 23}};
  for (const ComparedCurve& curve : curves) {
    if (curve.x.size() != curve.wall_minutes.size() || curve.x.size() != curve.mean.size() ||
        curve.x.size() != curve.std.size()) {
      throw std::invalid_argument("draw_comparison: curve \"" + curve.label +
                                  "\" has columns of different lengths");
    }
  }
  cv::Mat image(options.height, options.width, CV_8UC3, kBackground);
  int baseline = 0;
  const int title_height = text_size("Ag", kTitleScale, 1, &baseline).height;
  const int title_y = 10 + title_height;
  put_text(image, options.title, options.width / 2, title_y, kTitleScale, kText, Align::kCentre);

  double y_low = INFINITY;
  double y_high = -INFINITY;
  for (const ComparedCurve& curve : curves) {
    for (std::size_t i = 0; i < curve.mean.size(); ++i) {
      if (!finite(curve.mean[i])) continue;
      const double s = finite(curve.std[i]) ? curve.std[i] : 0.0;
      y_low = std::min(y_low, curve.mean[i] - s);
      y_high = std::max(y_high, curve.mean[i] + s);
    }
  }
  if (!finite(y_low)) {
    y_low = 0.0;
    y_high = 1.0;
  }
  const AxisTicks y_axis = nice_axis(y_low, y_high, 5);
  const double y_magnitude = std::max(std::abs(y_axis.low), std::abs(y_axis.high));

  // The legend: rows of (colour, label) under the title.
  int legend_y = title_y + 22;
  int legend_x = 16;
  for (std::size_t c = 0; c < curves.size(); ++c) {
    const int width = 30 + text_size(curves[c].label, kTickScale, 1, &baseline).width + 18;
    if (legend_x + width > options.width - 16 && legend_x > 16) {
      legend_x = 16;
      legend_y += 18;
    }
    const cv::Scalar& colour = colours[c % colours.size()];
    cv::line(image, {legend_x, legend_y - 4}, {legend_x + 24, legend_y - 4}, colour, 2,
             cv::LINE_AA);
    put_text(image, curves[c].label, legend_x + 30, legend_y, kTickScale, kText, Align::kLeft);
    legend_x += width;
  }

  const PanelLayout layout = panel_layout(y_axis, y_magnitude, legend_y, options);
  const int left_margin = layout.left_margin;
  const int top = layout.top;
  const int gap = layout.gap;
  const int panel_width = layout.panel_width;
  const int panel_height = layout.panel_height;
  if (panel_height < 60) {
    throw std::invalid_argument("draw_comparison: too many curves for a height of " +
                                std::to_string(options.height));
  }
  for (int p = 0; p < 2; ++p) {
    double x_high = 0.0;
    for (const ComparedCurve& curve : curves) {
      for (const double value : p == 0 ? curve.x : curve.wall_minutes) {
        if (finite(value)) x_high = std::max(x_high, value);
      }
    }
    if (x_high <= 0.0) x_high = 1.0;
    Panel panel;
    panel.area = cv::Rect(left_margin + p * (panel_width + gap + left_margin), top, panel_width,
                          panel_height);
    panel.x_axis = nice_axis(0.0, x_high, 5);
    panel.y_axis = y_axis;
    panel.x_label = p == 0 ? options.x_label : "wall time (min)";
    panel.x_magnitude = panel.x_axis.high;
    panel.y_magnitude = y_magnitude;
    draw_axes(image, panel);
    for (std::size_t c = 0; c < curves.size(); ++c) {
      const ComparedCurve& curve = curves[c];
      const Series series{p == 0 ? curve.x : curve.wall_minutes, curve.mean, curve.std};
      draw_mean(image, panel, series, colours[c % colours.size()]);
    }
    cv::rectangle(image, panel.area, kAxis, 1);
  }
  return rgb_image(image);
}

void write_curve_png(const std::filesystem::path& path, const ProgressTable& progress,
                     const CurvePlotOptions& options, const EvaluationPoints& evaluations) {
  const render::Image image = draw_curve(progress, options, evaluations);
  render::write_png(path.string(), image.view());
}

}  // namespace pixelgym::trainer
