// The trainer's progress on the terminal: a bar redrawn in place on a TTY, plain lines otherwise.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <ostream>
#include <string>

namespace pixelgym::trainer {

/// Where training stands, for the progress line.
struct ProgressStatus {
  static constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
  std::int64_t steps = 0;
  std::int64_t total_steps = 0;  // the step budget; 0: none
  double elapsed_s = 0.0;
  double time_limit_s = 0.0;           // the wall-time budget in seconds; 0: none
  double fps = kNone;                  // recent env steps per second
  double episode_return_mean = kNone;  // NaN before the first episode ends
};

/// How far along training is, in [0, 1]: the larger of steps / total_steps and
/// elapsed_s / time_limit_s (whichever budget ends training first); 0 with neither budget.
double progress_fraction(const ProgressStatus& status);

/// Seconds until the first budget runs out: the remaining steps at `fps`, or the remaining wall
/// time, whichever is less. NaN when unknown (no budget, or a step budget only and no fps yet).
double eta_seconds(const ProgressStatus& status);

/// A duration as "m:ss" under an hour ("0:07", "12:05"), "h:mm:ss" under 100 hours ("1:02:03"),
/// whole hours beyond ("123h"); "--:--" for NaN, infinite or negative.
std::string format_eta(double seconds);

/// A count in at most about 5 characters: 999, "12.3k", "100k", "1.23M", "12.3M".
std::string format_count(std::int64_t count);

/// A bar of exactly `width` characters (at least 3): "[####......]", the inside filled in
/// proportion to `fraction` (clamped to [0, 1]). Throws std::invalid_argument for width < 3.
std::string format_bar(double fraction, int width);

/// The terminal line: "[#####.....] 12.3k/100k  345 fps  return 123.4  ETA 4:05", at most
/// `columns` - 1 characters (no wrap): the bar takes the room the figures leave, and is left out
/// below 8 characters.
std::string format_bar_line(const ProgressStatus& status, int columns);

/// The plain line (no newline): "steps 12288/100000 (12.3%)  fps 345  return 123.4  elapsed
/// 0:36  ETA 4:05".
std::string format_plain_line(const ProgressStatus& status);

/// Writes the progress to a stream once per update, and within updates so that a reader of a
/// pipe never waits long: a plain line at least every kMaxSilenceS seconds.
class ProgressLine {
 public:
  enum class Mode {
    kBar,    // redraw one line in place ('\r', then erase to the end of the line)
    kPlain,  // a plain line every `every_n_updates` updates, or kMaxSilenceS after the last line
  };

  /// The most seconds between two lines in kPlain while updates, evaluations or ticks go on (the
  /// promise is a line at least every 10 s; ticks come between small steps, so the slack covers
  /// the longest step).
  static constexpr double kMaxSilenceS = 6.0;
  /// Seconds on a monotonic clock (steady_clock when absent).
  using Clock = std::function<double()>;

  /// Throws std::invalid_argument for every_n_updates < 1 or columns < 20.
  ProgressLine(std::ostream& out, Mode mode, int every_n_updates, int columns = 100,
               Clock clock = {});

  /// kBar when stdout is a terminal and not `quiet`, else kPlain.
  static Mode mode_for_stdout(bool quiet);
  /// The width of the terminal on stdout, or 100 when it is not one.
  static int stdout_columns();

  /// Reports one update (flushes what it writes): kPlain writes the line every every_n_updates
  /// updates, or when kMaxSilenceS passed since the last line.
  void update(const ProgressStatus& status);
  /// Reports progress within an update (call it often): kPlain writes the line when
  /// kMaxSilenceS passed since the last line, kBar redraws the bar at most once a second.
  /// Returns whether it wrote.
  bool tick(const ProgressStatus& status);
  /// Writes `line` (and a newline) when kMaxSilenceS passed since the last line: progress of
  /// work that is not training (an evaluation). Returns whether it wrote.
  bool tick_note(const std::string& line);
  /// Says that the caller wrote a line of its own to the stream (the silence starts again).
  void wrote_line();
  /// Reports the end: the bar's last state and a newline, or the final plain line (unless the
  /// last update wrote that state already).
  void finish(const ProgressStatus& status);

 private:
  std::ostream& out_;
  Mode mode_;
  int every_n_updates_;
  int columns_;
  Clock clock_;
  double last_line_s_ = 0.0;  // when the last line was written (or the bar drawn)
  std::int64_t updates_ = 0;
  bool last_written_ = false;  // the last update or tick wrote a plain line of the latest state
  bool bar_open_ = false;      // kBar: the bar is drawn and its line not ended
};

}  // namespace pixelgym::trainer
