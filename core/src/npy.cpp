#include "tsi/npy.hpp"

#include <fmt/format.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <map>
#include <optional>

#include "tsi/error.hpp"
#include "tsi/output.hpp"

namespace tsi {
namespace {

constexpr char magic[] = "\x93NUMPY";
constexpr std::size_t magic_size = 6;
constexpr std::uint64_t max_header_bytes = 1u << 20;  // NumPy's own reader stops at 10000 by default
constexpr std::size_t chunk_values = 1u << 15;        // values converted per read or write

// ---- Little-endian bytes ----------------------------------------------------------------------

template <typename T>
T from_little(const unsigned char* bytes) {
  T value;
  std::memcpy(&value, bytes, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) {
    unsigned char swapped[sizeof(T)];
    for (std::size_t k = 0; k < sizeof(T); ++k) swapped[k] = bytes[sizeof(T) - 1 - k];
    std::memcpy(&value, swapped, sizeof(T));
  }
  return value;
}

template <typename T>
void to_little(T value, unsigned char* bytes) {
  std::memcpy(bytes, &value, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(bytes, bytes + sizeof(T));
}

// ---- Files ------------------------------------------------------------------------------------

struct File {
  std::FILE* f = nullptr;
  File() = default;
  File(const File&) = delete;
  File& operator=(const File&) = delete;
  ~File() {
    if (f) std::fclose(f);
  }
};

// Reads exactly n bytes; a short read is the file changing under us (or a read error).
void read_exactly(const File& file, const std::string& path, unsigned char* out, std::size_t n) {
  if (n == 0) return;
  if (std::fread(out, 1, n, file.f) != n)
    throw Error(std::ferror(file.f) ? fmt::format("{}: cannot read: {}", path, std::strerror(errno))
                                    : fmt::format("{}: the file ended early (was it changed while being read?)", path));
}

// ---- The header's dict literal ----------------------------------------------------------------

// One value of the header's Python literal.
struct Literal {
  enum Kind { string, boolean, tuple, other } kind = other;
  std::string text;
  bool flag = false;
  std::vector<std::uint64_t> numbers;
};

// A strict reader of the dict NumPy writes: {'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }
class HeaderParser {
 public:
  HeaderParser(std::string path, const std::string& text) : path_(std::move(path)), s_(text) {}

  std::map<std::string, Literal> dict() {
    std::map<std::string, Literal> out;
    skip_space();
    expect('{');
    for (;;) {
      skip_space();
      if (peek() == '}') break;
      const std::string key = string_literal();
      skip_space();
      expect(':');
      skip_space();
      Literal value = literal(key);
      if (!out.emplace(key, std::move(value)).second) fail(fmt::format("the key '{}' appears twice", key));
      skip_space();
      if (peek() == ',') {
        ++i_;
        continue;
      }
      if (peek() != '}') fail("expected ',' or '}'");
    }
    ++i_;
    skip_space();
    if (i_ != s_.size()) fail("text after the closing '}'");
    return out;
  }

 private:
  [[noreturn]] void fail(const std::string& what) const {
    throw Error(fmt::format("{}: a malformed .npy header ({} at offset {} of \"{}\")", path_, what, i_,
                            s_.size() > 200 ? s_.substr(0, 200) + "..." : s_));
  }
  char peek() const { return i_ < s_.size() ? s_[i_] : '\0'; }
  void skip_space() {
    while (i_ < s_.size() && (s_[i_] == ' ' || s_[i_] == '\t' || s_[i_] == '\n' || s_[i_] == '\r')) ++i_;
  }
  void expect(char c) {
    if (peek() != c) fail(fmt::format("expected '{}'", c));
    ++i_;
  }
  std::string string_literal() {
    const char quote = peek();
    if (quote != '\'' && quote != '"') fail("expected a quoted key or string");
    ++i_;
    std::string out;
    while (i_ < s_.size() && s_[i_] != quote) {
      if (s_[i_] == '\\' || s_[i_] == '\n') fail("an escape or line break in a string");
      out += s_[i_++];
    }
    expect(quote);
    return out;
  }
  std::uint64_t integer() {
    if (peek() < '0' || peek() > '9') fail("expected a non-negative integer");
    std::uint64_t value = 0;
    while (peek() >= '0' && peek() <= '9') {
      const auto digit = static_cast<std::uint64_t>(peek() - '0');
      if (value > (std::numeric_limits<std::uint64_t>::max() - digit) / 10) fail("a dimension beyond 2^64");
      value = value * 10 + digit;
      ++i_;
    }
    if (peek() == 'L') ++i_;  // Python 2's long literal, in files written long ago
    return value;
  }
  Literal literal(const std::string& key) {
    Literal v;
    const char c = peek();
    if (c == '\'' || c == '"') {
      v.kind = Literal::string;
      v.text = string_literal();
    } else if (s_.compare(i_, 4, "True") == 0 || s_.compare(i_, 5, "False") == 0) {
      v.kind = Literal::boolean;
      v.flag = s_[i_] == 'T';
      i_ += v.flag ? 4 : 5;
    } else if (c == '(') {
      v.kind = Literal::tuple;
      ++i_;
      for (;;) {
        skip_space();
        if (peek() == ')') break;
        v.numbers.push_back(integer());
        skip_space();
        if (peek() == ',') {
          ++i_;
          continue;
        }
        if (peek() != ')') fail("expected ',' or ')' in the shape");
      }
      ++i_;
    } else if (c == '[' && key == "descr") {
      throw Error(fmt::format("{}: a structured dtype (a list as 'descr'); expected float64 '<f8' or complex128 "
                              "'<c16' (also '<f4', '<c8')",
                              path_));
    } else {
      fail(fmt::format("an unexpected value for '{}'", key));
    }
    return v;
  }

  std::string path_;
  const std::string& s_;
  std::size_t i_ = 0;
};

const char* const expected_dtypes = "float64 '<f8' or complex128 '<c16' (also float32 '<f4' and complex64 '<c8', widened)";

void set_dtype(NpyHeader& h, const std::string& path) {
  const std::string& d = h.descr;
  static const std::map<std::string, std::pair<bool, std::size_t>> accepted = {
      {"<f8", {false, 8}}, {"<f4", {false, 4}}, {"<c16", {true, 16}}, {"<c8", {true, 8}}};
  if (const auto it = accepted.find(d); it != accepted.end()) {
    h.is_complex = it->second.first;
    h.item_size = it->second.second;
    return;
  }
  std::string little = d;
  if (!little.empty()) little[0] = '<';
  if (d.size() > 1 && d[0] == '>' && accepted.count(little))
    throw Error(fmt::format("{}: dtype '{}' is big-endian; expected little-endian {}: save a.astype('<{}')", path,
                            d, expected_dtypes, d.substr(1)));
  throw Error(fmt::format("{}: dtype '{}' is not supported; expected {}", path, d, expected_dtypes));
}

// Opens `path` and reads its header; the file is left at the start of the data.
NpyHeader open_and_read_header(File& file, const std::string& path) {
  // Opened without blocking (a FIFO named by mistake would wait for a writer), checked to be a
  // regular file, then read as usual.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) throw Error(fmt::format("{}: cannot open: {}", path, std::strerror(errno)));
  struct stat st {};
  if (fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const int err = errno;
    const bool regular = S_ISREG(st.st_mode);
    ::close(fd);
    if (regular) throw Error(fmt::format("{}: cannot stat: {}", path, std::strerror(err)));
    throw Error(fmt::format("{}: not a regular file (a .npy file was expected)", path));
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  file.f = ::fdopen(fd, "rb");
  if (!file.f) {
    const int err = errno;
    ::close(fd);
    throw Error(fmt::format("{}: cannot open: {}", path, std::strerror(err)));
  }
  const auto size = static_cast<std::uint64_t>(st.st_size);
  constexpr std::size_t prefix1 = magic_size + 2 + 2;
  if (size < prefix1)
    throw Error(fmt::format("{}: {} bytes, too short for a .npy file (its fixed header alone has {})", path, size,
                            prefix1));
  unsigned char prefix[prefix1 + 2];
  read_exactly(file, path, prefix, prefix1);
  if (std::memcmp(prefix, magic, magic_size) != 0)
    throw Error(fmt::format("{}: not a .npy file (it does not start with the magic \"\\x93NUMPY\")", path));
  NpyHeader h;
  h.major_version = prefix[6];
  h.minor_version = prefix[7];
  std::uint64_t header_len = 0;
  std::size_t prefix_size = prefix1;
  if (h.major_version == 1 && h.minor_version == 0) {
    header_len = from_little<std::uint16_t>(prefix + 8);
  } else if ((h.major_version == 2 || h.major_version == 3) && h.minor_version == 0) {
    prefix_size = prefix1 + 2;
    if (size < prefix_size) throw Error(fmt::format("{}: {} bytes, too short for a .npy file of format {}.0", path, size,
                                                    h.major_version));
    read_exactly(file, path, prefix + prefix1, 2);
    header_len = from_little<std::uint32_t>(prefix + 8);
  } else {
    throw Error(fmt::format("{}: .npy format version {}.{}; expected 1.0, 2.0 or 3.0", path, h.major_version,
                            h.minor_version));
  }
  if (header_len > max_header_bytes)
    throw Error(fmt::format("{}: a .npy header of {} bytes; at most {} are read (no header of a plain array is that "
                            "long)",
                            path, header_len, max_header_bytes));
  if (prefix_size + header_len > size)
    throw Error(fmt::format("{}: truncated: the .npy header claims {} bytes, the file has {} after its {}-byte prefix",
                            path, header_len, size - prefix_size, prefix_size));
  std::string text(static_cast<std::size_t>(header_len), '\0');
  read_exactly(file, path, reinterpret_cast<unsigned char*>(text.data()), text.size());
  h.data_offset = prefix_size + header_len;
  if (text.find('\0') != std::string::npos) throw Error(fmt::format("{}: a NUL byte in the .npy header", path));

  const auto dict = HeaderParser(path, text).dict();
  for (const auto& [key, value] : dict)
    if (key != "descr" && key != "fortran_order" && key != "shape")
      throw Error(fmt::format("{}: an unexpected key '{}' in the .npy header; expected 'descr', 'fortran_order' and "
                              "'shape'",
                              path, key));
  const auto entry = [&](const char* key, Literal::Kind kind, const char* what) -> const Literal& {
    const auto it = dict.find(key);
    if (it == dict.end()) throw Error(fmt::format("{}: the .npy header has no '{}'", path, key));
    if (it->second.kind != kind) throw Error(fmt::format("{}: the .npy header's '{}' is not {}", path, key, what));
    return it->second;
  };
  h.descr = entry("descr", Literal::string, "a dtype string").text;
  h.fortran_order = entry("fortran_order", Literal::boolean, "True or False").flag;
  h.shape = entry("shape", Literal::tuple, "a tuple of integers").numbers;
  set_dtype(h, path);

  h.count = 1;
  for (const std::uint64_t n : h.shape)
    if (__builtin_mul_overflow(h.count, n, &h.count))
      throw Error(fmt::format("{}: shape {} holds more than 2^64 values", path, npy_shape_text(h.shape)));
  std::uint64_t bytes = 0;
  const std::uint64_t data_bytes = size - h.data_offset;
  const bool overflow = __builtin_mul_overflow(h.count, static_cast<std::uint64_t>(h.item_size), &bytes);
  if (overflow || bytes != data_bytes)
    throw Error(fmt::format("{}: {}: the header's shape {} of '{}' needs {} bytes of data ({} values of {} bytes), "
                            "the file holds {} after its {}-byte header",
                            path, overflow || bytes > data_bytes ? "truncated, or not what its header says"
                                                                 : "more data than its header says",
                            npy_shape_text(h.shape), h.descr, overflow ? std::string("more than 2^64") : std::to_string(bytes),
                            h.count, h.item_size, data_bytes, h.data_offset));
  if (h.count > static_cast<std::uint64_t>(std::numeric_limits<Index>::max()))
    throw Error(fmt::format("{}: {} values are more than a vector can index", path, h.count));
  if (h.fortran_order && std::count_if(h.shape.begin(), h.shape.end(), [](std::uint64_t n) { return n > 1; }) > 1)
    throw Error(fmt::format("{}: a Fortran-ordered array of shape {}; tsi reads C order (and 1-D arrays in either "
                            "order): save np.ascontiguousarray(a)",
                            path, npy_shape_text(h.shape)));
  return h;
}

// ---- Writing ----------------------------------------------------------------------------------

// NumPy's header for `descr` and `shape`, with its prefix: magic, version, length; the dict
// padded with spaces (room for the first dimension to grow to 21 digits, as NumPy leaves it)
// and a newline to a multiple of 64 bytes.
std::string npy_header(const std::string& descr, const std::vector<std::uint64_t>& shape) {
  std::string dict = "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + npy_shape_text(shape) + ", }";
  if (!shape.empty()) dict.append(21 - std::min<std::size_t>(21, std::to_string(shape.front()).size()), ' ');
  const std::size_t hlen = dict.size() + 1;  // with the newline
  for (const int major : {1, 2}) {
    const std::size_t prefix = major == 1 ? 10 : 12;
    const std::size_t pad = 64 - (prefix + hlen) % 64;
    const std::size_t total = hlen + pad;
    if (major == 1 && total > 0xffff) continue;
    std::string out(magic, magic_size);
    out += static_cast<char>(major);
    out += '\0';
    unsigned char len[4];
    if (major == 1)
      to_little(static_cast<std::uint16_t>(total), len);
    else
      to_little(static_cast<std::uint32_t>(total), len);
    out.append(reinterpret_cast<const char*>(len), major == 1 ? 2 : 4);
    out += dict;
    out.append(pad, ' ');
    out += '\n';
    return out;
  }
  return {};  // not reached: format 2.0's length holds any header of a shape tsi writes
}

// Writes header + count values of item_size bytes, `fill(first, n, bytes)` putting values
// first .. first + n - 1 into bytes; atomically, in chunks (write_file_atomically).
void write_atomically(const std::string& path, const std::string& header, std::uint64_t count, std::size_t item_size,
                      const std::function<void(std::uint64_t, std::size_t, unsigned char*)>& fill) {
  write_file_atomically(path, [&](std::FILE* file) {
    bool written = std::fwrite(header.data(), 1, header.size(), file) == header.size();
    std::vector<unsigned char> buffer(chunk_values * item_size);
    for (std::uint64_t first = 0; written && first < count; first += chunk_values) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(chunk_values, count - first));
      fill(first, n, buffer.data());
      written = std::fwrite(buffer.data(), item_size, n, file) == n;
    }
    return written;
  });
}

std::vector<std::uint64_t> checked_shape(const std::string& path, std::uint64_t count,
                                         const std::vector<std::uint64_t>& shape) {
  if (shape.empty()) return {count};
  std::uint64_t product = 1;
  bool overflow = false;
  for (const std::uint64_t n : shape) overflow = overflow || __builtin_mul_overflow(product, n, &product);
  if (overflow || product != count)
    throw Error(fmt::format("{}: cannot write {} values with shape {}", path, count, npy_shape_text(shape)));
  return shape;
}

}  // namespace

