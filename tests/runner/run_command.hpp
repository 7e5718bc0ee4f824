#pragma once
// Helpers for the runner tests: run the built `tsi` executable as a child process and
// capture its stdout, stderr and exit status; fresh temporary directories; small file I/O.
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>
#include <cstdlib>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

extern char** environ;

namespace tsi::test {

namespace fs = std::filesystem;
using Json = nlohmann::json;

/// Whether `text` contains `part`.
inline bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// What a finished child process left behind.
struct CommandResult {
  int exit_code = -1;  ///< the exit status, or -1 when the process died of a signal
  int signal = 0;      ///< the signal that ended it, 0 when it exited normally
  bool timed_out = false;  ///< killed (SIGKILL) after CommandEnv::timeout_seconds
  long max_rss_kb = 0;  ///< its peak resident memory (getrusage's ru_maxrss), in KiB
  std::string out;     ///< everything written to stdout
  std::string err;     ///< everything written to stderr

  bool exited() const { return signal == 0 && exit_code >= 0; }
  /// stdout and stderr, for failure messages.
  std::string describe() const {
    std::ostringstream s;
    s << "exit code " << exit_code;
    if (signal != 0) s << " (killed by signal " << signal << ")";
    s << "\n--- stdout ---\n" << out << "--- stderr ---\n" << err;
    return s.str();
  }
};

/// Options for run_command: environment changes applied on top of the test's own environment.
struct CommandEnv {
  std::map<std::string, std::string> set;  ///< variables to set (or replace)
  std::vector<std::string> unset;          ///< variables to remove
  int send_signal = 0;                     ///< a signal to send the child (0: none) ...
  double signal_after_seconds = 0.0;       ///< ... this long after it started
  double timeout_seconds = 0.0;            ///< kill the child (SIGKILL) after this long (0: never)
  /// The child's RLIMIT_FSIZE in bytes (-1: unchanged), with SIGXFSZ ignored: a write past
  /// it fails with EFBIG, as on a full disk.
  long long file_size_limit = -1;
  /// The child's RLIMIT_AS in bytes (-1: unchanged): an allocation past it fails, as under
  /// `ulimit -v` or a container's memory limit.
  long long address_space_limit = -1;
};

/// What mpirun needs here: root allowed (CI containers), one machine without network (shared
/// memory only, no single-copy ptrace transfers, which containers often forbid), more ranks
/// than cores allowed and no binding. The caller adds its own guard signal.
inline CommandEnv mpirun_env() {
  CommandEnv env;
  env.set = {{"OMPI_ALLOW_RUN_AS_ROOT", "1"}, {"OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1"},
             {"OMPI_MCA_btl", "self,vader"}, {"OMPI_MCA_btl_vader_single_copy_mechanism", "none"},
             {"OMPI_MCA_rmaps_base_oversubscribe", "1"}, {"OMPI_MCA_hwloc_base_binding_policy", "none"}};
  // Under AddressSanitizer (scripts/sanitize.sh): Open MPI's libraries have no frame pointers,
  // so its allocations need the slow stack walk for the leak suppressions to recognise them.
  if (const char* asan = std::getenv("ASAN_OPTIONS")) env.set["ASAN_OPTIONS"] = std::string(asan) + ":fast_unwind_on_malloc=0";
  return env;
}

namespace detail {

inline void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

/// The child's environment: the current one, without TSI_PLUGIN_PATH (so that the caller's
/// shell cannot change what the tests see), with `env` applied.
inline std::vector<std::string> child_environment(const CommandEnv& env) {
  std::vector<std::string> out;
  auto removed = [&env](const std::string& name) {
    if (name == "TSI_PLUGIN_PATH" || env.set.contains(name)) return true;
    for (const auto& u : env.unset)
      if (u == name) return true;
    return false;
  };
  for (char** e = environ; e && *e; ++e) {
    const std::string entry = *e;
    const auto eq = entry.find('=');
    if (removed(entry.substr(0, eq))) continue;
    out.push_back(entry);
  }
  for (const auto& [name, value] : env.set) out.push_back(name + "=" + value);
  return out;
}

}  // namespace detail

/// Runs `program args...` (no shell), waits for it and returns its status and output.
/// The child runs in `cwd` when it is not empty.
inline CommandResult run_command(const std::string& program, const std::vector<std::string>& args,
                                 const CommandEnv& env = {}, const std::string& cwd = {}) {
  int out_pipe[2] = {-1, -1}, err_pipe[2] = {-1, -1};
  if (::pipe2(out_pipe, O_CLOEXEC) != 0 || ::pipe2(err_pipe, O_CLOEXEC) != 0)
    throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, out_pipe[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, err_pipe[1], STDERR_FILENO);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  if (!cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, cwd.c_str());

  std::vector<std::string> argv_strings;
  argv_strings.push_back(program);
  argv_strings.insert(argv_strings.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_strings) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings = detail::child_environment(env);
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);

