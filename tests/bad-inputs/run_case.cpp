// Runs one case of the bad-input catalogue (tests/bad-inputs/NNN-name.json) against the built
// `tsi` and checks its outcome: no signal, no hang, the expected exit code, and a message on
// stderr "tsi: error: FIELD: ..." naming the expected field.
//
// A case file starts with a header of `// key: value` lines; the rest (the body, possibly
// empty or malformed) is written to a fresh directory as config.json (run) or study.json
// (study), and tsi runs there. Header keys:
//   command: run | study      the subcommand (default run); the body file is its argument
//            none             no subcommand: the args alone
//   arg: TEXT                 one more argument, verbatim (repeatable, in order)
//   config: PATH              pass PATH instead of the body file
//   out: PATH | none          --out (default {dir}/out); none: no --out
//   touch: NAME / mkdir: NAME create an empty file / a directory in {dir} before the run
//   exit: N                   the expected exit code (default 2)
//   field: FIELD              stderr must contain "tsi: error: FIELD:" (or "FIELD." and a path inside)
//   expect: TEXT              stderr must contain TEXT (repeatable)
//   timeout: SECONDS          a hang limit (default 60)
// Any other `//` line is a description. In values, {dir} is the case's directory and
// {config} the body file.
#include <algorithm>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "runner/run_command.hpp"

namespace {

using namespace tsi::test;

std::string substitute(std::string text, const std::string& dir, const std::string& config) {
  for (const auto& [key, value] : {std::pair<std::string, std::string>{"{dir}", dir}, {"{config}", config}})
    for (std::size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
      text.replace(at, key.size(), value);
  return text;
}

struct Case {
  std::string command = "run", config, out, field;
  std::vector<std::string> args, expect, touch, mkdir;
  bool has_config = false, has_out = false;
  int exit = 2;
  double timeout = 60.0;
  std::string body;
};

Case parse_case(const std::string& text) {
  Case c;
  std::size_t pos = 0;
  while (pos < text.size() && text.compare(pos, 2, "//") == 0) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    const std::string line = text.substr(pos + 2, end - pos - 2);
    pos = end + 1;
    const std::size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon), value = line.substr(colon + 1);
    key.erase(0, key.find_first_not_of(' '));
    if (!value.empty() && value.front() == ' ') value.erase(0, 1);
    if (key == "command") c.command = value;
    else if (key == "arg") c.args.push_back(value);
    else if (key == "config") c.config = value, c.has_config = true;
    else if (key == "out") c.out = value, c.has_out = true;
    else if (key == "touch") c.touch.push_back(value);
    else if (key == "mkdir") c.mkdir.push_back(value);
    else if (key == "exit") c.exit = std::stoi(value);
    else if (key == "field") c.field = value;
    else if (key == "expect") c.expect.push_back(value);
    else if (key == "timeout") c.timeout = std::stod(value);
  }
  c.body = pos < text.size() ? text.substr(pos) : std::string();
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: tsi_bad_input_case CASE.json\n";
    return 2;
  }
  const std::string case_file = argv[1];
  Case c;
  try {
    c = parse_case(read_text(case_file));
  } catch (const std::exception& e) {
    std::cerr << case_file << ": " << e.what() << "\n";
    return 1;
  }
  TempDir dir("tsi-bad-input");
  const std::string root = dir.path().string();
  const std::string body_file = dir / (c.command == "study" ? "study.json" : "config.json");
  write_text(body_file, c.body);
  for (const auto& name : c.mkdir) fs::create_directories(dir.path() / substitute(name, root, body_file));
  for (const auto& name : c.touch) write_text(dir.path() / substitute(name, root, body_file), "");

  const std::string config = c.has_config ? substitute(c.config, root, body_file) : body_file;
  const std::string out = c.has_out ? substitute(c.out, root, body_file) : dir / "out";
  std::vector<std::string> args;
  if (c.command != "none") args = {c.command, config};
  if (out != "none") args.insert(args.end(), {"--out", out});
  if (c.command == "study") args.push_back("--no-plots");
  for (const auto& a : c.args) args.push_back(substitute(a, root, body_file));

  CommandEnv env;
  env.timeout_seconds = c.timeout;
  const CommandResult r = run_tsi(args, env, root);

  std::vector<std::string> failures;
  if (r.timed_out) failures.push_back("hang: killed after " + std::to_string(c.timeout) + " s");
  else if (r.signal != 0) failures.push_back("crash: killed by signal " + std::to_string(r.signal));
  else if (r.exit_code != c.exit)
    failures.push_back("exit code " + std::to_string(r.exit_code) + ", expected " + std::to_string(c.exit));
  const std::string field = substitute(c.field, root, body_file);
  // The field, or a path inside it ("FIELD.[].[]" for nesting, "FIELD[0]" for an entry), starts the message.
  if (!field.empty() && !contains(r.err, "tsi: error: " + field + ":") && !contains(r.err, "tsi: error: " + field + ".") &&
      !contains(r.err, "tsi: error: " + field + "["))
    failures.push_back("stderr does not name the field: expected \"tsi: error: " + field + ":\"");
  for (const auto& e : c.expect)
    if (!contains(r.err, substitute(e, root, body_file))) failures.push_back("stderr lacks \"" + e + "\"");
  if (c.exit == 2 && c.command == "run" && fs::exists(fs::path(out) / "result.json"))
    failures.push_back("bad input wrote " + out + "/result.json");

  std::string command = "tsi";
  for (const auto& a : args) command += " " + a;
  std::cout << command << "\n" << r.describe() << "\n";
  for (const auto& f : failures) std::cout << "FAILED: " << f << "\n";
  return failures.empty() ? 0 : 1;
}
