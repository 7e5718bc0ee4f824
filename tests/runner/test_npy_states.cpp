// States as .npy files end to end: model.u0 naming a file (relative to the config or study),
// the same run as the same u0 in JSON to the bit; u_final.npy (and reference_u_final.npy)
// beside every result.json, equal to its u_final, in u0's shape; large states only as files;
// bad files refused as bad input naming model.u0 and the file; a file that cannot be written
// is exit code 3.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "run_command.hpp"
#include "tsi/npy.hpp"
#include "tsi/phase.hpp"

namespace t = tsi::test;

namespace {

// Runs a NumPy script with Debian's interpreter (scripts/install-deps.sh installs python3-numpy).
void python(const std::string& script, const std::string& cwd) {
  const t::CommandResult r = t::run_command("/usr/bin/python3", {"-c", "import numpy as np, json, sys\n" + script}, {}, cwd);
  INFO("the test needs /usr/bin/python3 with numpy (python3-numpy, scripts/install-deps.sh)");
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
}

// result.json's u_final (numbers, or [re, im] pairs) equals the values of `file`, exactly.
void check_state_file(const t::fs::path& file, const t::Json& state, bool complex_state) {
  INFO(file.string());
  const tsi::NpyArray a = tsi::read_npy(file.string());
  CHECK(a.header.descr == (complex_state ? "<c16" : "<f8"));
  REQUIRE(a.values.size() == static_cast<tsi::Index>(state.size()));
  for (std::size_t i = 0; i < state.size(); ++i) {
    const tsi::Complex want = complex_state ? tsi::Complex(state[i][0].get<double>(), state[i][1].get<double>())
                                            : tsi::Complex(state[i].get<double>(), 0.0);
    CHECK(a.values(static_cast<tsi::Index>(i)) == want);
  }
}

t::Json hh_config() {
  return {{"model", {{"name", "henon-heiles"}, {"eps", 0.1}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}}},
          {"scheme", {{"name", "se1"}}},
          {"time", {{"h", 0.25}, {"t_end", 1.0}}},
          {"reference", t::Json::object()}};
}

t::Json nls_config(int n_x) {
  return {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", n_x}}},
          {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}}},
          {"scheme", {{"name", "se1"}}},
          {"time", {{"h", 0.25}, {"t_end", 0.5}}},
          {"reference", t::Json::object()}};
}

// NLS on 8192 points, two Strang steps on the direct problem against Strang at half the step:
// a state of 8192 complex values, above what result.json holds inline, in a fraction of a second.
t::Json large_nls_config() {
  return {{"model", {{"name", "nls"}, {"eps", 0.1}, {"n_x", 8192}}},
          {"reformulation", {{"name", "direct"}}},
          {"scheme", {{"name", "strang"}}},
          {"time", {{"h", 0.125}, {"t_end", 0.25}}},
          {"reference", {{"scheme", "strang"}, {"reformulation", "direct"}, {"h", 0.0625}}}};
}

}  // namespace