  pid_t pid = 0;
  int spawn_error = 0;
  if (env.file_size_limit < 0 && env.address_space_limit < 0) {
    spawn_error = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), envp.data());
  } else {  // posix_spawn cannot set a resource limit: fork, set it in the child, exec
    pid = ::fork();
    if (pid < 0) spawn_error = errno;
    if (pid == 0) {  // async-signal-safe calls only
      const int in = ::open("/dev/null", O_RDONLY);
      if (in < 0 || ::dup2(in, STDIN_FILENO) < 0 || ::dup2(out_pipe[1], STDOUT_FILENO) < 0 ||
          ::dup2(err_pipe[1], STDERR_FILENO) < 0 || (!cwd.empty() && ::chdir(cwd.c_str()) != 0))
        ::_exit(127);
      if (env.file_size_limit >= 0) {
        const rlimit limit{static_cast<rlim_t>(env.file_size_limit), static_cast<rlim_t>(env.file_size_limit)};
        struct sigaction ignore {};
        ignore.sa_handler = SIG_IGN;
        if (::setrlimit(RLIMIT_FSIZE, &limit) != 0 || ::sigaction(SIGXFSZ, &ignore, nullptr) != 0) ::_exit(127);
      }
      if (env.address_space_limit >= 0) {
        const rlimit limit{static_cast<rlim_t>(env.address_space_limit), static_cast<rlim_t>(env.address_space_limit)};
        if (::setrlimit(RLIMIT_AS, &limit) != 0) ::_exit(127);
      }
      ::execve(program.c_str(), argv.data(), envp.data());
      ::_exit(127);
    }
  }
  posix_spawn_file_actions_destroy(&actions);
  detail::close_fd(out_pipe[1]);
  detail::close_fd(err_pipe[1]);
  if (spawn_error != 0) {
    detail::close_fd(out_pipe[0]);
    detail::close_fd(err_pipe[0]);
    throw std::runtime_error("posix_spawn " + program + ": " + std::strerror(spawn_error));
  }

  CommandResult result;
  const auto started = std::chrono::steady_clock::now();
  bool signalled = env.send_signal == 0;
  int fds[2] = {out_pipe[0], err_pipe[0]};
  std::string* sinks[2] = {&result.out, &result.err};
  char buffer[4096];
  while (fds[0] >= 0 || fds[1] >= 0) {
    pollfd polls[2];
    for (int k = 0; k < 2; ++k) polls[k] = {fds[k], POLLIN, 0};  // a negative fd is ignored
    if (!signalled && std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() >=
                          env.signal_after_seconds) {
      ::kill(pid, env.send_signal);
      signalled = true;
    }
    if (env.timeout_seconds > 0.0 && !result.timed_out &&
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count() >= env.timeout_seconds) {
      ::kill(pid, SIGKILL);
      result.timed_out = true;
    }
    const bool watching = !signalled || (env.timeout_seconds > 0.0 && !result.timed_out);
    if (::poll(polls, 2, watching ? 20 : -1) < 0) {
      if (errno == EINTR) continue;
      break;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k] < 0 || polls[k].revents == 0) continue;
      const ssize_t n = ::read(fds[k], buffer, sizeof buffer);
      if (n > 0)
        sinks[k]->append(buffer, static_cast<std::size_t>(n));
      else if (n == 0 || errno != EINTR)
        detail::close_fd(fds[k]);
    }
  }
  detail::close_fd(fds[0]);
  detail::close_fd(fds[1]);

  int status = 0;
  struct rusage usage {};
  while (::wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
  }
  result.max_rss_kb = usage.ru_maxrss;
  if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.signal = WTERMSIG(status);
  }
  return result;
}

