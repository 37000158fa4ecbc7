#include "pixelgym/trainer/progress_line.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace pixelgym::trainer {
namespace {

std::string format_return(double value) {
  if (!std::isfinite(value)) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.1f", value);
  return buffer;
}

std::string format_fps(double fps) {
  if (!std::isfinite(fps)) return "-";
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, fps < 10.0 ? "%.1f" : "%.0f", fps);
  return buffer;
}

}  // namespace

double progress_fraction(const ProgressStatus& status) {
  double fraction = 0.0;
  if (status.total_steps > 0) {
    fraction = static_cast<double>(status.steps) / static_cast<double>(status.total_steps);
  }
  if (status.time_limit_s > 0.0)
    fraction = std::max(fraction, status.elapsed_s / status.time_limit_s);
  return std::clamp(fraction, 0.0, 1.0);
}

double eta_seconds(const ProgressStatus& status) {
  double eta = std::nan("");
  if (status.total_steps > 0 && std::isfinite(status.fps) && status.fps > 0.0) {
    eta = static_cast<double>(std::max<std::int64_t>(0, status.total_steps - status.steps)) /
          status.fps;
  }
  if (status.time_limit_s > 0.0) {
    const double left = std::max(0.0, status.time_limit_s - status.elapsed_s);
    eta = std::isnan(eta) ? left : std::min(eta, left);
  }
  return eta;
}

std::string format_eta(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--:--";
  const auto total = static_cast<std::int64_t>(std::llround(seconds));
  const std::int64_t hours = total / 3600;
  const std::int64_t minutes = (total / 60) % 60;
  const std::int64_t secs = total % 60;
  char buffer[48];
  if (hours == 0) {
    std::snprintf(buffer, sizeof buffer, "%lld:%02lld", static_cast<long long>(minutes),
                  static_cast<long long>(secs));
  } else if (hours < 100) {
    std::snprintf(buffer, sizeof buffer, "%lld:%02lld:%02lld", static_cast<long long>(hours),
                  static_cast<long long>(minutes), static_cast<long long>(secs));
  } else {
    std::snprintf(buffer, sizeof buffer, "%lldh", static_cast<long long>(hours));
  }
  return buffer;
}

std::string format_count(std::int64_t count) {
  const double value = static_cast<double>(count);
  const double magnitude = std::abs(value);
  char buffer[32];
  if (magnitude < 1000.0) {
    std::snprintf(buffer, sizeof buffer, "%lld", static_cast<long long>(count));
    return buffer;
  }
  static constexpr const char* kSuffixes[] = {"k", "M", "G", "T"};
  double scaled = value / 1000.0;
  int index = 0;
  // Round first, so that 999950 reads "1.00M", not "1000k".
  while (index < 3 && std::abs(scaled) >= 999.5) {
    scaled /= 1000.0;
    ++index;
  }
  const double shown = std::abs(scaled);
  const char* format = shown < 9.995 ? "%.2f%s" : shown < 99.95 ? "%.1f%s" : "%.0f%s";
  std::snprintf(buffer, sizeof buffer, format, scaled, kSuffixes[index]);
  return buffer;
}

std::string format_bar(double fraction, int width) {
  if (width < 3) {
    throw std::invalid_argument("format_bar: expected a width of at least 3, got " +
                                std::to_string(width));
  }
  const int inside = width - 2;
  const double clamped = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  const int filled = static_cast<int>(std::floor(clamped * inside + 1e-9));
  return "[" + std::string(static_cast<std::size_t>(filled), '#') +
         std::string(static_cast<std::size_t>(inside - filled), '.') + "]";
}

std::string format_bar_line(const ProgressStatus& status, int columns) {
  std::string figures = format_count(status.steps);
  if (status.total_steps > 0) figures += "/" + format_count(status.total_steps);
  figures += "  " + format_fps(status.fps) + " fps  return " +
             format_return(status.episode_return_mean) + "  ETA " + format_eta(eta_seconds(status));
  const int room = columns - 1;
  const int bar_width = room - static_cast<int>(figures.size()) - 1;
  if (bar_width < 8) return figures.substr(0, static_cast<std::size_t>(std::max(room, 0)));
  return format_bar(progress_fraction(status), std::min(bar_width, 40)) + " " + figures;
}

