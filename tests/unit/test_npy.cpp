// The .npy reader and writer (tsi/npy.hpp): round trips, files NumPy wrote, NumPy reading
// tsi's files back (byte for byte what np.save writes), and every malformed or lying file
// refused with a message naming it, before anything large is allocated.
#include <doctest/doctest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <csignal>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "runner/run_command.hpp"
#include "tsi/error.hpp"
#include "tsi/npy.hpp"

namespace {

namespace t = tsi::test;
namespace fs = std::filesystem;
using tsi::Complex;
using Json = nlohmann::json;

// Runs a NumPy script with Debian's interpreter (scripts/install-deps.sh installs python3-numpy).
void python(const std::string& script, const std::string& cwd) {
  const t::CommandResult r = t::run_command("/usr/bin/python3", {"-c", "import numpy as np, json, sys\n" + script}, {}, cwd);
  INFO("the test needs /usr/bin/python3 with numpy (python3-numpy, scripts/install-deps.sh)");
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
}

std::vector<std::uint64_t> shape_of(std::initializer_list<std::uint64_t> s) { return s; }

// A .npy file of format 1.0 with the given header dict (padded as NumPy pads) and data bytes.
std::string raw_npy(const std::string& dict, const std::string& data, int major = 1) {
  std::string header = dict;
  const std::size_t prefix = major == 1 ? 10 : 12;
  header.append(64 - (prefix + header.size() + 1) % 64, ' ');
  header += '\n';
  std::string out = std::string("\x93NUMPY", 6) + static_cast<char>(major) + '\0';
  const std::size_t n = header.size();
  out += static_cast<char>(n & 0xff);
  out += static_cast<char>((n >> 8) & 0xff);
  if (major != 1) out += std::string(2, '\0');
  return out + header + data;
}

std::string doubles(std::initializer_list<double> values) {
  std::string out;
  for (const double v : values) out.append(reinterpret_cast<const char*>(&v), sizeof v);
  return out;
}

// The message of the tsi::Error that reading `file` throws ("" when it reads).
std::string read_error(const std::string& file) {
  try {
    (void)tsi::read_npy(file);
  } catch (const tsi::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_SUITE("tsi_unit_tests") {

TEST_CASE("npy: real and complex arrays, 1-D and 2-D, read back as written") {
  t::TempDir dir("tsi-npy");
  const std::vector<double> real = {1.0, -2.5, 1.0 / 3.0, 1e-300, -0.0, 6.02e23};
  const std::vector<Complex> complex = {{1.0, -1.0}, {0.1, 0.2}, {-3e10, 4e-10}, {0.0, 1.0 / 7.0}, {5.0, 0.0}, {-1.0, -2.0}};
  for (const auto& shape : {shape_of({6}), shape_of({2, 3}), shape_of({3, 2, 1}), shape_of({6, 1})}) {
    const std::size_t n = 6;
    INFO("shape " << tsi::npy_shape_text(shape));
    tsi::write_npy(dir / "r.npy", std::span<const double>(real.data(), n), shape);
    tsi::write_npy(dir / "c.npy", std::span<const Complex>(complex.data(), n), shape);
    const tsi::NpyArray r = tsi::read_npy(dir / "r.npy"), c = tsi::read_npy(dir / "c.npy");
    CHECK(r.header.descr == "<f8");
    CHECK(c.header.descr == "<c16");
    CHECK_FALSE(r.header.is_complex);
    CHECK(c.header.is_complex);
    CHECK(r.header.shape == shape);
    CHECK(c.header.shape == shape);
    CHECK(r.header.major_version == 1);
    CHECK(r.header.data_offset % 64 == 0);
    REQUIRE(r.values.size() == static_cast<tsi::Index>(n));
    REQUIRE(c.values.size() == static_cast<tsi::Index>(n));
    for (std::size_t i = 0; i < n; ++i) {
      CHECK(r.values(static_cast<tsi::Index>(i)) == Complex(real[i], 0.0));
      CHECK(c.values(static_cast<tsi::Index>(i)) == complex[i]);
    }
  }
  // An empty array, and a state written as its real parts.
  tsi::write_npy(dir / "e.npy", std::span<const double>(), shape_of({0, 3}));
  CHECK(tsi::read_npy(dir / "e.npy").values.size() == 0);
  tsi::Vector x(3);
  x << Complex(1.5, 9.0), Complex(-2.0, 9.0), Complex(0.25, 9.0);
  tsi::write_npy(dir / "x.npy", x, false);
  const tsi::NpyArray back = tsi::read_npy(dir / "x.npy");
  CHECK(back.header.descr == "<f8");
  CHECK(back.header.shape == shape_of({3}));
  CHECK(back.values == x.real().cast<Complex>());
  CHECK_THROWS_WITH_AS(tsi::write_npy(dir / "bad.npy", std::span<const double>(real), shape_of({4})),
                       doctest::Contains("cannot write 6 values with shape (4,)"), tsi::Error);
  CHECK_FALSE(fs::exists(dir.path() / "bad.npy"));
}

TEST_CASE("npy: a header that does not fit format 1.0 is written as 2.0 and read back") {
  t::TempDir dir("tsi-npy");
  const std::vector<std::uint64_t> shape(30000, 1);  // "1, " 30000 times: more than 65535 bytes
  const std::vector<double> one = {42.0};
  // (the default shape of a write is 1-D)
  tsi::write_npy(dir / "flat.npy", std::span<const double>(one));
  CHECK(tsi::read_npy_header(dir / "flat.npy").shape == shape_of({1}));
  tsi::write_npy(dir / "v2.npy", std::span<const double>(one), shape);
  const tsi::NpyArray a = tsi::read_npy(dir / "v2.npy");
  CHECK(a.header.major_version == 2);
  CHECK(a.header.shape.size() == shape.size());
  CHECK(a.header.data_offset % 64 == 0);
  CHECK(a.values(0) == Complex(42.0, 0.0));
}

TEST_CASE("npy: files written by NumPy are read, in every accepted dtype and format version") {
  t::TempDir dir("tsi-npy");
  python(R"py(
rng = np.random.default_rng(7)
r = rng.standard_normal((3, 4)) * 10.0 ** rng.integers(-20, 20, (3, 4))
c = rng.standard_normal(5) + 1j * rng.standard_normal(5)
np.save('f8.npy', r)
np.save('c16.npy', c)
np.save('f4.npy', r.astype(np.float32))
np.save('c8.npy', c.astype(np.complex64))
for name, a in [('fortran1d.npy', c), ('fortran_col.npy', r[:, :1].copy())]:
    with open(name, 'wb') as f:  # np.save writes C order whenever the array is C-contiguous too
        np.lib.format.write_array_header_1_0(f, {'descr': a.dtype.str, 'fortran_order': True, 'shape': a.shape})
        f.write(a.tobytes(order='F'))
np.save('scalar.npy', np.float64(0.1))
np.save('f8_3d.npy', r.reshape(2, 3, 2))
for v in [(2, 0), (3, 0)]:
    with open('f8_v%d.npy' % v[0], 'wb') as f:
        np.lib.format.write_array(f, r, version=v)
ref = {'r': [float(v) for v in r.ravel()], 'c': [[float(v.real), float(v.imag)] for v in c],
       'r32': [float(v) for v in r.astype(np.float32).ravel()],
       'c64': [[float(v.real), float(v.imag)] for v in c.astype(np.complex64)]}
json.dump(ref, open('ref.json', 'w'))
)py",
         dir.path());
  const Json ref = t::read_json(dir.path() / "ref.json");
  const auto check_real = [&](const std::string& file, const Json& values, std::vector<std::uint64_t> shape) {
    INFO(file);
    const tsi::NpyArray a = tsi::read_npy(dir / file);
    CHECK_FALSE(a.header.is_complex);
    CHECK(a.header.shape == shape);
    REQUIRE(a.values.size() == static_cast<tsi::Index>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i)
      CHECK(a.values(static_cast<tsi::Index>(i)) == Complex(values[i].get<double>(), 0.0));
  };
  const auto check_complex = [&](const std::string& file, const Json& values) {
    INFO(file);
    const tsi::NpyArray a = tsi::read_npy(dir / file);
    CHECK(a.header.is_complex);
    REQUIRE(a.values.size() == static_cast<tsi::Index>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i)
      CHECK(a.values(static_cast<tsi::Index>(i)) == Complex(values[i][0].get<double>(), values[i][1].get<double>()));
  };
  check_real("f8.npy", ref["r"], {3, 4});
  check_real("f4.npy", ref["r32"], {3, 4});
  check_real("f8_3d.npy", ref["r"], {2, 3, 2});
  check_real("f8_v2.npy", ref["r"], {3, 4});
  check_real("f8_v3.npy", ref["r"], {3, 4});
  CHECK(tsi::read_npy_header(dir / "f8_v2.npy").major_version == 2);
  CHECK(tsi::read_npy_header(dir / "f8_v3.npy").major_version == 3);
  check_complex("c16.npy", ref["c"]);
  check_complex("c8.npy", ref["c64"]);
  check_complex("fortran1d.npy", ref["c"]);  // 1-D: Fortran order is C order
  CHECK(tsi::read_npy_header(dir / "fortran1d.npy").fortran_order);
  const tsi::NpyArray column = tsi::read_npy(dir / "fortran_col.npy");  // (3, 1): one dimension above 1
  CHECK(column.header.fortran_order);
  CHECK(column.header.shape == shape_of({3, 1}));
  for (int i = 0; i < 3; ++i) CHECK(column.values(i) == Complex(ref["r"][static_cast<std::size_t>(4 * i)].get<double>(), 0.0));
  const tsi::NpyArray scalar = tsi::read_npy(dir / "scalar.npy");
  CHECK(scalar.header.shape.empty());
  CHECK(scalar.values.size() == 1);
  CHECK(scalar.values(0) == Complex(0.1, 0.0));
}

TEST_CASE("npy: NumPy reads tsi's files back, and they are byte for byte what np.save writes") {
  t::TempDir dir("tsi-npy");
  std::vector<double> real;
  std::vector<Complex> complex;
  for (int i = 0; i < 24; ++i) {
    real.push_back(std::ldexp(1.0 + i / 7.0, 3 * i - 30) * (i % 3 == 0 ? -1.0 : 1.0));
    complex.emplace_back(1.0 / (i + 1), -std::sqrt(static_cast<double>(i)));
  }
  Json ref = {{"r", real}, {"c", Json::array()}};
  for (const auto& z : complex) ref["c"].push_back({z.real(), z.imag()});
  t::write_text(dir.path() / "ref.json", ref.dump());
  tsi::write_npy(dir / "r1.npy", std::span<const double>(real));
  tsi::write_npy(dir / "r2.npy", std::span<const double>(real), shape_of({4, 6}));
  tsi::write_npy(dir / "c1.npy", std::span<const Complex>(complex));
  tsi::write_npy(dir / "c3.npy", std::span<const Complex>(complex), shape_of({2, 3, 4}));
  tsi::write_npy(dir / "big.npy", std::span<const double>(real.data(), 1), shape_of({1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1}));
  python(R"py(
ref = json.load(open('ref.json'))
r = np.array(ref['r'], dtype='<f8')
c = np.array([complex(a, b) for a, b in ref['c']], dtype='<c16')
cases = {'r1.npy': r, 'r2.npy': r.reshape(4, 6), 'c1.npy': c, 'c3.npy': c.reshape(2, 3, 4),
         'big.npy': r[:1].reshape((1,) * 12)}
for name, want in cases.items():
    got = np.load(name)
    assert got.dtype == want.dtype and got.shape == want.shape, (name, got.dtype, got.shape)
    assert np.array_equal(got, want), name
    np.save('numpy_' + name, want)
    assert open(name, 'rb').read() == open('numpy_' + name, 'rb').read(), name + ': not the bytes np.save writes'
)py",
         dir.path());
}

TEST_CASE("npy: malformed, lying and unsupported files are refused naming the file, without large allocations") {
  t::TempDir dir("tsi-npy");
  const auto file = [&](const std::string& name, const std::string& bytes) {
    t::write_text(dir.path() / name, bytes);
    return dir / name;
  };
  const std::string good = raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (2,), }", doubles({1.0, 2.0}));
  REQUIRE(read_error(file("good.npy", good)).empty());

  const auto refused = [&](const std::string& name, const std::string& bytes, std::vector<std::string> words) {
    const std::string path = file(name, bytes);
    const std::string what = read_error(path);
    INFO(name << ": " << what);
    CHECK(t::contains(what, path));
    for (const auto& w : words) CHECK(t::contains(what, w));
  };
  refused("truncated.npy", good.substr(0, good.size() - 3), {"truncated", "needs 16 bytes", "holds 13"});
  refused("trailing.npy", good + "xyz", {"more data than its header says"});
  refused("wrong-magic.npy", "\x93NUMPZ" + good.substr(6), {"not a .npy file"});
  refused("text.npy", "{\"model\": 1}\n", {"not a .npy file"});
  refused("tiny.npy", "\x93NU", {"too short for a .npy file"});
  refused("empty.npy", "", {"too short"});
  refused("version.npy", good.substr(0, 6) + "\x04" + good.substr(7), {"format version 4.0", "expected 1.0, 2.0 or 3.0"});
  refused("big-endian.npy", raw_npy("{'descr': '>f8', 'fortran_order': False, 'shape': (2,), }", doubles({1.0, 2.0})),
          {"'>f8' is big-endian", "'<f8'", "'<c16'"});
  refused("int.npy", raw_npy("{'descr': '<i8', 'fortran_order': False, 'shape': (2,), }", doubles({1.0, 2.0})),
          {"dtype '<i8' is not supported", "expected float64 '<f8' or complex128 '<c16'"});
  refused("structured.npy", raw_npy("{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (2,), }", doubles({1.0, 2.0})),
          {"structured dtype"});
  refused("shape-lies.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (3,), }", doubles({1.0, 2.0})),
          {"truncated, or not what its header says", "(3,)"});
  // Shapes far beyond the file: refused from the header alone (an allocation of 8 TB or of
  // 2^64 values would abort the process).
  refused("huge.npy", raw_npy("{'descr': '<c16', 'fortran_order': False, 'shape': (1000000, 1000000), }", doubles({1.0})),
          {"(1000000, 1000000)", "16000000000000 bytes"});
  refused("overflow.npy",
          raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (4294967296, 4294967296, 2), }", doubles({1.0})),
          {"more than 2^64 values"});
  refused("overflow-bytes.npy", raw_npy("{'descr': '<c16', 'fortran_order': False, 'shape': (4611686018427387904,), }", ""),
          {"more than 2^64"});
  refused("dimension.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (99999999999999999999999,), }", ""),
          {"beyond 2^64"});
  refused("fortran-2d.npy", raw_npy("{'descr': '<f8', 'fortran_order': True, 'shape': (2, 2), }", doubles({1, 2, 3, 4})),
          {"Fortran-ordered array of shape (2, 2)", "np.ascontiguousarray"});
  refused("no-shape.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, }", doubles({1.0})), {"has no 'shape'"});
  refused("extra-key.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'x': 1, }", doubles({1.0})),
          {"malformed"});
  refused("extra-key2.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), 'x': 'y', }", doubles({1.0})),
          {"unexpected key 'x'"});
  refused("twice.npy", raw_npy("{'descr': '<f8', 'descr': '<f8', 'fortran_order': False, 'shape': (1,), }", doubles({1.0})),
          {"appears twice"});
  refused("garbage.npy", raw_npy("{'descr': '<f8', 'fortran_order': Flase, 'shape': (1,), }", doubles({1.0})),
          {"malformed"});
  refused("unclosed.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,", doubles({1.0})), {"malformed"});
  refused("negative.npy", raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (-1,), }", doubles({1.0})),
          {"malformed"});
  refused("bool-order.npy", raw_npy("{'descr': '<f8', 'fortran_order': 0, 'shape': (1,), }", doubles({1.0})), {"malformed"});
  // A header length beyond the file, and beyond any plain array's header.
  std::string long_header = good;
  long_header[8] = '\xff', long_header[9] = '\x7f';
  refused("header-beyond.npy", long_header, {"truncated", "the .npy header claims 32767 bytes"});
  std::string v2 = raw_npy("{'descr': '<f8', 'fortran_order': False, 'shape': (1,), }", doubles({1.0}), 2);
  v2[11] = '\x7f';  // a 2 GB header
  refused("header-huge.npy", v2, {"at most 1048576 are read"});

  const std::string missing = dir / "missing.npy";
  CHECK(t::contains(read_error(missing), missing + ": cannot open: No such file or directory"));
  fs::create_directory(dir.path() / "dir.npy");
  CHECK(t::contains(read_error(dir / "dir.npy"), "not a regular file"));
  REQUIRE(::mkfifo((dir / "fifo.npy").c_str(), 0600) == 0);  // refused at once, not waited on
  CHECK(t::contains(read_error(dir / "fifo.npy"), "not a regular file"));
  // The header reader checks the same sizes, without reading the data.
  CHECK_THROWS_WITH_AS(tsi::read_npy_header(dir / "huge.npy"), doctest::Contains("(1000000, 1000000)"), tsi::Error);
}

