// `mpirun -np P tsi run CONFIG --split` on a spectral grid: nls, klein-gordon and
// klein-gordon-complex in 2-D and 3-D, split in slabs of the first direction over 2 and 3 ranks (FFTW's MPI transforms),
// give the run on one process to 1e-12 (u, every invariant row, the fixed-point sweeps and the
// field snapshots of output.fields_every, read back with h5py against their XDMF file), and a
// grid that cannot be split is refused, naming the field. Built only with MPI (TSI_WITH_MPI).
#include <doctest/doctest.h>

#ifdef TSI_TEST_MPIEXEC
#include <cmath>
#include <string>
#include <vector>

#include "run_command.hpp"
#include "split_run.hpp"

namespace t = tsi::test;

namespace {

t::Json grid_config(t::Json model, const std::string& reformulation, const std::string& scheme) {
  t::Json config = {{"model", std::move(model)},
                    {"reformulation", {{"name", reformulation}}},
                    {"scheme", {{"name", scheme}}},
                    {"time", {{"h", 0.02}, {"t_end", 0.2}}},
                    {"output", {{"every", 1}, {"fields_every", 5}}}};
  if (reformulation == "two-scale") config["reformulation"]["n_tau"] = 16;
  return config;
}

// fields.h5 of the split run (`b`) against the one-process run's (`a`), with h5py: the same
// snapshots and arrays to 1e-12 of their largest entry, every array fields.xmf names present
// with its shape, the grid's attributes, and the last snapshot's |u| that of u_final.npy.
void check_fields(const t::fs::path& a, const t::fs::path& b, int fields) {
  const std::string script = R"(
import sys, h5py, numpy as np, xml.etree.ElementTree as ET
a, b, fields = sys.argv[1], sys.argv[2], int(sys.argv[3])
A, B = h5py.File(a + '/fields.h5', 'r'), h5py.File(b + '/fields.h5', 'r')
assert list(A['fields']) == list(B['fields']) and len(A['fields']) == 3, (list(A['fields']), list(B['fields']))
assert (A.attrs['grid_shape'] == B.attrs['grid_shape']).all()
worst = 0.0
for g in A['fields']:
    assert A['fields'][g].attrs['time'] == B['fields'][g].attrs['time']
    assert len(A['fields'][g]) == 3 * fields, list(A['fields'][g])
    for d in A['fields'][g]:
        x, y = A['fields'][g][d][()], B['fields'][g][d][()]
        assert x.shape == tuple(A.attrs['grid_shape']), (d, x.shape)
        worst = max(worst, np.abs(x - y).max() / np.abs(x).max())
assert worst < 1e-12, worst
items = ET.parse(b + '/fields.xmf').getroot().iter('DataItem')
named = [i for i in items if i.get('Format') == 'HDF']
assert len(named) == 3 * 3 * fields, len(named)
for i in named:
    file, path = i.text.split(':')
    assert file == 'fields.h5' and B[path].shape == tuple(int(n) for n in i.get('Dimensions').split()), i.text
u = np.load(b + '/u_final.npy')
last = B['fields'][list(B['fields'])[-1]]
first = sorted(k for k in last if k.endswith('_abs'))[0]  # u, or v of the real Klein-Gordon
np.testing.assert_allclose(last[first][()], np.abs(u if fields == 1 else u[0]), rtol=0, atol=1e-14 * np.abs(u).max())
print('fields agree to', worst)
)";
  const t::CommandResult r =
      t::run_command("/usr/bin/python3", {"-c", script, a.string(), b.string(), std::to_string(fields)});
  INFO("the test needs /usr/bin/python3 with h5py (python3-h5py, scripts/install-deps.sh)");
  INFO(r.describe());
  CHECK(r.exit_code == 0);
}

struct Case {
  std::string label;
  t::Json config;
  int fields;  // the model's grid fields (klein-gordon-complex: u and v)
};