TEST_SUITE("tsi_runner_tests") {

TEST_CASE("npy states: u0 from a .npy file runs bit for bit as the same u0 in JSON, u_final.npy is result.json's u_final") {
  for (const bool complex_model : {false, true}) {
    CAPTURE(complex_model);
    t::TempDir dir("tsi-npy-run");
    t::fs::create_directory(dir.path() / "configs");
    // Values a JSON number and a float64 hold alike (Python's repr round-trips).
    python(complex_model ? R"py(
x = np.linspace(0, 2 * np.pi, 8, endpoint=False)
u = (1 + 0.3 * np.cos(x)) * np.exp(1j * x) / 3
np.save('configs/u0.npy', u)
json.dump([[float(v.real), float(v.imag)] for v in u], open('u0.json', 'w'))
)py"
                         : R"py(
u = np.array([0.12, -0.1, 0.13, 1 / 9])
np.save('configs/u0.npy', u)
json.dump([float(v) for v in u], open('u0.json', 'w'))
)py",
           dir.path());
    t::Json with_file = complex_model ? nls_config(8) : hh_config(), with_json = with_file;
    with_file["model"]["u0"] = "u0.npy";  // relative to the config's directory, not to where tsi runs
    with_json["model"]["u0"] = t::read_json(dir.path() / "u0.json");
    const std::string config_file = t::write_config(dir, with_file, "configs/file.json");
    const std::string config_json = t::write_config(dir, with_json, "configs/json.json");
    const t::CommandResult a = t::run_tsi({"run", config_file, "--out", dir / "a"}, {}, "/");
    const t::CommandResult b = t::run_tsi({"run", config_json, "--out", dir / "b"}, {}, "/");
    INFO(a.describe());
    INFO(b.describe());
    REQUIRE(a.exit_code == 0);
    REQUIRE(b.exit_code == 0);
    CHECK(t::contains(a.out, dir / "a/u_final.npy"));
    CHECK(t::contains(a.out, dir / "a/reference_u_final.npy"));
    const t::Json ra = t::read_json(dir.path() / "a/result.json"), rb = t::read_json(dir.path() / "b/result.json");
    // The resolved config records the file's absolute name.
    CHECK(ra["config"]["model"]["u0"] == (dir.path() / "configs/u0.npy").string());
    CHECK(ra["u_final"] == rb["u_final"]);
    CHECK(ra["error"]["relative"] == rb["error"]["relative"]);
    CHECK(ra["error"]["reference"]["u_final"] == rb["error"]["reference"]["u_final"]);
    CHECK(ra["invariants"] == rb["invariants"]);
    CHECK(t::read_text(dir.path() / "a/invariants.csv") == t::read_text(dir.path() / "b/invariants.csv"));
    for (const char* file : {"u_final.npy", "reference_u_final.npy"})
      CHECK(t::read_text(dir.path() / "a" / file) == t::read_text(dir.path() / "b" / file));
    REQUIRE(ra["u_final"].is_array());
    check_state_file(dir.path() / "a/u_final.npy", ra["u_final"], complex_model);
    check_state_file(dir.path() / "a/reference_u_final.npy", ra["error"]["reference"]["u_final"], complex_model);
    // NumPy reads them as the same state.
    python(R"py(
r = json.load(open('a/result.json'))
def state(v):
    a = np.array(v, dtype=float)
    return a[:, 0] + 1j * a[:, 1] if a.ndim == 2 else a
for name, want in [('a/u_final.npy', r['u_final']), ('a/reference_u_final.npy', r['error']['reference']['u_final'])]:
    got = np.load(name)
    assert got.shape == (len(want),) and np.array_equal(got, state(want)), name
    assert got.dtype == (np.complex128 if isinstance(want[0], list) else np.float64), got.dtype
)py",
           dir.path());
  }
}

