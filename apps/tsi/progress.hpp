#pragma once
// The progress line of `tsi run` and `tsi study` (and of tsi.run / tsi.study with progress=True):
// on a terminal one line rewritten in place ('\r') at most once a second; elsewhere (a log
// file) a plain line at most every 30 s; nothing with --quiet. The clock is injectable, so that
// the throttling is tested without sleeping.
#include <chrono>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

namespace tsi::app {

/// How a progress line is drawn, and how often.
enum class ProgressMode {
  off,       ///< --quiet (and every rank but 0)
  terminal,  ///< one line rewritten in place with '\r', at most once a second
  plain,     ///< a line of its own, at most every 30 s
};

/// The mode for a stream: off when `quiet`, terminal when the stream is one, else plain.
ProgressMode progress_mode(bool quiet, bool is_terminal);

/// The mode for stderr (isatty) under --quiet or not.
ProgressMode stderr_progress_mode(bool quiet);

using ProgressClock = std::chrono::steady_clock;
/// What a progress line reads the time from (ProgressClock::now unless a test gives its own).
using ProgressNow = std::function<ProgressClock::time_point()>;

/// Where a run (or its reference, or the error estimate's runs at other steps) is, given to
/// its progress function after every step (step 0 first).
struct StepProgress {
  const char* what = "run";  ///< "run", "reference", "reference check", "error estimate (h / 2)", ...
  long step = 0;
  long steps = 0;  ///< in all (for an adaptive reference: its chunks)
  double t = 0.0;
  double t_end = 0.0;
};

/// Where a study is: its units of work are its distinct references and its runs.
struct StudyProgress {
  std::size_t done = 0, total = 0;  ///< units finished, and in all
  std::size_t running = 0;          ///< units being computed now
  double running_done = 0.0;        ///< the sum of their fractions done (for the time left)
  std::string current;              ///< the unit last started or advanced: a run's id, or "reference"
  double current_fraction = 0.0;    ///< its fraction done
};

/// "47 s", "3 min 05 s", "2 h 04 min": a duration as a person reads it.
std::string duration_text(double seconds);

/// "run: step 1200/4000 (30%), t = 3 of 10, 0.152 per s, about 47 s left": `seconds` since
/// the phase started at step `from_step`, time `from_t` (its rate and time left are its own).
std::string step_progress_text(const StepProgress& p, double seconds, long from_step = 0, double from_t = 0.0);

/// "study: 3/12 done, r0004 at 45% (+1 running), 12 s elapsed, about 36 s left".
std::string study_progress_text(const StudyProgress& p, double seconds);

/// One progress line, throttled: a line offered is shown only when the interval of its mode
/// has passed since the last one shown (since the line was made, for the first: a short run
/// shows none). Not thread safe: callers from several threads hold a lock.
class ProgressLine {
 public:
  using Sink = std::function<void(std::string_view)>;
  static constexpr std::chrono::seconds terminal_interval{1};
  static constexpr std::chrono::seconds plain_interval{30};
  /// A terminal line is cut to this many characters: a line that wraps cannot be rewritten.
  static constexpr std::size_t width = 79;

  /// `sink` receives the text to write (default: stderr, flushed); `now` the clock.
  explicit ProgressLine(ProgressMode mode, Sink sink = {}, ProgressNow now = {});
  ~ProgressLine();  ///< finish()
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  ProgressMode mode() const { return mode_; }
  bool enabled() const { return mode_ != ProgressMode::off; }
  ProgressClock::time_point now() const { return now_(); }
  /// Seconds since the line was made.
  double elapsed(ProgressClock::time_point now) const;
  /// Whether a line offered at `now` would be shown.
  bool due(ProgressClock::time_point now) const;
  /// Shows `text` when due: on a terminal '\r', the text (cut to width) and spaces over the
  /// rest of the previous line; otherwise "tsi: " text and a newline. Returns whether shown.
  bool offer(ProgressClock::time_point now, std::string_view text);
  /// Ends the line before other output: on a terminal the line shown is erased and the cursor
  /// put back at its start; nothing to do otherwise. A later offer starts afresh.
  void finish();

 private:
  ProgressMode mode_;
  Sink sink_;
  ProgressNow now_;
  ProgressClock::time_point started_, last_shown_;
  std::size_t shown_width_ = 0;  ///< what a terminal line now shows (0: nothing)
};

/// A clock read only every few calls, so that a step pays a decrement and a compare: the
/// stride doubles while reads come less than 2 ms apart (up to max_stride), and when they come
/// more than 50 ms apart it shrinks at once to what would have read 10 ms apart. A run's loop
/// calls its progress function when it reads.
class SteppedClock {
 public:
  static constexpr long max_stride = 1024;
  explicit SteppedClock(ProgressNow now = {});
  /// Called every step: the time on every stride-th call, else nothing.
  std::optional<ProgressClock::time_point> tick() {
    if (--countdown_ > 0) return std::nullopt;
    return read();
  }
  long stride() const { return stride_; }

 private:
  ProgressClock::time_point read();
  ProgressNow now_;
  long countdown_ = 1, stride_ = 1;
  std::optional<ProgressClock::time_point> last_;
};

/// A run's progress on a ProgressLine (a ProgressFn, called every few steps, from the first):
/// each phase ("run", "reference", ...) has its own rate and time left, from its first call.
class StepProgressLine {
 public:
  explicit StepProgressLine(ProgressLine& line) : line_(line) {}
  void operator()(const StepProgress& p);

 private:
  ProgressLine& line_;
  std::string phase_;
  ProgressClock::time_point phase_start_;
  long from_step_ = 0;
  double from_t_ = 0.0;
};

}  // namespace tsi::app
