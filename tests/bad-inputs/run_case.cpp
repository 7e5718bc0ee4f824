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
//   npy: NAME DTYPE SHAPE [fortran] VALUES
//                             write NAME in {dir} as a .npy file (format 1.0, as np.save): DTYPE
//                             NumPy's descr ('<f8', '>f8', '<f4', '<c16', '<c8', '<i8', '<i4'),
//                             SHAPE the tuple as Python writes it ("(2, 4)", "(8,)", "()"),
//                             `fortran` for fortran_order True, then the values in order (nan and
//                             inf taken; N*X is X N times; a complex dtype's imaginary parts are
//                             0). Their count is not checked against SHAPE: a short list makes a
//                             truncated file (repeatable)
//   exit: N                   the expected exit code (default 2)
//   field: FIELD              stderr must contain "tsi: error: FIELD:" (or "FIELD." and a path inside)
//   expect: TEXT              stderr must contain TEXT (repeatable)
//   timeout: SECONDS          a hang limit (default 60)
// Any other `//` line is a description. In values, {dir} is the case's directory and
// {config} the body file.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
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

// The bytes of a .npy file from a case's `npy:` value "NAME DTYPE SHAPE [fortran] VALUES"
// (the case's directory prefixed to NAME by the caller): the name and the file's bytes.
std::pair<std::string, std::string> npy_file(const std::string& spec) {
  std::istringstream in(spec);
  std::string name, descr;
  in >> name >> descr;
  std::string rest;
  std::getline(in, rest);
  const std::size_t open = rest.find('('), close = rest.find(')');
  if (name.empty() || descr.size() < 3 || open == std::string::npos || close == std::string::npos || close < open)
    throw std::runtime_error("npy: expected NAME DTYPE SHAPE [fortran] VALUES, got \"" + spec + "\"");
  const std::string shape = rest.substr(open, close - open + 1);
  std::istringstream values(rest.substr(close + 1));
  bool fortran = false;
  const char order = descr[0], kind = descr[1];
  const int size = std::stoi(descr.substr(2)), components = kind == 'c' ? 2 : 1, part = size / components;
  std::string data;
  // One component of `part` bytes, little-endian in memory (the catalogue runs on x86-64 and
  // AArch64 Linux), reversed for a big-endian dtype.
  const auto put = [&](double x) {
    char bytes[8];
    if (kind == 'i' && part == 8) {
      const auto v = static_cast<std::int64_t>(x);
      std::memcpy(bytes, &v, 8);
    } else if (kind == 'i' && part == 4) {
      const auto v = static_cast<std::int32_t>(x);
      std::memcpy(bytes, &v, 4);
    } else if ((kind == 'f' || kind == 'c') && part == 8) {
      std::memcpy(bytes, &x, 8);
    } else if ((kind == 'f' || kind == 'c') && part == 4) {
      const auto v = static_cast<float>(x);
      std::memcpy(bytes, &v, 4);
    } else {
      throw std::runtime_error("npy: unsupported dtype " + descr);
    }
    if (order == '>') std::reverse(bytes, bytes + part);
    data.append(bytes, static_cast<std::size_t>(part));
  };
  for (std::string token; values >> token;) {
    if (token == "fortran") {
      fortran = true;
      continue;
    }
    const std::size_t star = token.find('*');
    const long repeat = star == std::string::npos ? 1 : std::stol(token.substr(0, star));
    const double x = std::stod(star == std::string::npos ? token : token.substr(star + 1));
    for (long k = 0; k < repeat; ++k) {
      put(x);
      if (components == 2) put(0.0);
    }
  }
  std::string dict = "{'descr': '" + descr + "', 'fortran_order': " + (fortran ? "True" : "False") +
                     ", 'shape': " + shape + ", }";
  dict.append(63 - (10 + dict.size()) % 64, ' ');  // the data start on a multiple of 64 bytes
  dict += '\n';
  std::string file = "\x93NUMPY";
  file += '\x01';
  file += '\x00';
  file += static_cast<char>(dict.size() & 0xff);
  file += static_cast<char>(dict.size() >> 8);
  return {name, file + dict + data};
}

struct Case {
  std::string command = "run", config, out, field;
  std::vector<std::string> args, expect, touch, mkdir, npy;
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
    else if (key == "npy") c.npy.push_back(value);
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
  try {
    for (const auto& spec : c.npy) {
      const auto [name, bytes] = npy_file(spec);
      write_text(dir.path() / name, bytes);
    }
  } catch (const std::exception& e) {
    std::cerr << case_file << ": " << e.what() << "\n";
    return 1;
  }

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
