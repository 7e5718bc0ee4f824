// How much memory a run may take before it takes it: a size that does not fit is a refusal
// naming its fields, never the out-of-memory killer or std::bad_alloc half way through.
#include "tsi/memory.hpp"

#include <fmt/format.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <limits>
#include <sstream>

#include "tsi/error.hpp"

namespace tsi {
namespace {

constexpr double unknown = std::numeric_limits<double>::infinity();

// MemAvailable from /proc/meminfo, else the physical memory.
double machine_available() {
  std::ifstream meminfo("/proc/meminfo");
  for (std::string key; meminfo >> key;) {
    double kb = 0.0;
    meminfo >> kb;
    if (key == "MemAvailable:") return kb * 1024.0;
    meminfo.ignore(64, '\n');
  }
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * static_cast<double>(page) : unknown;
}

// RLIMIT_AS less the process's mapped size now (/proc/self/statm's first field, in pages).
double address_space_left() {
  rlimit limit{};
  if (getrlimit(RLIMIT_AS, &limit) != 0 || limit.rlim_cur == RLIM_INFINITY) return unknown;
  std::ifstream statm("/proc/self/statm");
  double pages = 0.0;
  if (!(statm >> pages)) return static_cast<double>(limit.rlim_cur);
  return std::max(0.0, static_cast<double>(limit.rlim_cur) - pages * static_cast<double>(sysconf(_SC_PAGE_SIZE)));
}

// A number from a cgroup v2 file ("max": none).
double cgroup_value(const std::string& path) {
  std::ifstream file(path);
  std::string text;
  if (!(file >> text) || text == "max") return unknown;
  try {
    return std::stod(text);
  } catch (const std::exception&) {
    return unknown;
  }
}

// The process's cgroup v2 (the "0::/path" line of /proc/self/cgroup): memory.max less memory.current.
double cgroup_left() {
  std::ifstream file("/proc/self/cgroup");
  for (std::string line; std::getline(file, line);) {
    if (line.rfind("0::", 0) != 0) continue;
    const std::string dir = "/sys/fs/cgroup" + line.substr(3);
    const double max = cgroup_value(dir + "/memory.max");
    if (max == unknown) return unknown;
    const double current = cgroup_value(dir + "/memory.current");
    return current == unknown ? max : std::max(0.0, max - current);
  }
  return unknown;
}

}  // namespace

double allocatable_bytes() { return std::min({machine_available(), address_space_left(), cgroup_left()}); }

void check_allocation(const std::string& field, double bytes, const std::string& what, double limit) {
  const bool own_limit = limit > 0.0;
  const double available = own_limit ? limit : allocatable_bytes();
  if (!(bytes > available)) return;
  throw ConfigError(field, fmt::format("{} needs {:.3g} GB; {} {:.3g} GB", what, bytes / 1e9,
                                       own_limit ? "the run's memory limit is" : "this process can allocate",
                                       available / 1e9));
}

}  // namespace tsi