std::string format_plain_line(const ProgressStatus& status) {
  std::string line = "steps " + std::to_string(status.steps);
  if (status.total_steps > 0) {
    char percent[32];
    std::snprintf(
        percent, sizeof percent, " (%.1f%%)",
        100.0 * static_cast<double>(status.steps) / static_cast<double>(status.total_steps));
    line += "/" + std::to_string(status.total_steps) + percent;
  }
  line += "  fps " + format_fps(status.fps) + "  return " +
          format_return(status.episode_return_mean) + "  elapsed " + format_eta(status.elapsed_s) +
          "  ETA " + format_eta(eta_seconds(status));
  return line;
}

ProgressLine::ProgressLine(std::ostream& out, Mode mode, int every_n_updates, int columns,
                           Clock clock)
    : out_(out),
      mode_(mode),
      every_n_updates_(every_n_updates),
      columns_(columns),
      clock_(std::move(clock)) {
  if (every_n_updates < 1 || columns < 20) {
    throw std::invalid_argument(
        "ProgressLine: expected every_n_updates >= 1 and columns >= 20, got " +
        std::to_string(every_n_updates) + " and " + std::to_string(columns));
  }
  if (!clock_) {
    clock_ = [] {
      return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch())
          .count();
    };
  }
  last_line_s_ = clock_();
}

ProgressLine::Mode ProgressLine::mode_for_stdout(bool quiet) {
  return !quiet && ::isatty(STDOUT_FILENO) == 1 ? Mode::kBar : Mode::kPlain;
}

int ProgressLine::stdout_columns() {
  struct winsize size {};
  if (::isatty(STDOUT_FILENO) == 1 && ::ioctl(STDOUT_FILENO, TIOCGWINSZ, &size) == 0 &&
      size.ws_col >= 20) {
    return size.ws_col;
  }
  return 100;
}

void ProgressLine::update(const ProgressStatus& status) {
  ++updates_;
  const double now = clock_();
  if (mode_ == Mode::kBar) {
    out_ << '\r' << format_bar_line(status, columns_) << "\x1b[K" << std::flush;
    last_line_s_ = now;
    bar_open_ = true;
    return;
  }
  last_written_ = updates_ % every_n_updates_ == 0 || now - last_line_s_ >= kMaxSilenceS;
  if (last_written_) {
    out_ << format_plain_line(status) << '\n' << std::flush;
    last_line_s_ = now;
  }
}

bool ProgressLine::tick(const ProgressStatus& status) {
  const double now = clock_();
  if (mode_ == Mode::kBar) {
    if (now - last_line_s_ < 1.0) return false;
    out_ << '\r' << format_bar_line(status, columns_) << "\x1b[K" << std::flush;
    last_line_s_ = now;
    bar_open_ = true;
    return true;
  }
  if (now - last_line_s_ < kMaxSilenceS) return false;
  out_ << format_plain_line(status) << '\n' << std::flush;
  last_line_s_ = now;
  last_written_ = false;  // the update's own state is still to come
  return true;
}

bool ProgressLine::tick_note(const std::string& line) {
  const double now = clock_();
  if (now - last_line_s_ < kMaxSilenceS) return false;
  if (bar_open_) out_ << '\n';
  bar_open_ = false;
  out_ << line << '\n' << std::flush;
  last_line_s_ = now;
  return true;
}

void ProgressLine::wrote_line() {
  last_line_s_ = clock_();
  bar_open_ = false;
}

void ProgressLine::finish(const ProgressStatus& status) {
  if (mode_ == Mode::kBar) {
    out_ << '\r' << format_bar_line(status, columns_) << "\x1b[K\n" << std::flush;
    last_line_s_ = clock_();
    bar_open_ = false;
    return;
  }
  if (!last_written_) out_ << format_plain_line(status) << '\n' << std::flush;
  last_written_ = true;
  last_line_s_ = clock_();
}

}  // namespace pixelgym::trainer
