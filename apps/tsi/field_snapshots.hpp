#pragma once
#include <string>
#include <vector>

#include "tsi/model.hpp"
#include "tsi/types.hpp"

namespace tsi::app {

/// output.fields_every: snapshots of a grid model's fields for ParaView and h5py. Each snapshot
/// is a group of fields.h5 (HDF5, Debian's libhdf5-dev, written by the module
/// apps/tsi/hdf5_fields, which only a run writing fields loads) holding, for every field of the model
/// (Model::grid_fields), |u|, Re u and Im u of a complex state (u of a real one) as arrays of the
/// grid's shape, with its time and step; fields.xmf (XDMF 3) lists the snapshots as a time
/// series on the grid's uniform mesh. The HDF5 file is flushed and the XDMF file rewritten (by a
/// rename) after every snapshot: a run stopped anywhere keeps every snapshot it announced.
class FieldSnapshots {
 public:
  /// In `dir`; `fields` from the model, `complex` whether the state is. Throws IoError when the
  /// file cannot be made, ConfigError (output.fields_every) where the HDF5 module is missing.
  FieldSnapshots(const std::string& dir, GridFields fields, bool complex);
  ~FieldSnapshots();
  FieldSnapshots(const FieldSnapshots&) = delete;
  FieldSnapshots& operator=(const FieldSnapshots&) = delete;

  /// The physical state x (the whole run's: every field one after the other) at step n, time t.
  void write(long step, double t, const Vector& x);
  /// Snapshots written so far.
  long count() const { return static_cast<long>(written_.size()); }
  /// Whether the HDF5 module can be loaded, and if not, why (its path and the loader's message).
  static bool available();
  static std::string unavailable_reason();

 private:
  struct Written {
    long step;
    double t;
  };
  void write_xdmf() const;
  std::string dir_;
  GridFields fields_;
  bool complex_;
  void* file_ = nullptr;  // the HDF5 module's handle of fields.h5
  std::vector<Written> written_;
};

}  // namespace tsi::app
