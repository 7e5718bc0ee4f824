// `tsi run --dry-run` and `tsi study --dry-run` (checked as a run is, summarised, nothing
// written), the progress line on a terminal and off one (--quiet: none), and -h / --help.
#include <doctest/doctest.h>
#include <fcntl.h>
#include <fmt/format.h>
#include <poll.h>
#include <pty.h>
#include <sys/wait.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <csignal>
#include <sstream>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace {

using namespace tsi::test;

// The entries of a directory, by name.
std::vector<std::string> entries(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  return names;
}

// The line of `text` that starts with `start` (after spaces), split at spaces; empty if none.
std::vector<std::string> row_starting(const std::string& text, const std::string& start) {
  for (const auto& line : lines_of(text)) {
    std::istringstream s(line);
    std::vector<std::string> words;
    for (std::string w; s >> w;) words.push_back(w);
    if (!words.empty() && words.front() == start) return words;
  }
  return {};
}

// A run of about 100 s of work (as the interrupt tests'): long enough for a progress line.
Json long_config() {
  return {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 64}}},
          {"scheme", {{"name", "se1"}}},
          {"time", {{"h", 0.01}, {"t_end", 1000.0}}}};
}

struct TerminalResult {
  int exit_code = -1;
  std::string text;  // everything written to the terminal (stdout and stderr)
};