std::string npy_header_bytes(bool complex_values, const std::vector<std::uint64_t>& shape) {
  return npy_header(complex_values ? "<c16" : "<f8", shape);
}

std::string npy_shape_text(const std::vector<std::uint64_t>& shape) {
  if (shape.size() == 1) return fmt::format("({},)", shape.front());
  return fmt::format("({})", fmt::join(shape, ", "));
}

NpyHeader read_npy_header(const std::string& path) {
  File file;
  return open_and_read_header(file, path);
}

NpyArray read_npy(const std::string& path) {
  File file;
  NpyArray out;
  out.header = open_and_read_header(file, path);
  const NpyHeader& h = out.header;
  out.values.resize(static_cast<Index>(h.count));  // at most what the file holds (checked against its size)
  std::vector<unsigned char> buffer(chunk_values * h.item_size);
  for (std::uint64_t first = 0; first < h.count; first += chunk_values) {
    const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(chunk_values, h.count - first));
    read_exactly(file, path, buffer.data(), n * h.item_size);
    Complex* dst = out.values.data() + first;
    const unsigned char* src = buffer.data();
    for (std::size_t k = 0; k < n; ++k, src += h.item_size) {
      if (h.descr == "<f8")
        dst[k] = Complex(from_little<double>(src), 0.0);
      else if (h.descr == "<c16")
        dst[k] = Complex(from_little<double>(src), from_little<double>(src + 8));
      else if (h.descr == "<f4")
        dst[k] = Complex(static_cast<double>(from_little<float>(src)), 0.0);
      else
        dst[k] = Complex(static_cast<double>(from_little<float>(src)), static_cast<double>(from_little<float>(src + 4)));
    }
  }
  return out;
}