TEST_CASE("npy states: a state above 4096 values is only a file in result.json, in the shape of u0's file") {
  t::TempDir dir("tsi-npy-run");
  python(R"py(
x = np.linspace(0, 2 * np.pi, 8192, endpoint=False)
np.save('u0.npy', ((1 + 0.3 * np.cos(x)) * np.exp(1j * x) / 3).reshape(64, 128))
np.save('hh.npy', np.array([[0.12, 0.12], [0.12, 0.12]]))
)py",
         dir.path());
  t::Json config = large_nls_config();
  config["model"]["u0"] = "u0.npy";
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  const t::Json result = t::read_json(dir.path() / "out/result.json");
  const t::Json entry = {{"file", "u_final.npy"}, {"dtype", "complex128"}, {"shape", {64, 128}}};
  CHECK(result["u_final"] == entry);
  t::Json reference_entry = entry;
  reference_entry["file"] = "reference_u_final.npy";
  CHECK(result["error"]["reference"]["u_final"] == reference_entry);
  CHECK(t::read_text(dir.path() / "out/result.json").size() < 20000);  // no state in it
  const tsi::NpyArray u = tsi::read_npy(dir / "out/u_final.npy"), ref = tsi::read_npy(dir / "out/reference_u_final.npy");
  CHECK(u.header.shape == std::vector<std::uint64_t>{64, 128});
  CHECK(ref.header.shape == std::vector<std::uint64_t>{64, 128});
  CHECK(u.values.allFinite());
  // The error result.json reports is that of the two files (discrete L2 on the grid: a ratio of norms).
  const double error = (u.values - ref.values).norm() / ref.values.norm();
  CHECK(error == doctest::Approx(result["error"]["relative"].get<double>()).epsilon(1e-12));

  // Without a file, the states are 1-D; a small state stays inline and keeps u0's shape in its file.
  config["model"].erase("u0");
  const t::CommandResult flat = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "flat"});
  REQUIRE(flat.exit_code == 0);
  CHECK(t::read_json(dir.path() / "flat/result.json")["u_final"]["shape"] == t::Json::array({8192}));
  t::Json hh = hh_config();
  hh["model"]["u0"] = "hh.npy";
  const t::CommandResult small = t::run_tsi({"run", t::write_config(dir, hh), "--out", dir / "hh"});
  REQUIRE(small.exit_code == 0);
  const t::Json hh_result = t::read_json(dir.path() / "hh/result.json");
  CHECK(hh_result["u_final"].size() == 4);
  CHECK(tsi::read_npy_header(dir / "hh/u_final.npy").shape == std::vector<std::uint64_t>{2, 2});
  python("assert np.load('hh/u_final.npy').shape == (2, 2)\nassert np.load('out/u_final.npy').shape == (64, 128)",
         dir.path());
}

TEST_CASE("npy states: a 2-D grid's states are (n_x, n_y) arrays, from u0's file and without one") {
  // 2-D NLS on 8 x 6 points, u0 a plane wave of modulus 0.5 as an (8, 6) array: u_final.npy and
  // the reference's have the grid's shape, with a file or without (the model's physical shape),
  // and the run keeps the modulus (the plane wave turns in place).
  t::TempDir dir("tsi-npy-grid");
  python(R"py(
x = np.arange(8) * 2 * np.pi / 8
y = np.arange(6) * 2 * np.pi / 6
np.save('u0.npy', 0.5 * np.exp(1j * x)[:, None] * np.exp(-2j * y)[None, :])
)py",
         dir.path());
  t::Json config = nls_config(8);
  config["model"]["dims"] = 2;
  config["model"]["n_y"] = 6;
  config["model"]["u0"] = "u0.npy";
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"});
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  CHECK(tsi::read_npy_header(dir / "out/u_final.npy").shape == std::vector<std::uint64_t>{8, 6});
  CHECK(tsi::read_npy_header(dir / "out/reference_u_final.npy").shape == std::vector<std::uint64_t>{8, 6});
  python("u = np.load('out/u_final.npy')\nassert u.shape == (8, 6)\nassert abs(abs(u) - 0.5).max() < 1e-10", dir.path());
  config["model"].erase("u0");
  const t::CommandResult plain = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "plain"});
  REQUIRE(plain.exit_code == 0);
  CHECK(tsi::read_npy_header(dir / "plain/u_final.npy").shape == std::vector<std::uint64_t>{8, 6});
}

TEST_CASE("npy states: a run that stops part-way writes u_final.npy of its last state, a stale reference file goes") {
  t::TempDir dir("tsi-npy-run");
  t::Json config = hh_config();
  const t::CommandResult first = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"});
  REQUIRE(first.exit_code == 0);
  REQUIRE(t::fs::exists(dir.path() / "out/reference_u_final.npy"));
  config.erase("reference");
  config["monitor"] = {{"max_err_H", 1e-12}};  // a blow-up at the first step
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"});
  INFO(r.describe());
  CHECK(r.exit_code == 1);
  const t::Json result = t::read_json(dir.path() / "out/result.json");
  CHECK(result["status"] == "blow-up");
  CHECK(result["steps"] == 1);
  check_state_file(dir.path() / "out/u_final.npy", result["u_final"], false);
  CHECK_FALSE(t::fs::exists(dir.path() / "out/reference_u_final.npy"));  // from the run before
}