/// Runs the built `tsi` runner with `args`.
inline CommandResult run_tsi(const std::vector<std::string>& args, const CommandEnv& env = {},
                         const std::string& cwd = {}) {
  return run_command(TSI_TEST_RUNNER, args, env, cwd);
}

/// A fresh, empty directory under the system temp directory, removed on destruction.
class TempDir {
 public:
  explicit TempDir(const std::string& tag = "tsi-runner-test") {
    static std::atomic<unsigned> counter{0};
    const auto now = std::chrono::steady_clock::now().time_since_epoch().count();
    for (int attempt = 0;; ++attempt) {
      path_ = fs::temp_directory_path() /
              (tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(now) + "-" +
               std::to_string(counter.fetch_add(1)));
      if (fs::create_directory(path_)) break;
      if (attempt > 100) throw std::runtime_error("cannot create a temp directory " + path_.string());
    }
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const fs::path& path() const { return path_; }
  /// A path inside the directory, as a string.
  std::string operator/(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

inline std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file, std::ios::binary);
  if (!out) throw std::runtime_error("cannot write " + file.string());
  out << text;
}

inline Json read_json(const fs::path& file) { return Json::parse(read_text(file)); }

/// Writes `config` as a JSON file in `dir` and returns its path.
inline std::string write_config(const TempDir& dir, const Json& config, const std::string& name = "config.json") {
  const std::string file = dir / name;
  write_text(file, config.dump(2));
  return file;
}

/// The pieces of a path joined into one string. g++ 12 at -O3 warns (-Warray-bounds, a false
/// positive that depends on the lengths of the pieces, and so on where the tree is checked out)
/// about `std::string(MACRO) + "..."`; appending to a reserved string does not trip it.
inline std::string path_text(std::initializer_list<std::string_view> parts) {
  std::size_t size = 0;
  for (std::string_view part : parts) size += part.size();
  std::string text;
  text.reserve(size);
  for (std::string_view part : parts) text.append(part);
  return text;
}

/// The shipped example config.
inline std::string example_config(const std::string& name = "hh-se1.json") {
  return path_text({TSI_TEST_SOURCE_DIR, "/examples/", name});
}

inline std::string fixture_plugin(const std::string& name) {
  return path_text({TSI_TEST_FIXTURE_DIR, "/tsi_fixture_", name, ".so"});
}

/// A small, fast config (Henon-Heiles, SE1 on the two-scale problem, 4 steps, no reference).
inline Json small_config() {
  return Json::parse(R"({
    "model": {"name": "henon-heiles", "eps": 0.1},
    "reformulation": {"name": "two-scale", "n_tau": 16},
    "scheme": {"name": "se1"},
    "time": {"h": 0.25, "t_end": 1.0}
  })");
}

/// Splits text into lines (without the newline characters).
inline std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream s(text);
  for (std::string line; std::getline(s, line);) out.push_back(line);
  return out;
}

/// Splits one CSV line at commas.
inline std::vector<std::string> csv_fields(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream s(line);
  for (std::string field; std::getline(s, field, ',');) out.push_back(field);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

}  // namespace tsi::test