// The case run on one process, then split over each of `ranks`: u, every row of invariants.csv,
// the fixed-point sweeps and the field snapshots agree to 1e-12.
void check_split_matches(const Case& c, const std::vector<int>& ranks) {
  CAPTURE(c.label);
  t::TempDir dir("tsi-split-grid");
  const std::string config = t::write_config(dir, c.config, "run.json");
  const t::CommandResult one = t::run_tsi({"run", config, "--out", dir / "one"});
  REQUIRE_MESSAGE(one.exit_code == 0, one.describe());
  const t::Json one_record = t::read_json(dir.path() / "one/result.json");
  for (const int p : ranks) {
    CAPTURE(p);
    const std::string out = dir / ("split" + std::to_string(p));
    const t::CommandResult split = t::split_run(p, {config, "--out", out});
    REQUIRE_MESSAGE(split.exit_code == 0, split.describe());
    const t::Json record = t::read_json(t::fs::path(out) / "result.json");
    CHECK(record["split"]["processes"] == p);
    CHECK(record["fields"]["snapshots"] == 3);  // steps 0, 5 and 10
    CHECK(t::relative_difference(dir.path() / "one/u_final.npy", t::fs::path(out) / "u_final.npy") < 1e-12);
    const auto rows = t::csv_rows(dir.path() / "one/invariants.csv"),
               split_rows = t::csv_rows(t::fs::path(out) / "invariants.csv");
    REQUIRE(rows.size() == 11);
    REQUIRE(rows.size() == split_rows.size());
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (std::size_t j = 0; j < rows[i].size(); ++j)
        CHECK(std::abs(split_rows[i][j] - rows[i][j]) <= 1e-12 * std::abs(rows[i][j]) + 1e-13);
    CHECK(record["solver"] == one_record["solver"]);
    check_fields(dir.path() / "one", out, c.fields);
  }
}

const t::Json nls2 = {{"name", "nls"}, {"dims", 2}, {"n_x", 12}, {"n_y", 6}, {"eps", 0.05}};
const t::Json kg2 = {{"name", "klein-gordon-complex"}, {"dims", 2}, {"n_x", 12}, {"n_y", 6}, {"eps", 0.05},
                     {"data", "cai-zhou"}};

}  // namespace

TEST_CASE("split grid run: nls and klein-gordon-complex in 2-D with SE1 on 2 ranks give one rank's run to 1e-12") {
  for (const Case& c : {Case{"nls 2-D se1", grid_config(nls2, "two-scale", "se1"), 1},
                        Case{"kg 2-D se1", grid_config(kg2, "two-scale", "se1"), 2}})
    check_split_matches(c, {2});
}

TEST_CASE("split grid run: nls and klein-gordon, real and complex, in 2-D and 3-D on 2 and 3 ranks give one rank's run to 1e-12") {
  const t::Json nls3 = {{"name", "nls"}, {"dims", 3}, {"n_x", 6}, {"n_y", 6}, {"n_z", 4}, {"eps", 0.1}};
  const t::Json kg3 = {{"name", "klein-gordon-complex"}, {"dims", 3}, {"n_x", 6}, {"n_y", 6}, {"n_z", 4},
                       {"eps", 0.1}, {"data", "cai-zhou"}};
  const t::Json real2 = {{"name", "klein-gordon"}, {"dims", 2}, {"n_x", 12}, {"n_y", 6}, {"eps", 0.05}};
  const t::Json real3 = {{"name", "klein-gordon"}, {"dims", 3}, {"n_x", 6}, {"n_y", 6}, {"n_z", 4}, {"eps", 0.1}};
  // Not here: eab and fd on the two-scale problem of either Klein-Gordon. Their prepared data of
  // order 6 (4 for fd) amplify the transforms' rounding about 10^7-fold, so that two FFT plans of
  // one process differ by 1e-11 to 1.4e-9 (the one-process run against `mpirun -np 1 --split`):
  // docs/how-to/mpi-and-shards.md.
  t::Json anderson = grid_config(nls2, "two-scale", "composition");  // the base scheme's fixed points, reduced
  anderson["scheme"]["solver"] = "anderson";
  for (const Case& c : {Case{"nls 2-D se1", grid_config(nls2, "two-scale", "se1"), 1},
                        Case{"nls 3-D se2", grid_config(nls3, "two-scale", "se2"), 1},
                        Case{"nls 2-D composition, anderson", anderson, 1},
                        Case{"nls 2-D eab, filtered", grid_config(nls2, "filtered", "eab"), 1},
                        Case{"nls 2-D strang, direct", grid_config(nls2, "direct", "strang"), 1},
                        Case{"kg 2-D se1", grid_config(kg2, "two-scale", "se1"), 2},
                        Case{"kg 3-D npi, filtered", grid_config(kg3, "filtered", "npi"), 2},
                        Case{"kg 2-D trigonometric, direct", grid_config(kg2, "direct", "trigonometric"), 2},
                        Case{"real kg 2-D se2", grid_config(real2, "two-scale", "se2"), 1},
                        Case{"real kg 3-D micro-macro, filtered", grid_config(real3, "filtered", "micro-macro"), 1}})
    check_split_matches(c, {2, 3});
}

