// The progress line on a clock the test moves: at most one line a second on a terminal and one
// every 30 s elsewhere, the first only after that long, rewritten in place and erased at the
// end; the clock read only every few steps; and the line's text.
#include <doctest/doctest.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <vector>

#include "progress.hpp"

namespace {

using tsi::app::ProgressClock;
using tsi::app::ProgressLine;
using tsi::app::ProgressMode;
using namespace std::chrono_literals;

// A clock that moves only when the test says, counting its reads.
struct FakeClock {
  ProgressClock::time_point now{};
  long reads = 0;
  tsi::app::ProgressNow function() {
    return [this] {
      ++reads;
      return now;
    };
  }
  void advance(std::chrono::nanoseconds d) { now += std::chrono::duration_cast<ProgressClock::duration>(d); }
};

// What a line wrote, one entry per write.
struct Capture {
  std::vector<std::string> writes;
  ProgressLine::Sink sink() {
    return [this](std::string_view text) { writes.emplace_back(text); };
  }
};

// Offers a line every `every` for `span` of fake time; returns the seconds (since the line was
// made) of the offers that were shown.
std::vector<double> offer_for(ProgressLine& line, FakeClock& clock, std::chrono::milliseconds every,
                              std::chrono::seconds span) {
  const auto start = clock.now;
  std::vector<double> shown;
  while (clock.now - start < span) {
    clock.advance(every);
    if (line.offer(clock.now, "x")) shown.push_back(std::chrono::duration<double>(clock.now - start).count());
  }
  return shown;
}

}  // namespace

