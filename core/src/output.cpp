#include "tsi/output.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "tsi/error.hpp"

namespace tsi {

void write_file_atomically(const std::string& path, const std::string& contents) {
  write_file_atomically(path, [&](std::FILE* file) {
    return std::fwrite(contents.data(), 1, contents.size(), file) == contents.size();
  });
}

void write_file_atomically(const std::string& path, const std::function<bool(std::FILE*)>& write) {
  const std::string tmp = path + ".tmp." + std::to_string(getpid());
  const auto fail = [&](int err) {
    std::remove(tmp.c_str());
    return IoError("cannot write " + path + ": " + std::strerror(err));
  };
  std::FILE* file = std::fopen(tmp.c_str(), "wb");
  if (!file) throw IoError("cannot write " + path + ": " + std::strerror(errno));
  const bool written = write(file) && std::fflush(file) == 0 && fsync(fileno(file)) == 0;
  const int err = errno;
  if (std::fclose(file) != 0 && written) throw fail(errno);
  if (!written) throw fail(err);
  if (std::rename(tmp.c_str(), path.c_str()) != 0) throw fail(errno);
}

}  // namespace tsi