TEST_CASE("npy states: a bad u0 file is bad input naming model.u0 and the file, before anything is written") {
  t::TempDir dir("tsi-npy-run");
  python(R"py(
np.save('five.npy', np.full(5, 0.1))
np.save('complex.npy', np.array([0.1, 0.1, 0.1, 0.1 + 1e-3j]))
np.save('nan.npy', np.array([[0.1, np.nan], [0.1, 0.1]]))
np.save('big_endian.npy', np.full(4, 0.1).astype('>f8'))
np.save('ints.npy', np.ones(4, dtype=np.int64))
np.save('real_zero_imag.npy', np.full(4, 0.12 + 0j))
b = open('five.npy', 'rb').read()
open('truncated.npy', 'wb').write(b[:-8])
open('lying.npy', 'wb').write(b.replace(b"(5,)", b"(9,)"))
)py",
         dir.path());
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
      {"five.npy", {"5 values (shape (5,)), expected 4 (the model's dimension"}},
      {"complex.npy", {"entry 3 is 0.1+0.001j", "expected real values"}},
      {"nan.npy", {"entry 1 (index (0, 1) of shape (2, 2)) is nan", "expected finite values"}},
      {"big_endian.npy", {"'>f8' is big-endian"}},
      {"ints.npy", {"dtype '<i8' is not supported"}},
      {"truncated.npy", {"truncated"}},
      {"lying.npy", {"truncated, or not what its header says", "(9,)"}},
      {"missing.npy", {"cannot open: No such file or directory"}},
      {"sub/../missing.npy", {"cannot open"}}};
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const auto& [file, words] = cases[k];
    CAPTURE(file);
    t::Json config = hh_config();
    config["model"]["u0"] = file;
    const std::string out = dir / ("out-" + std::to_string(k));
    const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", out});
    INFO(r.describe());
    CHECK(r.exit_code == 2);
    const std::string path = t::fs::path(dir / file).lexically_normal().string();
    CHECK(t::contains(r.err, "tsi: error: model.u0: " + path));
    for (const auto& w : words) CHECK(t::contains(r.err, w));
    CHECK_FALSE(t::fs::exists(t::fs::path(out) / "result.json"));
  }
  // A complex file of zero imaginary parts is a real u0.
  t::Json config = hh_config();
  config["model"]["u0"] = "real_zero_imag.npy";
  const t::CommandResult ok = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "ok"});
  INFO(ok.describe());
  CHECK(ok.exit_code == 0);
}

TEST_CASE("npy states: a study's u0 files are relative to the study, and every run writes u_final.npy") {
  t::TempDir dir("tsi-npy-run");
  t::fs::create_directory(dir.path() / "study");
  python("np.save('study/a.npy', np.full(4, 0.12))\nnp.save('study/b.npy', np.full(4, 0.1))", dir.path());
  t::Json base = hh_config();
  base.erase("reference");
  base["model"]["u0"] = "a.npy";
  const t::Json study = {{"kind", "conservation"},
                         {"base", base},
                         {"cases", {{{"label", "a"}}, {{"label", "b"}, {"set", {{"model.u0", "b.npy"}}}}}}};
  const std::string file = t::write_config(dir, study, "study/study.json");
  const t::CommandResult r = t::run_tsi({"study", file, "--out", dir / "out", "--jobs", "1", "--no-plots"}, {}, "/");
  INFO(r.describe());
  REQUIRE(r.exit_code == 0);
  for (const auto& [id, name] : {std::pair{"r0001", "a.npy"}, std::pair{"r0002", "b.npy"}}) {
    const t::fs::path run = dir.path() / "out/runs" / id;
    const t::Json result = t::read_json(run / "result.json");
    CHECK(result["config"]["model"]["u0"] == (dir.path() / "study" / name).string());
    check_state_file(run / "u_final.npy", result["u_final"], false);
  }
  CHECK(t::read_json(dir.path() / "out/runs/r0001/result.json")["u_final"] !=
        t::read_json(dir.path() / "out/runs/r0002/result.json")["u_final"]);
}

