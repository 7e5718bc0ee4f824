// The HDF5 half of output.fields_every (apps/tsi/field_snapshots.cpp): fields.h5's header and
// snapshots, through libhdf5 (Debian's libhdf5-dev, serial). A module of its own, which the runner
// opens only for a run that writes fields: linked into tsi, libhdf5 brings 33 libraries (curl,
// TLS, Kerberos, LDAP, ...) to every start, 11 ms against 4 ms for `tsi --version` and 6.7 MB
// more resident memory. A C interface: the runner finds it with dlsym.
//
// Layout: the file's attributes grid_shape (int64) and box_lengths (float64); a group
// /fields/<step, 10 digits> per snapshot with attributes time (float64) and step (int64) and one
// float64 dataset per array, of the grid's shape. Every call flushes the file, so that a run
// stopped anywhere leaves every snapshot written. Failures return non-zero (the runner names
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
// order on the box `lengths`; an opaque handle, or null where the file cannot be made.
TSI_HDF5_FIELDS_API void* tsi_fields_h5_create(const char* path, int rank, const long long* shape,
                                               const double* lengths) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  const hid_t file = H5Fcreate(path, H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (file < 0) return nullptr;
  bool ok = attribute(file, "grid_shape", H5T_NATIVE_LLONG, shape, static_cast<hsize_t>(rank)) &&
            attribute(file, "box_lengths", H5T_NATIVE_DOUBLE, lengths, static_cast<hsize_t>(rank));
  const hid_t group = H5Gcreate2(file, "/fields", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  ok = ok && group >= 0;
  if (group >= 0) H5Gclose(group);
  ok = ok && H5Fflush(file, H5F_SCOPE_GLOBAL) >= 0;
  if (!ok) {
    H5Fclose(file);
    return nullptr;
  }
  return new hid_t(file);
}

// The snapshot of step `step` at time `t`: `count` arrays named `names`, each of the file's grid
// shape. 0 on success.
TSI_HDF5_FIELDS_API int tsi_fields_h5_write(void* handle, long long step, double t, int count,
                                            const char* const* names, const double* const* arrays) {
  const hid_t file = *static_cast<hid_t*>(handle);
  char group_name[40];
  std::snprintf(group_name, sizeof group_name, "/fields/%010lld", step);
  long long rank = 0;
  std::vector<long long> shape(3);
  {
    const hid_t a = H5Aopen(file, "grid_shape", H5P_DEFAULT);
    if (a < 0) return -1;
    const hid_t space = H5Aget_space(a);
    rank = H5Sget_simple_extent_npoints(space);
    H5Sclose(space);
    shape.resize(static_cast<std::size_t>(rank));
    const bool ok = rank >= 1 && rank <= 3 && H5Aread(a, H5T_NATIVE_LLONG, shape.data()) >= 0;
    H5Aclose(a);
    if (!ok) return -1;
  }
  std::vector<hsize_t> dims(shape.begin(), shape.end());
  const hid_t group = H5Gcreate2(file, group_name, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
  if (group < 0) return -1;
  bool ok = attribute(group, "time", H5T_NATIVE_DOUBLE, &t) && attribute(group, "step", H5T_NATIVE_LLONG, &step);
  const hid_t space = H5Screate_simple(static_cast<int>(rank), dims.data(), nullptr);
  ok = ok && space >= 0;
  for (int i = 0; ok && i < count; ++i) {
    const hid_t d = H5Dcreate2(group, names[i], H5T_IEEE_F64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ok = d >= 0 && H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, arrays[i]) >= 0;
    if (d >= 0) H5Dclose(d);
  }
  if (space >= 0) H5Sclose(space);
  H5Gclose(group);
  ok = ok && H5Fflush(file, H5F_SCOPE_GLOBAL) >= 0;  // on disk before the XDMF file names it
  return ok ? 0 : -1;
}

TSI_HDF5_FIELDS_API void tsi_fields_h5_close(void* handle) {
  if (!handle) return;
  auto* file = static_cast<hid_t*>(handle);
  H5Fclose(*file);
  delete file;
}
