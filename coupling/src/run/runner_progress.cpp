// The progress line of `frictherm run` (stderr, terminals only).
#include "run/runner_detail.hpp"

#include <cmath>
#include <cstdio>

namespace frictherm::coupling::detail {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "--:--";
  const long s = static_cast<long>(std::lround(seconds));
  char buf[32];
  if (s >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    std::snprintf(buf, sizeof buf, "%02ld:%02ld", s / 60, s % 60);
  return buf;
}

ProgressLine::ProgressLine(std::ostream& out, bool enabled, double end_time)
    : out_(out), enabled_(enabled), end_time_(end_time), start_(Clock::now()), last_draw_(start_) {}

ProgressLine::~ProgressLine() { finish(); }

void ProgressLine::update(long step, double time) {
  if (!enabled_) return;
  const Clock::time_point now = Clock::now();
  const double since_draw = std::chrono::duration<double>(now - last_draw_).count();
  if (since_draw < 0.25) return;
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  const double rate = static_cast<double>(step - last_step_) / since_draw;
  const double fraction = end_time_ > 0.0 ? time / end_time_ : 0.0;
  const double eta = fraction > 0.0 ? elapsed * (1.0 - fraction) / fraction : -1.0;
  char line[160];
  const int n = std::snprintf(line, sizeof line, "step %ld  t = %.4g s  (%.1f %%)  %.0f steps/s  ETA %s", step, time,
                              100.0 * fraction, rate, format_duration(eta).c_str());
  const std::size_t len = n > 0 ? static_cast<std::size_t>(n) : 0;
  out_ << '\r' << line;
  if (len < width_) out_ << std::string(width_ - len, ' ');
  out_.flush();
  width_ = len;
  last_draw_ = now;
  last_step_ = step;
}

void ProgressLine::message(std::ostream& log, const std::string& line) {
  if (enabled_ && width_ > 0 && &log == &out_) {
    out_ << '\r' << std::string(width_, ' ') << '\r';
    width_ = 0;
  }
  log << line << '\n' << std::flush;
}

void ProgressLine::finish() {
  if (!enabled_) return;
  if (width_ > 0) out_ << '\r' << std::string(width_, ' ') << '\r' << std::flush;
  enabled_ = false;
}

}  // namespace frictherm::coupling::detail