// Runs tsi with stdout and stderr on a pseudo-terminal (output post-processing off, so that a
// '\r' is only what tsi wrote), and sends SIGINT once `stop_at` appears in what it wrote or
// `seconds` have passed.
TerminalResult run_on_terminal(const std::vector<std::string>& args, const std::string& stop_at, double seconds) {
  int master = -1, slave = -1;
  REQUIRE(::openpty(&master, &slave, nullptr, nullptr, nullptr) == 0);
  termios mode{};
  REQUIRE(::tcgetattr(slave, &mode) == 0);
  mode.c_oflag &= ~static_cast<tcflag_t>(OPOST);  // no "\n" -> "\r\n"
  REQUIRE(::tcsetattr(slave, TCSANOW, &mode) == 0);

  std::vector<std::string> argv_strings = {TSI_TEST_RUNNER};
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = detail::child_environment({});
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  const pid_t pid = ::fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {  // async-signal-safe calls only
    const int in = ::open("/dev/null", O_RDONLY);
    if (in < 0 || ::dup2(in, STDIN_FILENO) < 0 || ::dup2(slave, STDOUT_FILENO) < 0 || ::dup2(slave, STDERR_FILENO) < 0)
      ::_exit(127);
    ::close(master);
    ::close(slave);
    ::execve(argv[0], argv.data(), envp.data());
    ::_exit(127);
  }
  ::close(slave);
  TerminalResult result;
  const auto started = std::chrono::steady_clock::now();
  bool signalled = false;
  char buffer[4096];
  for (;;) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    if (!signalled && (elapsed >= seconds || (!stop_at.empty() && contains(result.text, stop_at)))) {
      ::kill(pid, SIGINT);
      signalled = true;
    }
    if (elapsed > seconds + 60.0) ::kill(pid, SIGKILL);  // a hung child fails the test, not the suite
    pollfd p{master, POLLIN, 0};
    if (::poll(&p, 1, 20) < 0) continue;
    if (p.revents == 0) continue;
    const ssize_t n = ::read(master, buffer, sizeof buffer);
    if (n <= 0) break;  // EIO: the child and its terminal are gone
    result.text.append(buffer, static_cast<size_t>(n));
  }
  ::close(master);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("dry run: a run is checked and summarised, t_end / h steps, and nothing is written") {
  TempDir dir;
  Json config = small_config();
  config["time"] = {{"h", 0.01}, {"t_end", 2.0}};
  const std::string file = write_config(dir, config);
  const long steps = std::lround(2.0 / 0.01);

  const CommandResult r = run_tsi({"run", file, "--out", dir / "out", "--dry-run"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(contains(r.out, fmt::format("t_end = 2, h = 0.01: {} steps", steps)));
  CHECK(contains(r.out, "henon-heiles (eps = 0.1"));
  CHECK(contains(r.out, "two-scale ("));
  CHECK(contains(r.out, "n_tau = 16"));
  CHECK(contains(r.out, "se1 ("));
  CHECK(contains(r.out, "memory"));
  CHECK(contains(r.out, "nothing was run or written"));
  CHECK(r.err.empty());
  CHECK(!fs::exists(dir.path() / "out"));
  CHECK(entries(dir.path()) == std::vector<std::string>{"config.json"});

  // Without --out, the default out/<name> is not made either.
  const CommandResult here = run_tsi({"run", file, "--dry-run"}, {}, dir.path().string());
  INFO(here.describe());
  CHECK(here.exit_code == 0);
  CHECK(entries(dir.path()) == std::vector<std::string>{"config.json"});

  // A reference and a Richardson estimate: their work is said too.
  const CommandResult ref = run_tsi({"run", example_config(), "--out", dir / "out2", "--dry-run", "--set",
                                     "output.error_estimate=\"richardson\""});
  INFO(ref.describe());
  CHECK(ref.exit_code == 0);
  CHECK(contains(ref.out, "rk78 on filtered"));
  CHECK(contains(ref.out, "at least"));
  // t_end = 1, h = 0.125: 8 steps; the estimate reruns at h / 2 and 2 h: 16 + 4 = 20.
  CHECK(contains(ref.out, ": 8 steps"));
  CHECK(contains(ref.out, "Richardson: 20 more steps"));
  CHECK(!fs::exists(dir.path() / "out2"));
}

TEST_CASE("dry run: bad input is refused as the run refuses it, exit code 2 naming the field") {
  TempDir dir;
  struct Case {
    const char* field;
    Json config;
  };
  Json not_whole = small_config();
  not_whole["time"]["h"] = 0.3;  // t_end = 1 is not a whole number of steps
  Json unknown = small_config();
  unknown["scheme"]["bogus"] = 1;
  Json late_time = small_config();  // checked when the run is built, after the config resolves
  late_time["output"] = {{"times", {0.5, 5.0}}};
  for (const auto& c : {Case{"time.h", not_whole}, Case{"scheme.bogus", unknown}, Case{"output.times[1]", late_time}}) {
    CAPTURE(c.field);
    const std::string file = write_config(dir, c.config);
    const CommandResult dry = run_tsi({"run", file, "--out", dir / "out", "--dry-run"});
    INFO(dry.describe());
    CHECK(dry.exit_code == 2);
    CHECK(contains(dry.err, c.field));
    CHECK(!contains(dry.out, "dry run"));
    CHECK(!fs::exists(dir.path() / "out"));
    const CommandResult real = run_tsi({"run", file, "--out", dir / "real"});
    CHECK(real.exit_code == 2);
    CHECK(real.err == dry.err);  // the same message
    fs::remove_all(dir.path() / "real");
  }
}

TEST_CASE("dry run: a study lists each run's steps and the total, and writes nothing") {
  TempDir dir;
  const Json spec = {{"kind", "convergence"}, {"base", small_config()}, {"vary", {{"time.h", {0.25, 0.125, 0.0625}}}}};
  const std::string file = write_config(dir, spec, "study.json");
  const CommandResult r = run_tsi({"study", file, "--out", dir / "out", "--dry-run", "--no-plots"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(contains(r.out, "3 runs"));
  // t_end = 1: 4, 8 and 16 steps.
  const double hs[] = {0.25, 0.125, 0.0625};
  long total = 0;
  for (int k = 0; k < 3; ++k) {
    const std::vector<std::string> row = row_starting(r.out, fmt::format("r000{}", k + 1));
    REQUIRE(row.size() >= 3);
    CHECK(row[1] == fmt::format("h={}", hs[k]));
    CHECK(row[2] == std::to_string(std::lround(1.0 / hs[k])));
    total += std::lround(1.0 / hs[k]);
  }
  CHECK(contains(r.out, fmt::format("total: 3 runs, {} steps", total)));
  CHECK(!fs::exists(dir.path() / "out"));
  CHECK(entries(dir.path()) == std::vector<std::string>{"study.json"});

  // A bad value is refused before anything, as the study refuses it.
  const Json bad = {{"kind", "convergence"}, {"base", small_config()}, {"vary", {{"time.h", {0.25, 0.3}}}}};
  const std::string bad_file = write_config(dir, bad, "bad.json");
  const CommandResult refused = run_tsi({"study", bad_file, "--out", dir / "out", "--dry-run"});
  INFO(refused.describe());
  CHECK(refused.exit_code == 2);
  CHECK(contains(refused.err, "time.h"));
  CHECK(!fs::exists(dir.path() / "out"));
  CHECK(run_tsi({"study", "--merge", dir / "a", "--out", dir / "out", "--dry-run"}).exit_code == 2);
}

TEST_CASE("progress: one line rewritten in place on a terminal, none with --quiet or off a terminal") {
  TempDir dir;
  const std::string file = write_config(dir, long_config());
  // On a terminal: a line within about a second, rewritten with '\r', erased before the summary.
  const TerminalResult tty = run_on_terminal({"run", file, "--out", dir / "tty"}, "\rrun: step ", 20.0);
  INFO(tty.text);
  CHECK(tty.exit_code == 128 + SIGINT);
  const auto line = tty.text.find("\rrun: step ");
  REQUIRE(line != std::string::npos);
  CHECK(contains(tty.text.substr(line), "/100000 ("));  // of t_end / h steps
  CHECK(contains(tty.text.substr(line), "/s, about "));
  const auto erased = tty.text.rfind('\r');
  REQUIRE(erased != std::string::npos);
  CHECK(tty.text.substr(erased - 1, 2) == " \r");  // the last '\r' ends the erasing spaces
  CHECK(contains(tty.text.substr(erased), "interrupted"));  // what follows starts on a clean line

  // --quiet: nothing of the kind, over two seconds of steps.
  const TerminalResult quiet = run_on_terminal({"run", file, "--out", dir / "quiet", "--quiet"}, "", 2.0);
  INFO(quiet.text);
  CHECK(quiet.exit_code == 128 + SIGINT);
  CHECK(!contains(quiet.text, "\r"));
  CHECK(!contains(quiet.text, "run: step"));

  // Off a terminal (a pipe): no '\r' (a plain line comes only every 30 s).
  CommandEnv env;
  env.send_signal = SIGINT;
  env.signal_after_seconds = 1.5;
  const CommandResult piped = run_tsi({"run", file, "--out", dir / "piped"}, env);
  INFO(piped.describe());
  CHECK(piped.exit_code == 128 + SIGINT);
  CHECK(!contains(piped.err, "\r"));
  CHECK(!contains(piped.out, "\r"));
}

TEST_CASE("help: -h the short help and --help the long one, both on stdout with exit code 0") {
  for (const std::vector<std::string>& command : {std::vector<std::string>{}, {"run"}, {"study"}}) {
    CAPTURE(command.size() ? command[0] : "tsi");
    std::vector<std::string> short_args = command, long_args = command;
    short_args.push_back("-h");
    long_args.push_back("--help");
    const CommandResult brief = run_tsi(short_args), full = run_tsi(long_args);
    INFO(brief.describe());
    INFO(full.describe());
    CHECK(brief.exit_code == 0);
    CHECK(full.exit_code == 0);
    CHECK(brief.err.empty());
    CHECK(full.err.empty());
    CHECK(contains(brief.out, "--help"));
    CHECK(!contains(brief.out, "Exit codes"));
    CHECK(contains(full.out, "Exit codes"));
    CHECK(contains(full.out, "Examples"));
    CHECK(full.out.size() > brief.out.size());
    if (!command.empty()) {
      CHECK(contains(brief.out, "--dry-run"));
      CHECK(contains(brief.out, "--quiet"));
    }
  }
}

}  // TEST_SUITE
