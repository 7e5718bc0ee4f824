#pragma once
#include <algorithm>

#include "tsi/types.hpp"

namespace tsi {

/// A real model's filtered and direct states hold its d real values two to a complex entry:
/// entry k is (x_{2k}, x_{2k+1}), the last one's imaginary part 0 when d is odd. Half the memory
/// of a complex state, and the same numbers: the arithmetic schemes apply to these states is
/// real (real coefficients, since L is 0 or absent there; real parts of inner products; maxima
/// over the doubles), and a real coefficient times (a, b) is (c a, c b) exactly.
class RealPacking {
 public:
  RealPacking() = default;
  /// Packing for d real values, or none (`on` false: a complex state as it stands).
  RealPacking(Index d, bool on) : d_(d), on_(on) {}

  bool on() const { return on_; }
  /// Entries of the state: (d + 1) / 2 packed, else d.
  Index size() const { return on_ ? (d_ + 1) / 2 : d_; }
  /// The d real parts of `values` two to an entry into `packed` (size()).
  void pack(const Complex* values, Complex* packed) const {
    for (Index k = 0; 2 * k < d_; ++k)
      packed[k] = Complex(values[2 * k].real(), 2 * k + 1 < d_ ? values[2 * k + 1].real() : 0.0);
  }
  /// The d values (imaginary parts 0) from `packed`.
  void unpack(const Complex* packed, Complex* values) const {
    for (Index k = 0; 2 * k < d_; ++k) {
      values[2 * k] = packed[k].real();
      if (2 * k + 1 < d_) values[2 * k + 1] = packed[k].imag();
    }
  }
  /// The d `values` into `out`, resized to size(): their real parts two to an entry where the
  /// packing is on, as they stand otherwise.
  void pack_into(const Complex* values, Vector& out) const {
    out.resize(size());
    if (on_)
      pack(values, out.data());
    else
      std::copy(values, values + d_, out.data());
  }
  /// A model state (d values) as a state of the problem.
  Vector packed(const Vector& values) const {
    if (!on_) return values;
    Vector out(size());
    pack(values.data(), out.data());
    return out;
  }
  /// A state of the problem as a model state.
  Vector unpacked(const Vector& packed) const {
    if (!on_) return packed;
    Vector out(d_);
    unpack(packed.data(), out.data());
    return out;
  }

 private:
  Index d_ = 0;
  bool on_ = false;
};

}  // namespace tsi