TEST_CASE("npy states: a u_final.npy that cannot be written (a full disk) is exit code 3, and result.json says so") {
  t::TempDir dir("tsi-npy-run");
  t::Json config = large_nls_config();
  config.erase("reference");
  t::CommandEnv env;
  env.file_size_limit = 100000;  // u_final.npy has 131,200 bytes; result.json and invariants.csv fit
  const t::CommandResult r = t::run_tsi({"run", t::write_config(dir, config), "--out", dir / "out"}, env);
  INFO(r.describe());
  CHECK(r.exit_code == 3);
  CHECK(t::contains(r.err, "tsi: error: cannot write " + dir / "out/u_final.npy" + ": File too large"));
  const t::Json result = t::read_json(dir.path() / "out/result.json");
  CHECK(result["status"] == "failed");
  CHECK(t::contains(result["message"].get<std::string>(), "u_final.npy: File too large"));
  CHECK_FALSE(t::fs::exists(dir.path() / "out/u_final.npy"));
  for (const auto& entry : t::fs::directory_iterator(dir.path() / "out"))
    CHECK_FALSE(t::contains(entry.path().filename().string(), ".tmp."));
}

}  // TEST_SUITE

namespace {

// vlasov-poisson-2d re-prepared every step (the UA-PIC set-up: each step starts again from the
// physical particles) over 2 T in one run, and over T, then T more from its state.npy: the
// largest difference of the final particles.
double resumed_difference(double h, double t) {
  t::TempDir dir("tsi-npy-resume");
  t::Json whole = {{"model", {{"name", "vlasov-poisson-2d"}, {"eps", 0.1}, {"particles", 256}, {"n_x", 8}, {"n_y", 8}}},
                   {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}, {"initial_data_order", 2}, {"reprepare", 1}}},
                   {"scheme", {{"name", "etd2rk"}}},
                   {"time", {{"h", h}, {"t_end", 2.0 * t}}},
                   {"output", {{"every", 4}, {"state_every", 4}}}};
  t::Json first = whole;
  first["time"]["t_end"] = t;
  const t::CommandResult a = t::run_tsi({"run", t::write_config(dir, whole, "whole.json"), "--out", dir / "whole"});
  REQUIRE_MESSAGE(a.exit_code == 0, a.describe());
  const t::CommandResult b = t::run_tsi({"run", t::write_config(dir, first, "first.json"), "--out", dir / "first"});
  REQUIRE_MESSAGE(b.exit_code == 0, b.describe());
  const t::Json record = t::read_json(dir.path() / "first" / "result.json");
  REQUIRE(record.contains("state"));
  CHECK(record["state"]["t"].get<double>() == doctest::Approx(t).epsilon(1e-15));
  CHECK(record["state"]["step"].get<long>() == 8);
  t::Json second = first;
  second["model"]["particles"] = dir / "first/state.npy";
  const t::CommandResult c = t::run_tsi({"run", t::write_config(dir, second, "second.json"), "--out", dir / "second"});
  REQUIRE_MESSAGE(c.exit_code == 0, c.describe());
  const tsi::NpyArray state = tsi::read_npy(dir / "first/state.npy");
  CHECK(state.header.shape == std::vector<std::uint64_t>{256, 4});
  // The state keeps positions in the box [0, 4 pi) x [0, 2 pi) (k_x = 0.5, k_y = 1); u_final
  // the unwrapped trajectories: the resumed run's positions differ from the whole run's by
  // whole box lengths where the state wrapped them.
  const double lengths[2] = {2.0 * tsi::two_pi, tsi::two_pi};
  for (tsi::Index i = 0; i < state.values.size(); ++i)
    if (i % 4 < 2) {
      CHECK(state.values(i).real() >= 0.0);
      CHECK(state.values(i).real() < lengths[i % 4]);
    }
  const tsi::NpyArray u_whole = tsi::read_npy(dir / "whole/u_final.npy"), u_resumed = tsi::read_npy(dir / "second/u_final.npy");
  REQUIRE(u_whole.values.size() == u_resumed.values.size());
  double largest = 0.0;
  for (tsi::Index i = 0; i < u_whole.values.size(); ++i) {
    double d = u_whole.values(i).real() - u_resumed.values(i).real();
    if (i % 4 < 2) d -= lengths[i % 4] * std::round(d / lengths[i % 4]);
    largest = std::max(largest, std::abs(d));
  }
  return largest / u_whole.values.cwiseAbs().maxCoeff();
}

}  // namespace

