#include "run_files.hpp"

#include <filesystem>

#include "tsi/error.hpp"
#include "tsi/output.hpp"

namespace tsi::app {

void write_run_files(const std::string& dir, const RunOutcome& outcome) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw Error("--out " + dir + ": cannot create the output directory: " + ec.message());
  write_file_atomically(dir + "/invariants.csv", outcome.csv);
  write_file_atomically(dir + "/result.json", outcome.result.dump(2) + "\n");
}

}  // namespace tsi::app
