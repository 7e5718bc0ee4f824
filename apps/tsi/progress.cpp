#include "progress.hpp"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace tsi::app {

ProgressMode progress_mode(bool quiet, bool is_terminal) {
  if (quiet) return ProgressMode::off;
  return is_terminal ? ProgressMode::terminal : ProgressMode::plain;
}

ProgressMode stderr_progress_mode(bool quiet) { return progress_mode(quiet, isatty(fileno(stderr)) != 0); }

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0.0) return "?";
  const long s = std::lround(seconds);
  if (s < 60) return fmt::format("{} s", s);
  if (s < 3600) return fmt::format("{} min {:02} s", s / 60, s % 60);
  if (s < 100 * 3600) return fmt::format("{} h {:02} min", s / 3600, (s % 3600) / 60);
  return fmt::format("{} h", s / 3600);
}

std::string step_progress_text(const StepProgress& p, double seconds, long from_step, double from_t) {
  std::string s = fmt::format("{}: step {}/{}", p.what, p.step, p.steps);
  if (p.steps > 0) s += fmt::format(" ({:.1f}%)", 100.0 * static_cast<double>(p.step) / static_cast<double>(p.steps));
  s += fmt::format(", t = {:.4g} of {:.4g}", p.t, p.t_end);
  const long steps_done = p.step - from_step;
  if (seconds > 0.0 && steps_done > 0) {
    // Simulated time per wall second, and the phase's time left at its rate so far.
    s += fmt::format(", {:.3g}/s", (p.t - from_t) / seconds);
    s += fmt::format(", about {} left",
                     duration_text(seconds * static_cast<double>(p.steps - p.step) / static_cast<double>(steps_done)));
  }
  return s;
}

std::string study_progress_text(const StudyProgress& p, double seconds) {
  std::string s = fmt::format("study: {}/{} done", p.done, p.total);
  if (p.running > 0 && !p.current.empty()) {
    s += fmt::format(", {} at {:.0f}%", p.current, 100.0 * p.current_fraction);
    if (p.running > 1) s += fmt::format(" (+{} running)", p.running - 1);
  }
  s += fmt::format(", {} elapsed", duration_text(seconds));
  // Runs finished count whole, runs under way by their fraction done.
  const double done = static_cast<double>(p.done) + p.running_done;
  if (done > 0.0 && seconds > 0.0)
    s += fmt::format(", about {} left", duration_text(seconds * (static_cast<double>(p.total) - done) / done));
  return s;
}

// --- ProgressLine -------------------------------------------------------------------------------

ProgressLine::ProgressLine(ProgressMode mode, Sink sink, ProgressNow now)
    : mode_(mode),
      sink_(sink ? std::move(sink)
                 : Sink([](std::string_view text) {
                     std::fwrite(text.data(), 1, text.size(), stderr);
                     std::fflush(stderr);
                   })),
      now_(now ? std::move(now) : ProgressNow(&ProgressClock::now)),
      started_(now_()),
      last_shown_(started_) {}

ProgressLine::~ProgressLine() {
  try {
    finish();
  } catch (...) {  // a sink that fails (Python's stderr gone) does not end the process
  }
}

double ProgressLine::elapsed(ProgressClock::time_point now) const {
  return std::chrono::duration<double>(now - started_).count();
}

bool ProgressLine::due(ProgressClock::time_point now) const {
  switch (mode_) {
    case ProgressMode::off:
      return false;
    case ProgressMode::terminal:
      return now - last_shown_ >= terminal_interval;
    case ProgressMode::plain:
      return now - last_shown_ >= plain_interval;
  }
  return false;
}

bool ProgressLine::offer(ProgressClock::time_point now, std::string_view text) {
  if (!due(now)) return false;
  last_shown_ = now;
  if (mode_ == ProgressMode::plain) {
    sink_(fmt::format("tsi: {}\n", text));
    return true;
  }
  text = text.substr(0, std::min(text.size(), width));
  // Spaces over what the previous line showed beyond this one.
  const std::size_t pad = shown_width_ > text.size() ? shown_width_ - text.size() : 0;
  sink_(fmt::format("\r{}{:{}}", text, "", pad));
  shown_width_ = text.size();
  return true;
}

void ProgressLine::finish() {
  if (mode_ != ProgressMode::terminal || shown_width_ == 0) return;
  sink_(fmt::format("\r{:{}}\r", "", shown_width_));
  shown_width_ = 0;
}

// --- SteppedClock -------------------------------------------------------------------------------

SteppedClock::SteppedClock(ProgressNow now) : now_(now ? std::move(now) : ProgressNow(&ProgressClock::now)) {}

ProgressClock::time_point SteppedClock::read() {
  const auto now = now_();
  if (last_) {
    const auto gap = now - *last_;
    if (gap < std::chrono::milliseconds(2) && stride_ < max_stride) {
      stride_ *= 2;
    } else if (gap > std::chrono::milliseconds(50) && stride_ > 1) {  // steps slowed down: 10 ms apart again
      const double scaled = static_cast<double>(stride_) * 0.01 / std::chrono::duration<double>(gap).count();
      stride_ = std::max(1L, static_cast<long>(scaled));
    }
  }
  last_ = now;
  countdown_ = stride_;
  return now;
}

// --- StepProgressLine ---------------------------------------------------------------------------

void StepProgressLine::operator()(const StepProgress& p) {
  const auto now = line_.now();
  if (phase_ != p.what) {  // a new phase: its rate and time left from here
    phase_ = p.what;
    phase_start_ = now;
    from_step_ = p.step;
    from_t_ = p.t;
  }
  if (!line_.due(now)) return;
  line_.offer(now, step_progress_text(p, std::chrono::duration<double>(now - phase_start_).count(), from_step_, from_t_));
}

}  // namespace tsi::app
