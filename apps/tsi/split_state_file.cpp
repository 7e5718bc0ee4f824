#include "split_state_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "tsi/error.hpp"
#include "tsi/npy.hpp"

namespace tsi::app {

namespace {
// pwrite of n bytes at `offset`, through short writes; false on an error.
bool write_at(int fd, const unsigned char* bytes, std::size_t n, std::uint64_t offset) {
  while (n > 0) {
    const ssize_t done = ::pwrite(fd, bytes, n, static_cast<off_t>(offset));
    if (done < 0 && errno == EINTR) continue;
    if (done <= 0) return false;
    bytes += done;
    n -= static_cast<std::size_t>(done);
    offset += static_cast<std::uint64_t>(done);
  }
  return true;
}

// Whether every process succeeded (a failure anywhere is a failure everywhere).
bool everyone(const Collective& split, bool ok) { return split.all(ok); }
}  // namespace

void write_split_state(const Collective& split, const std::string& path, const Vector& local, Index parts,
                       bool complex_values, const std::vector<std::uint64_t>& shape) {
  const std::string temporary = path + ".split-partial";
  const std::string header = npy_header_bytes(complex_values, shape);
  const std::size_t item = complex_values ? 16 : 8;
  const Index share = local.size() / parts, processes = split.size(), rank = split.rank();
  std::uint64_t total = 1;
  for (const std::uint64_t n : shape) total *= n;
  bool ok = total == static_cast<std::uint64_t>(share * parts * processes);
  if (rank == 0 && ok) {  // the header, and the file at its full size
    const int fd = ::open(temporary.c_str(), O_CREAT | O_TRUNC | O_WRONLY, 0644);
    ok = fd >= 0 && write_at(fd, reinterpret_cast<const unsigned char*>(header.data()), header.size(), 0) &&
         ::ftruncate(fd, static_cast<off_t>(header.size() + total * item)) == 0;
    if (fd >= 0) ok = ::close(fd) == 0 && ok;
  }
  if (everyone(split, ok)) {
    const int fd = ::open(temporary.c_str(), O_WRONLY);
    ok = fd >= 0;
    std::vector<unsigned char> bytes(static_cast<std::size_t>(share) * item);
    for (Index f = 0; ok && f < parts; ++f) {
      for (Index i = 0; i < share; ++i) {  // little-endian float64 (x86, as np.save on it)
        const Complex z = local(f * share + i);
        const double values[2] = {to_double(z.real()), to_double(z.imag())};
        std::memcpy(bytes.data() + static_cast<std::size_t>(i) * item, values, item);
      }
      const std::uint64_t at = header.size() + static_cast<std::uint64_t>((f * processes + rank) * share) * item;
      ok = write_at(fd, bytes.data(), bytes.size(), at);
    }
    if (fd >= 0) ok = ::fsync(fd) == 0 && ::close(fd) == 0 && ok;
  }
  if (everyone(split, ok)) {
    if (rank == 0) ok = std::rename(temporary.c_str(), path.c_str()) == 0;
    if (everyone(split, ok)) return;
  }
  if (rank == 0) std::remove(temporary.c_str());
  throw IoError("cannot write " + path + " (a split run's processes, each its share): " +
                (total == static_cast<std::uint64_t>(share * parts * processes) ? "a write failed"
                                                                                 : "the shares do not fill its shape"));
}

}  // namespace tsi::app
