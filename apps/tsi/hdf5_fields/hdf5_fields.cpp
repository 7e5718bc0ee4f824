// The HDF5 half of output.fields_every (apps/tsi/field_snapshots.cpp): fields.h5's header and
// snapshots, through libhdf5 (Debian's libhdf5-dev, serial). A module of its own, which the runner
// opens only for a run that writes fields: linked into tsi, libhdf5 brings 33 libraries (curl,
// TLS, Kerberos, LDAP, ...) to every start, 11 ms against 4 ms for `tsi --version` and 6.7 MB
// more resident memory. A C interface: the runner finds it with dlsym.
//
// Every call opens and closes the file, which is then complete on disk: a run stopped anywhere
// keeps every snapshot written. A split run's processes write a snapshot's rows in turn
// (tsi_fields_h5_write_rows): serial HDF5 has one writer at a time.
//
// Layout: the file's attributes grid_shape (int64) and box_lengths (float64); a group
// /fields/<step, 10 digits> per snapshot with attributes time (float64) and step (int64) and one
// float64 dataset per array, of the grid's shape. Failures return non-zero (the runner names
// the file and raises); HDF5's own error printing is off.
#include <hdf5.h>

#include <cstdio>
#include <string>
#include <vector>

#define TSI_HDF5_FIELDS_API extern "C" __attribute__((visibility("default")))

namespace {
bool attribute(hid_t where, const char* name, hid_t type, const void* value, hsize_t count = 1) {
  const hid_t space = H5Screate_simple(1, &count, nullptr);
  if (space < 0) return false;
  const hid_t a = H5Acreate2(where, name, type, space, H5P_DEFAULT, H5P_DEFAULT);
  const bool ok = a >= 0 && H5Awrite(a, type, value) >= 0;
  if (a >= 0) H5Aclose(a);
  H5Sclose(space);
  return ok;
}
}  // namespace

// A new fields.h5 at `path` (replacing one there) for fields of `rank` dimensions, `shape` in C
// order on the box `lengths`: its header, the file closed again. 0 on success.
TSI_HDF5_FIELDS_API int tsi_fields_h5_create(const char* path, int rank, const long long* shape,
                                             const double* lengths) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) return -1;
  bool ok = attribute(file, "grid_shape", H5T_NATIVE_LLONG, shape, static_cast<hsize_t>(rank)) &&
            attribute(file, "box_lengths", H5T_NATIVE_DOUBLE, lengths, static_cast<hsize_t>(rank));
  const hid_t group = H5Gcreate2(file, "/fields", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ok = ok && group >= 0;
  if (group >= 0) H5Gclose(group);
  ok = H5Fclose(file) >= 0 && ok;
  return ok ? 0 : -1;
}

// Rows [first_row, first_row + rows) of the first dimension of the snapshot of step `step`: the
// file at `path` opened, the group and its full-size datasets made where `create` (the first
// process, before the others), the rows written, the file closed. 0 on success.
TSI_HDF5_FIELDS_API int tsi_fields_h5_write_rows(const char* path, long long step, double t, int count,
                                                 const char* const* names, const double* const* arrays,
                                                 long long first_row, long long rows, int create) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fopen(path, H5F_ACC_RDWR, H5P_DEFAULT);
  if (file < 0) return -1;
  char group_name[40];
  std::snprintf(group_name, sizeof group_name, "/fields/%010lld", step);
  std::vector<long long> shape(3);
  int rank = 0;
  {
    const hid_t a = H5Aopen(file, "grid_shape", H5P_DEFAULT);
    const hid_t space = a >= 0 ? H5Aget_space(a) : -1;
    rank = space >= 0 ? static_cast<int>(H5Sget_simple_extent_npoints(space)) : 0;
    if (space >= 0) H5Sclose(space);
    const bool ok = rank >= 1 && rank <= 3 && H5Aread(a, H5T_NATIVE_LLONG, shape.data()) >= 0;
    if (a >= 0) H5Aclose(a);
    if (!ok) {
      H5Fclose(file);
      return -1;
    }
  }
  std::vector<hsize_t> dims(shape.begin(), shape.begin() + rank), start(static_cast<std::size_t>(rank), 0),
      extent = dims;
  start[0] = static_cast<hsize_t>(first_row);
  extent[0] = static_cast<hsize_t>(rows);
  const hid_t group = create ? H5Gcreate2(file, group_name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                             : H5Gopen2(file, group_name, H5P_DEFAULT);
  bool ok = group >= 0;
  if (ok && create) ok = attribute(group, "time", H5T_NATIVE_DOUBLE, &t) && attribute(group, "step", H5T_NATIVE_LLONG, &step);
  const hid_t whole = H5Screate_simple(rank, dims.data(), nullptr), part = H5Screate_simple(rank, extent.data(), nullptr);
  ok = ok && whole >= 0 && part >= 0 &&
       H5Sselect_hyperslab(whole, H5S_SELECT_SET, start.data(), nullptr, extent.data(), nullptr) >= 0;
  for (int i = 0; ok && i < count; ++i) {
    const hid_t d = create ? H5Dcreate2(group, names[i], H5T_IEEE_F64LE, whole, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT)
                           : H5Dopen2(group, names[i], H5P_DEFAULT);
    ok = d >= 0 && H5Dwrite(d, H5T_NATIVE_DOUBLE, part, whole, H5P_DEFAULT, arrays[i]) >= 0;
    if (d >= 0) H5Dclose(d);
  }
  if (part >= 0) H5Sclose(part);
  if (whole >= 0) H5Sclose(whole);
  if (group >= 0) H5Gclose(group);
  ok = H5Fclose(file) >= 0 && ok;
  return ok ? 0 : -1;
}
