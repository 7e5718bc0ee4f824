#include "field_snapshots.hpp"

#include <dlfcn.h>
#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "tsi/error.hpp"
#include "tsi/output.hpp"
#include "tsi/plugin_loader.hpp"

namespace tsi::app {

namespace {
const char* const h5_name = "fields.h5";
const char* const xdmf_name = "fields.xmf";

// The group of step n: zero-padded, so that h5py and h5ls list the snapshots in order.
std::string group_name(long step) { return fmt::format("/fields/{:010d}", step); }

// The arrays written for one field: |u|, Re u, Im u of a complex state, u of a real one.
struct Component {
  enum Part { real, imaginary, modulus } part;
  const char* suffix;  // the dataset's name after the field's
  const char* label;   // ParaView's name, the field's in it
  Real of(Complex z) const { return part == real ? z.real() : part == imaginary ? z.imag() : std::abs(z); }
};
std::vector<Component> components(bool complex) {
  if (complex)
    return {{Component::modulus, "_abs", "|{}|"}, {Component::real, "_re", "Re {}"},
            {Component::imaginary, "_im", "Im {}"}};
  return {{Component::real, "", "{}"}};
}
}  // namespace

namespace {
// The HDF5 module (apps/tsi/hdf5_fields), next to the plugins' directory: lib/tsi/ of the build
// tree or of an installed prefix. Opened on first use and kept; null where it is not there.
struct Hdf5Module {
  int (*create)(const char*, int, const long long*, const double*) = nullptr;
  int (*write_rows)(const char*, long long, double, int, const char* const*, const double* const*, long long,
                    long long, int) = nullptr;
  std::string path, error;
};
const Hdf5Module& hdf5_module() {
  static const Hdf5Module module = [] {
    Hdf5Module m;
    m.path = (std::filesystem::path(PluginLoader::default_directory()).parent_path() / "libtsi_hdf5_fields.so").string();
    void* handle = dlopen(m.path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      m.error = why ? why : "not found";
      return m;
    }
    m.create = reinterpret_cast<decltype(m.create)>(dlsym(handle, "tsi_fields_h5_create"));
    m.write_rows = reinterpret_cast<decltype(m.write_rows)>(dlsym(handle, "tsi_fields_h5_write_rows"));
    if (!m.create || !m.write_rows) m.error = "it lacks the tsi_fields_h5_* functions";
    return m;
  }();
  return module;
}

// Pointers to the names and arrays, for the module's C interface.
int write_rows(const std::string& path, long step, double t, const std::vector<std::string>& names,
               const std::vector<std::vector<double>>& values, Index first_row, Index rows, bool create) {
  std::vector<const char*> name_pointers;
  std::vector<const double*> value_pointers;
  for (std::size_t i = 0; i < names.size(); ++i) {
    name_pointers.push_back(names[i].c_str());
    value_pointers.push_back(values[i].data());
  }
  return hdf5_module().write_rows(path.c_str(), step, t, static_cast<int>(names.size()), name_pointers.data(),
                                  value_pointers.data(), first_row, rows, create ? 1 : 0);
}
}  // namespace

bool FieldSnapshots::available() { return hdf5_module().error.empty(); }

std::string FieldSnapshots::unavailable_reason() {
  const Hdf5Module& m = hdf5_module();
  return m.error.empty() ? std::string() : m.path + ": " + m.error;
}

FieldSnapshots::FieldSnapshots(const std::string& dir, GridFields fields, bool complex, bool lists)
    : dir_(dir), fields_(std::move(fields)), complex_(complex), lists_(lists) {
  const Hdf5Module& m = hdf5_module();
  if (!m.error.empty())
    throw ConfigError("output.fields_every", "this tsi cannot write HDF5 (" + unavailable_reason() +
                                                 "); build it with libhdf5-dev installed");
  if (!lists_) return;
  const std::string path = dir_ + "/" + h5_name;
  const std::vector<long long> shape(fields_.shape.begin(), fields_.shape.end());
  if (m.create(path.c_str(), static_cast<int>(shape.size()), shape.data(), fields_.lengths.data()) != 0)
    throw IoError(fmt::format("cannot create {}", path));
  write_xdmf();
}

void FieldSnapshots::arrays(const Vector& x, Index points, std::vector<std::string>& names,
                            std::vector<std::vector<double>>& values) const {
  for (std::size_t f = 0; f < fields_.names.size(); ++f) {
    const auto field = x.segment(static_cast<Index>(f) * points, points);
    for (const Component& c : components(complex_)) {
      names.push_back(fields_.names[f] + c.suffix);
      std::vector<double>& v = values.emplace_back(static_cast<std::size_t>(points));
      for (Index p = 0; p < points; ++p) v[static_cast<std::size_t>(p)] = to_double(c.of(field(p)));
    }
  }
}

void FieldSnapshots::write(long step, double t, const Vector& x) {
  Index points = 1;
  for (const Index n : fields_.shape) points *= n;
  if (x.size() != points * static_cast<Index>(fields_.names.size()))
    throw Error(fmt::format("output.fields_every: a state of {} values for {} fields of {} points", x.size(),
                            fields_.names.size(), points));
  std::vector<std::string> names;
  std::vector<std::vector<double>> values;
  arrays(x, points, names, values);
  if (write_rows(dir_ + "/" + h5_name, step, t, names, values, 0, fields_.shape.front(), true) != 0)
    throw IoError(fmt::format("cannot write {} of step {} to {}/{}", group_name(step), step, dir_, h5_name));
  written_.push_back({step, t});
  write_xdmf();
}

void FieldSnapshots::write_shares(const Collective& split, long step, double t, const Vector& local) {
  const Index parts = static_cast<Index>(fields_.names.size()), points = local.size() / parts;
  Index row_points = 1;
  for (std::size_t i = 1; i < fields_.shape.size(); ++i) row_points *= fields_.shape[i];
  const Index rows = points / row_points, first_row = rows * split.rank();  // equal slabs (tsi::grid_slab)
  std::vector<std::string> names;
  std::vector<std::vector<double>> values;
  arrays(local, points, names, values);
  bool ok = true;
  for (int turn = 0; turn < split.size(); ++turn) {  // serial HDF5: one writer at a time, rank 0 first
    if (turn == split.rank())
      ok = write_rows(dir_ + "/" + h5_name, step, t, names, values, first_row, rows, turn == 0) == 0;
    if (!split.all(ok))
      throw IoError(fmt::format("cannot write {} of step {} to {}/{} (rank {} of {}, its rows {} to {})",
                                group_name(step), step, dir_, h5_name, split.rank(), split.size(), first_row,
                                first_row + rows - 1));
  }
  if (!lists_) return;
  written_.push_back({step, t});
  write_xdmf();
}

// XDMF 3: a temporal collection of uniform grids on a CoRectMesh (origin 0, spacing L_i / n_i),
// dimensions in C order (the slowest first), as the HDF5 arrays are. A 1-D grid is a 2-D mesh of
// one row (XDMF has no 1-D structured mesh).
void FieldSnapshots::write_xdmf() const {
  std::vector<Index> shape = fields_.shape;
  std::vector<double> spacing;
  for (std::size_t i = 0; i < shape.size(); ++i) spacing.push_back(fields_.lengths[i] / static_cast<double>(shape[i]));
  if (shape.size() == 1) {
    shape.insert(shape.begin(), 1);
    spacing.insert(spacing.begin(), 1.0);
  }
  const bool three = shape.size() == 3;
  std::string dimensions, origin, step;
  for (std::size_t i = 0; i < shape.size(); ++i) {
    dimensions += fmt::format("{}{}", i ? " " : "", shape[i]);
    origin += i ? " 0" : "0";
    step += fmt::format("{}{:.17g}", i ? " " : "", spacing[i]);
  }
  std::string text = "<?xml version=\"1.0\" ?>\n<Xdmf Version=\"3.0\">\n <Domain>\n"
                     "  <Grid Name=\"fields\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const Written& w : written_) {
    text += fmt::format("   <Grid Name=\"step {}\" GridType=\"Uniform\">\n    <Time Value=\"{:.17g}\"/>\n", w.step, w.t);
    text += fmt::format("    <Topology TopologyType=\"{}\" Dimensions=\"{}\"/>\n", three ? "3DCoRectMesh" : "2DCoRectMesh",
                        dimensions);
    text += fmt::format("    <Geometry GeometryType=\"{}\">\n"
                        "     <DataItem Dimensions=\"{}\" Format=\"XML\">{}</DataItem>\n"
                        "     <DataItem Dimensions=\"{}\" Format=\"XML\">{}</DataItem>\n    </Geometry>\n",
                        three ? "ORIGIN_DXDYDZ" : "ORIGIN_DXDY", shape.size(), origin, shape.size(), step);
    for (const std::string& field : fields_.names)
      for (const Component& c : components(complex_))
        text += fmt::format("    <Attribute Name=\"{}\" AttributeType=\"Scalar\" Center=\"Node\">\n"
                            "     <DataItem Dimensions=\"{}\" NumberType=\"Float\" Precision=\"8\" "
                            "Format=\"HDF\">{}:{}/{}{}</DataItem>\n    </Attribute>\n",
                            fmt::format(fmt::runtime(c.label), field), dimensions, h5_name, group_name(w.step), field,
                            c.suffix);
    text += "   </Grid>\n";
  }
  text += "  </Grid>\n </Domain>\n</Xdmf>\n";
  write_file_atomically(dir_ + "/" + xdmf_name, text);
}

}  // namespace tsi::app
