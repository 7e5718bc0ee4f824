#include "field_snapshots.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "tsi/error.hpp"
#include "tsi/output.hpp"

#ifdef TSI_WITH_HDF5
#include <hdf5.h>
#endif

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

#ifdef TSI_WITH_HDF5
namespace {
// An HDF5 call that failed: its message names the file and what was being written.
void check(herr_t status, const std::string& what) {
  if (status < 0) throw IoError(fmt::format("cannot write {}: {}", h5_name, what));
}
hid_t checked(hid_t id, const std::string& what) {
  if (id < 0) throw IoError(fmt::format("cannot write {}: {}", h5_name, what));
  return id;
}
void attribute(hid_t where, const char* name, hid_t type, const void* value, hsize_t count = 1) {
  const hid_t space = checked(H5Screate_simple(1, &count, nullptr), name);
  const hid_t a = checked(H5Acreate2(where, name, type, space, H5P_DEFAULT, H5P_DEFAULT), name);
  check(H5Awrite(a, type, value), name);
  H5Aclose(a);
  H5Sclose(space);
}
}  // namespace

bool FieldSnapshots::available() { return true; }

FieldSnapshots::FieldSnapshots(const std::string& dir, GridFields fields, bool complex)
    : dir_(dir), fields_(std::move(fields)), complex_(complex) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // failures are reported as IoError, not printed
  const std::string path = dir_ + "/" + h5_name;
  file_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file_ < 0) throw IoError(fmt::format("cannot create {}", path));
  const hid_t root = static_cast<hid_t>(file_);
  std::vector<long long> shape(fields_.shape.begin(), fields_.shape.end());
  attribute(root, "grid_shape", H5T_NATIVE_LLONG, shape.data(), shape.size());
  attribute(root, "box_lengths", H5T_NATIVE_DOUBLE, fields_.lengths.data(), fields_.lengths.size());
  const hid_t group = checked(H5Gcreate2(root, "/fields", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "/fields");
  H5Gclose(group);
  check(H5Fflush(root, H5F_SCOPE_GLOBAL), "the header");
  write_xdmf();
}

FieldSnapshots::~FieldSnapshots() {
  if (file_ >= 0) H5Fclose(static_cast<hid_t>(file_));
}

void FieldSnapshots::write(long step, double t, const Vector& x) {
  const std::size_t rank = fields_.shape.size();
  Index points = 1;
  for (const Index n : fields_.shape) points *= n;
  if (x.size() != points * static_cast<Index>(fields_.names.size()))
    throw Error(fmt::format("output.fields_every: a state of {} values for {} fields of {} points", x.size(),
                            fields_.names.size(), points));
  const hid_t root = static_cast<hid_t>(file_);
  const std::string name = group_name(step);
  const hid_t group = checked(H5Gcreate2(root, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), name);
  attribute(group, "time", H5T_NATIVE_DOUBLE, &t);
  const long long step_value = step;
  attribute(group, "step", H5T_NATIVE_LLONG, &step_value);
  std::vector<hsize_t> dims(fields_.shape.begin(), fields_.shape.end());
  const hid_t space = checked(H5Screate_simple(static_cast<int>(rank), dims.data(), nullptr), name);
  std::vector<double> values(static_cast<std::size_t>(points));
  for (std::size_t f = 0; f < fields_.names.size(); ++f) {
    const auto field = x.segment(static_cast<Index>(f) * points, points);
    for (const Component& c : components(complex_)) {
      for (Index p = 0; p < points; ++p) values[static_cast<std::size_t>(p)] = to_double(c.of(field(p)));
      const std::string dataset = fields_.names[f] + c.suffix;
      const hid_t d = checked(H5Dcreate2(group, dataset.c_str(), H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT,
                                         H5P_DEFAULT),
                              name + "/" + dataset);
      check(H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name + "/" + dataset);
      H5Dclose(d);
    }
  }
  H5Sclose(space);
  H5Gclose(group);
  check(H5Fflush(root, H5F_SCOPE_GLOBAL), name);  // on disk before the XDMF file names it
  written_.push_back({step, t});
  write_xdmf();
}
#else
bool FieldSnapshots::available() { return false; }
FieldSnapshots::FieldSnapshots(const std::string&, GridFields, bool) {
  throw ConfigError("output.fields_every", "this tsi was built without HDF5; install libhdf5-dev and rebuild (cmake "
                                           "finds it by itself) to write field snapshots");
}
FieldSnapshots::~FieldSnapshots() = default;
void FieldSnapshots::write(long, double, const Vector&) {}
#endif

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
