#include "run_files.hpp"

#include <filesystem>
#include <fstream>

#include "tsi/error.hpp"
#include "tsi/output.hpp"

namespace tsi::app {

void prepare_output_dir(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw ConfigError("--out", "\"" + dir + "\" is a file, expected a directory for the results");
  fs::create_directories(dir, ec);
  if (ec) throw ConfigError("--out", "cannot create \"" + dir + "\": " + ec.message());
  const fs::path probe = fs::path(dir) / ".tsi-write-test";
  {
    std::ofstream out(probe);
    out << "tsi\n";
    out.flush();
    if (!out) throw ConfigError("--out", "\"" + dir + "\" is not writable");
  }
  fs::remove(probe, ec);
}

void write_run_files(const std::string& dir, const RunOutcome& outcome) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw IoError("cannot create the output directory " + dir + ": " + ec.message());
  if (outcome.csv_file.empty()) {
    write_file_atomically(dir + "/invariants.csv", outcome.csv);
  } else {  // streamed while the run went: complete now
    std::filesystem::rename(outcome.csv_file, dir + "/invariants.csv", ec);
  }
  // result.json even when the rows are gone (the directory was removed mid-run): what the
  // run computed is in it.
  write_file_atomically(dir + "/result.json", outcome.result.dump(2) + "\n");
  if (ec) throw IoError("cannot rename " + outcome.csv_file + " to " + dir + "/invariants.csv: " + ec.message());
}

}  // namespace tsi::app