TEST_CASE("split grid run: above 4096 values every rank writes its share of the state files and snapshots, none gathers") {
  // 2 x 48 x 48 values (u and v): result.json names the files, and the ranks write them.
  t::Json config = grid_config({{"name", "klein-gordon-complex"}, {"dims", 2}, {"n_x", 48}, {"n_y", 48}, {"eps", 0.05},
                                {"data", "cai-zhou"}},
                               "two-scale", "se1");
  config["reformulation"]["n_tau"] = 8;
  config["time"] = {{"h", 0.02}, {"t_end", 0.06}};
  config["output"] = {{"every", 1}, {"fields_every", 2}, {"state_every", 2}};
  config["reference"] = {{"scheme", "se1"}, {"reformulation", "two-scale"}, {"h", 0.01}, {"n_tau", 8}};
  t::TempDir dir("tsi-split-shares");
  const std::string file = t::write_config(dir, config, "run.json");
  const t::CommandResult one = t::run_tsi({"run", file, "--out", dir / "one"});
  REQUIRE_MESSAGE(one.exit_code == 0, one.describe());
  for (const int p : {2, 3}) {
    CAPTURE(p);
    const t::fs::path out = dir.path() / ("split" + std::to_string(p));
    const t::CommandResult split = t::split_run(p, {file, "--out", out.string()});
    REQUIRE_MESSAGE(split.exit_code == 0, split.describe());
    CHECK(t::contains(split.out, "(4608 values: "));  // the summary's u, from rank 0's share
    const t::Json record = t::read_json(out / "result.json");
    CHECK(record["u_final"] == t::Json({{"file", "u_final.npy"}, {"dtype", "complex128"}, {"shape", {2, 48, 48}}}));
    for (const char* name : {"u_final.npy", "state.npy", "reference_u_final.npy"}) {
      CAPTURE(name);
      CHECK(t::relative_difference(dir.path() / "one" / name, out / name) < 1e-12);
      CHECK_FALSE(t::fs::exists(out / (std::string(name) + ".split-partial")));
    }
    CHECK(record["error"]["relative"].get<double>() ==
          doctest::Approx(t::read_json(dir.path() / "one/result.json")["error"]["relative"].get<double>()).epsilon(1e-9));
    check_fields(dir.path() / "one", out, 2);
  }
}

TEST_CASE("split grid run: a grid that cannot be split in slabs is refused on every rank, naming the field") {
  t::TempDir dir("tsi-split-grid-refused");
  const t::Json nls2 = {{"name", "nls"}, {"dims", 2}, {"n_x", 8}, {"n_y", 8}, {"eps", 0.1}};
  const t::Json nls1 = {{"name", "nls"}, {"dims", 1}, {"n_x", 12}, {"eps", 0.1}};
  const std::string config = t::write_config(dir, grid_config(nls2, "two-scale", "se1"), "run.json");
  const std::string line = t::write_config(dir, grid_config(nls1, "two-scale", "se1"), "line.json");
  struct Case {
    std::string config;
    std::vector<std::string> set;
    const char* says;
  };
  for (const Case& c : {Case{line, {}, "model.dims: got 1 with --split over 3 processes; expected 2 or 3"},
                        Case{config, {"model.n_x=2"}, "model.n_x: got 2 with --split over 3 processes; expected at least one slab"},
                        Case{config, {}, "model.n_x: got 8 with --split over 3 processes; expected a multiple of 3"},
                        Case{config, {"model.n_x=6"}, "model.n_y: got 8 with --split over 3 processes; expected a multiple of 3"}}) {
    CAPTURE(c.says);
    std::vector<std::string> args = {c.config, "--out", dir / "out"};
    for (const std::string& s : c.set) args.insert(args.end(), {"--set", s});
    const t::CommandResult r = t::split_run(3, args);
    CHECK_MESSAGE(r.exit_code == 2, r.describe());
    const std::size_t first = r.err.find(c.says);
    REQUIRE_MESSAGE(first != std::string::npos, r.describe());
    CHECK(r.err.find(c.says, first + 1) == std::string::npos);  // once, by rank 0
    CHECK_FALSE(t::fs::exists(dir.path() / "out" / "result.json"));
  }
}
#endif