TEST_SUITE("tsi_app_tests") {

TEST_CASE("progress: on a terminal, at most one line a second, the first after a second") {
  FakeClock clock;
  Capture out;
  ProgressLine line(ProgressMode::terminal, out.sink(), clock.function());
  const std::vector<double> shown = offer_for(line, clock, 10ms, 10s);  // 1000 offers
  REQUIRE(shown.size() == 10);  // at 1, 2, ..., 10 s: none in the first second
  CHECK(shown.front() == doctest::Approx(1.0));
  for (size_t k = 1; k < shown.size(); ++k) CHECK(shown[k] - shown[k - 1] >= 1.0 - 1e-12);
  for (const auto& w : out.writes) {
    CHECK(w.front() == '\r');  // rewritten in place
    CHECK(w.find('\n') == std::string::npos);
  }
}

TEST_CASE("progress: off a terminal, a plain line at most every 30 s, and nothing when off") {
  FakeClock clock;
  Capture out;
  ProgressLine line(ProgressMode::plain, out.sink(), clock.function());
  const std::vector<double> shown = offer_for(line, clock, 1000ms, 100s);
  REQUIRE(shown.size() == 3);  // at 30, 60 and 90 s
  CHECK(shown[0] == doctest::Approx(30.0));
  CHECK(shown[2] == doctest::Approx(90.0));
  for (const auto& w : out.writes) {
    CHECK(w == "tsi: x\n");
    CHECK(w.find('\r') == std::string::npos);
  }
  line.finish();
  CHECK(out.writes.size() == 3);  // a plain line has nothing to erase

  Capture quiet;
  ProgressLine off(ProgressMode::off, quiet.sink(), clock.function());
  CHECK(offer_for(off, clock, 1000ms, 100s).empty());
  off.finish();
  CHECK(quiet.writes.empty());
  CHECK(tsi::app::progress_mode(true, true) == ProgressMode::off);
  CHECK(tsi::app::progress_mode(false, true) == ProgressMode::terminal);
  CHECK(tsi::app::progress_mode(false, false) == ProgressMode::plain);
}

TEST_CASE("progress: a terminal line covers a longer previous one, is cut to the width, and is erased at the end") {
  FakeClock clock;
  Capture out;
  {
    ProgressLine line(ProgressMode::terminal, out.sink(), clock.function());
    clock.advance(1s);
    REQUIRE(line.offer(clock.now, "abcdef"));
    clock.advance(1s);
    REQUIRE(line.offer(clock.now, "xy"));
    CHECK(out.writes[1] == "\rxy    ");  // four spaces over "cdef"
    clock.advance(1s);
    REQUIRE(line.offer(clock.now, std::string(200, 'z')));
    CHECK(out.writes[2] == "\r" + std::string(ProgressLine::width, 'z'));
    line.finish();
    CHECK(out.writes[3] == "\r" + std::string(ProgressLine::width, ' ') + "\r");
    line.finish();  // nothing shown since: nothing to erase
    CHECK(out.writes.size() == 4);
    clock.advance(1s);
    REQUIRE(line.offer(clock.now, "again"));
  }  // the destructor erases what is shown
  CHECK(out.writes.back() == "\r     \r");
}

TEST_CASE("progress: a step reads the clock only every few steps, and at once again when steps slow down") {
  FakeClock clock;
  tsi::app::SteppedClock stepped(clock.function());
  const long fast_steps = 100000;  // steps of 100 us
  long reads = 0;
  for (long n = 0; n < fast_steps; ++n) {
    if (stepped.tick()) ++reads;
    clock.advance(100us);
  }
  CHECK(reads == clock.reads);
  // The stride doubles while reads come less than 2 ms apart: 32 steps (3.2 ms) a read.
  CHECK(stepped.stride() == 32);
  CHECK(reads < fast_steps / 16);
  CHECK(reads > fast_steps / 64);
  // Steps of 300 ms: the next read comes within the stride, and from then on every step reads.
  long steps_to_first = 0;
  while (!stepped.tick()) {
    clock.advance(300ms);
    ++steps_to_first;
  }
  CHECK(steps_to_first < 32);
  clock.advance(300ms);
  long later_reads = 0;
  for (int n = 0; n < 10; ++n, clock.advance(300ms))
    if (stepped.tick()) ++later_reads;
  CHECK(stepped.stride() == 1);
  CHECK(later_reads >= 9);  // the first may still count down a stride shrunk to what 10 ms took
}

TEST_CASE("progress: a run's line at most once a second, and a new phase with its own rate") {
  FakeClock clock;
  Capture out;
  ProgressLine line(ProgressMode::terminal, out.sink(), clock.function());
  tsi::app::StepProgressLine progress(line);
  // Called every 5 ms (as a run's loop calls it, when its SteppedClock reads) for 10 s: 50
  // steps of 100 us each time, t advancing 0.001 a step.
  const long steps = 100000;
  for (long n = 0; n <= steps; n += 50) {
    progress({"run", n, steps, 0.001 * static_cast<double>(n), 100.0});
    clock.advance(5ms);
  }
  // About one line a second, and never more: 9 or 10 in 10 s (the first after one second).
  CHECK(out.writes.size() >= 9);
  CHECK(out.writes.size() <= 10);
  // Its text: t advances 0.05 each 5 ms, 10 a second.
  CHECK(out.writes.back().find("\rrun: step ") == 0);
  CHECK(out.writes.back().find(", 10/s,") != std::string::npos);

  // A reference whose steps take 0.3 s each: its first line within a second and a step, with
  // its own rate (0.1 per 0.3 s), at most one a second.
  const size_t lines_before = out.writes.size();
  for (long n = 0; n <= 10; ++n) {
    progress({"reference", n, 10, 0.1 * static_cast<double>(n), 1.0});
    clock.advance(300ms);
  }
  REQUIRE(out.writes.size() > lines_before);
  CHECK(out.writes[lines_before].find("\rreference: step ") == 0);
  CHECK(out.writes.size() - lines_before <= 4);  // 3.3 s of reference
  CHECK(out.writes.back().find(", 0.333/s,") != std::string::npos);
}

TEST_CASE("progress: the run and study lines say where they are, their rate and the time left") {
  using tsi::app::duration_text;
  CHECK(duration_text(59.4) == "59 s");
  CHECK(duration_text(185.0) == "3 min 05 s");
  CHECK(duration_text(7440.0) == "2 h 04 min");
  CHECK(duration_text(-1.0) == "?");

  // 1200 of 4000 steps in 20 s: t advances 3 / 20 = 0.15 a second; 2800 steps left at 60 a second.
  CHECK(tsi::app::step_progress_text({"run", 1200, 4000, 3.0, 10.0}, 20.0) ==
        "run: step 1200/4000 (30.0%), t = 3 of 10, 0.15/s, about 47 s left");
  // No step yet: no rate, no time left.
  CHECK(tsi::app::step_progress_text({"run", 0, 4000, 0.0, 10.0}, 0.5) == "run: step 0/4000 (0.0%), t = 0 of 10");
  // A phase from step 100 at t = 1: its own rate, 100 steps in 10 s.
  CHECK(tsi::app::step_progress_text({"reference", 200, 400, 2.0, 4.0}, 10.0, 100, 1.0) ==
        "reference: step 200/400 (50.0%), t = 2 of 4, 0.1/s, about 20 s left");

  // 3 of 12 done and two under way at a quarter each: 3.5 done in 12 s, 8.5 to go.
  tsi::app::StudyProgress p{3, 12, 2, 0.5, "r0004", 0.25};
  CHECK(tsi::app::study_progress_text(p, 12.0) ==
        "study: 3/12 done, r0004 at 25% (+1 running), 12 s elapsed, about 29 s left");
  p = {0, 4, 0, 0.0, "", 0.0};
  CHECK(tsi::app::study_progress_text(p, 2.0) == "study: 0/4 done, 2 s elapsed");
}

}  // TEST_SUITE
