#pragma once
// Comparing two study directories as the same study: table.csv and study.json equal apart from
// what depends on how and when the study ran (wall times, jobs, ranks, shards).
#include <algorithm>
#include <string>
#include <vector>

#include "run_command.hpp"

namespace tsi::test {

/// table.csv without its wall_seconds column, line by line.
inline std::vector<std::string> table_without_timings(const fs::path& dir) {
  const auto lines = lines_of(read_text(dir / "table.csv"));
  std::vector<std::string> out;
  if (lines.empty()) return out;
  const auto header = csv_fields(lines[0]);
  const auto at = static_cast<size_t>(std::find(header.begin(), header.end(), "wall_seconds") - header.begin());
  for (const auto& line : lines) {
    auto fields = csv_fields(line);
    if (at < fields.size()) fields.erase(fields.begin() + static_cast<long>(at));
    std::string joined;
    for (size_t k = 0; k < fields.size(); ++k) joined += (k ? "," : "") + fields[k];
    out.push_back(joined);
  }
  return out;
}

/// study.json without the fields that record how and when it ran.
inline Json study_without_timings(const fs::path& dir) {
  Json s = read_json(dir / "study.json");
  for (const char* key : {"wall_seconds", "jobs", "machine", "mpi_ranks", "shards"}) s.erase(key);
  for (auto& row : s["table"]) row.erase("wall_seconds");
  if (s.contains("work_at_error")) s.erase("work_at_error");  // built from wall times
  return s;
}

}  // namespace tsi::test