TEST_CASE("npy states: a particle run resumed from its state.npy (output.state_every) ends where the whole run ends") {
  // Where t / eps is a tau-grid point (h = pi/16, the peer's: t_n / eps = n 5 pi / 8, on the
  // grid of n_tau = 16) the data re-prepared at the restart are the whole run's, shifted by
  // grid points: the same numbers to rounding.
  const double on_grid = resumed_difference(tsi::two_pi / 32.0, tsi::two_pi / 4.0);
  CAPTURE(on_grid);
  CHECK(on_grid < 1e-13);
  // Elsewhere the restart centres its data at phase 0 instead of t / eps: a difference of the
  // scheme's order (measured 5e-9 relative, h = 1/8, against errors of 1e-5).
  const double off_grid = resumed_difference(0.125, 1.0);
  CAPTURE(off_grid);
  CHECK(off_grid > 0.0);
  CHECK(off_grid < 1e-6);
}

TEST_CASE("npy states: a particle run that carried particles more than a box length out resumes from its state.npy") {
  // At eps = 1 the gyration radius is |v| (up to 5, the peer's streams at v1 = +-2): by t = 4
  // particles are farther than 2 pi out along x2, where the particle files' box check refuses
  // positions. state.npy holds them wrapped into the box.
  t::TempDir dir("tsi-npy-far");
  const t::Json far = {{"model", {{"name", "vlasov-poisson-2d"}, {"eps", 1.0}, {"particles", 256}, {"distribution", "peer"},
                                  {"n_x", 8}, {"n_y", 8}}},
                       {"reformulation", {{"name", "two-scale"}, {"n_tau", 16}, {"initial_data_order", 2}, {"reprepare", 1}}},
                       {"scheme", {{"name", "etd2rk"}}},
                       {"time", {{"h", 0.125}, {"t_end", 4.0}}},
                       {"output", {{"every", 8}, {"state_every", 8}}}};
  const t::CommandResult a = t::run_tsi({"run", t::write_config(dir, far, "far.json"), "--out", dir / "far"});
  REQUIRE_MESSAGE(a.exit_code == 0, a.describe());
  const tsi::NpyArray u = tsi::read_npy(dir / "far/u_final.npy"), state = tsi::read_npy(dir / "far/state.npy");
  const double length_y = tsi::two_pi;
  bool far_out = false;
  for (tsi::Index k = 0; k < u.values.size() / 4; ++k) {
    const double x2 = u.values(4 * k + 1).real(), wrapped = state.values(4 * k + 1).real();
    far_out = far_out || x2 < -length_y || x2 >= 2.0 * length_y;
    CHECK(wrapped >= 0.0);
    CHECK(wrapped < length_y);
    CHECK(std::abs(std::remainder(x2 - wrapped, length_y)) < 1e-12);  // the same point of the periodic box
  }
  REQUIRE(far_out);  // the case this test is about
  t::Json resumed = far;
  resumed["model"]["particles"] = dir / "far/state.npy";
  const t::CommandResult b = t::run_tsi({"run", t::write_config(dir, resumed, "resumed.json"), "--out", dir / "resumed"});
  CHECK_MESSAGE(b.exit_code == 0, b.describe());
}