void write_npy(const std::string& path, std::span<const double> values, const std::vector<std::uint64_t>& shape) {
  const std::uint64_t count = values.size();
  write_atomically(path, npy_header("<f8", checked_shape(path, count, shape)), count, 8,
                   [&](std::uint64_t first, std::size_t n, unsigned char* out) {
                     for (std::size_t k = 0; k < n; ++k) to_little(values[first + k], out + 8 * k);
                   });
}

void write_npy(const std::string& path, std::span<const Complex> values, const std::vector<std::uint64_t>& shape) {
  const std::uint64_t count = values.size();
  write_atomically(path, npy_header("<c16", checked_shape(path, count, shape)), count, 16,
                   [&](std::uint64_t first, std::size_t n, unsigned char* out) {
                     for (std::size_t k = 0; k < n; ++k) {
                       to_little(to_double(values[first + k].real()), out + 16 * k);
                       to_little(to_double(values[first + k].imag()), out + 16 * k + 8);
                     }
                   });
}

void write_npy(const std::string& path, const Vector& values, bool complex_values,
               const std::vector<std::uint64_t>& shape) {
  const std::span<const Complex> all(values.data(), static_cast<std::size_t>(values.size()));
  if (complex_values) return write_npy(path, all, shape);
  const std::uint64_t count = all.size();
  write_atomically(path, npy_header("<f8", checked_shape(path, count, shape)), count, 8,
                   [&](std::uint64_t first, std::size_t n, unsigned char* out) {
                     for (std::size_t k = 0; k < n; ++k) to_little(to_double(all[first + k].real()), out + 8 * k);
                   });
}

void write_npy_rows(const std::string& path, const std::vector<Vector>& rows, Index row_size, bool complex_values,
                    const std::vector<std::uint64_t>& shape) {
  const auto width = static_cast<std::uint64_t>(row_size);
  const std::uint64_t count = rows.size() * width;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The value at flat index i: row i / width, or NaN where that row was not computed.
  const auto value = [&](std::uint64_t i) -> Complex {
    const Vector& row = rows[i / width];
    return row.size() == row_size ? row(static_cast<Index>(i % width)) : Complex(nan, nan);
  };
  const std::size_t item = complex_values ? 16 : 8;
  write_atomically(path, npy_header(complex_values ? "<c16" : "<f8", checked_shape(path, count, shape)), count, item,
                   [&](std::uint64_t first, std::size_t n, unsigned char* out) {
                     for (std::size_t k = 0; k < n; ++k) {
                       const Complex x = value(first + k);
                       to_little(to_double(x.real()), out + item * k);
                       if (complex_values) to_little(to_double(x.imag()), out + item * k + 8);
                     }
                   });
}

}  // namespace tsi
