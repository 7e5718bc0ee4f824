#pragma once
#include <string>
#include <vector>

#include "tsi/collective.hpp"
#include "tsi/model.hpp"
#include "tsi/types.hpp"

namespace tsi::app {

/// output.fields_every: snapshots of a grid model's fields for ParaView and h5py. Each snapshot
/// is a group of fields.h5 (HDF5, Debian's libhdf5-dev, written by the module
/// apps/tsi/hdf5_fields, which only a run writing fields loads) holding, for every field of the model
/// (Model::grid_fields), |u|, Re u and Im u of a complex state (u of a real one) as arrays of the
/// grid's shape, with its time and step; fields.xmf (XDMF 3) lists the snapshots as a time
/// series on the grid's uniform mesh. The HDF5 file is closed and the XDMF file rewritten (by a
/// rename) after every snapshot: a run stopped anywhere keeps every snapshot it announced.
class FieldSnapshots {
 public:
  /// In `dir`; `fields` from the model, `complex` whether the state is. `lists`: this process
  /// makes fields.h5 and keeps fields.xmf (all but a split run's ranks other than 0). Throws
  /// IoError when the file cannot be made, ConfigError (output.fields_every) where the HDF5
  /// module is missing.
  FieldSnapshots(const std::string& dir, GridFields fields, bool complex, bool lists = true);

  /// The physical state x (the whole run's: every field one after the other) at step n, time t.
  void write(long step, double t, const Vector& x);
  /// A split run's snapshot, not gathered: each process writes the rows of its slab of every
  /// field (`local`, its share of the physical state), rank 0 first, then the others in turn.
  /// Every process calls it alike; a failure on any is an IoError on all.
  void write_shares(const Collective& split, long step, double t, const Vector& local);
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
  // The arrays of one snapshot (|u|, Re u, Im u of each field, or u), from `points` values a field.
  void arrays(const Vector& x, Index points, std::vector<std::string>& names,
              std::vector<std::vector<double>>& values) const;
  void write_xdmf() const;
  std::string dir_;
  GridFields fields_;
  bool complex_, lists_;
  std::vector<Written> written_;
};

}  // namespace tsi::app