TEST_CASE("npy: a write that fails (a full disk) is an IoError naming the file, and leaves nothing behind") {
  t::TempDir dir("tsi-npy");
  const std::vector<double> values(200000, 0.5);  // 1.6 MB
  CHECK_THROWS_WITH_AS(tsi::write_npy(dir / "no-such-dir/u.npy", std::span<const double>(values)),
                       doctest::Contains(("cannot write " + dir / "no-such-dir/u.npy").c_str()), tsi::IoError);
  // A file size limit: writes beyond it fail with EFBIG, as on a full disk.
  rlimit old{};
  REQUIRE(getrlimit(RLIMIT_FSIZE, &old) == 0);
  const auto previous = std::signal(SIGXFSZ, SIG_IGN);
  rlimit limited = old;
  limited.rlim_cur = 100000;
  REQUIRE(setrlimit(RLIMIT_FSIZE, &limited) == 0);
  std::string what;
  try {
    tsi::write_npy(dir / "u.npy", std::span<const double>(values));
  } catch (const tsi::IoError& e) {
    what = e.what();
  }
  REQUIRE(setrlimit(RLIMIT_FSIZE, &old) == 0);
  std::signal(SIGXFSZ, previous);
  CHECK(t::contains(what, "cannot write " + dir / "u.npy" + ": File too large"));
  CHECK_FALSE(fs::exists(dir.path() / "u.npy"));
  CHECK(fs::is_empty(dir.path()));  // no temporary file either
  // The same file written whole replaces an older one atomically.
  tsi::write_npy(dir / "u.npy", std::span<const double>(values.data(), 2));
  tsi::write_npy(dir / "u.npy", std::span<const double>(values));
  CHECK(tsi::read_npy(dir / "u.npy").values.size() == 200000);
}

}  // TEST_SUITE
