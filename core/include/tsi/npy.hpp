#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "tsi/export.hpp"
#include "tsi/types.hpp"

namespace tsi {

/// NumPy's .npy files: states too large for JSON (model.u0 given as a file, every run's
/// u_final.npy). The format: the magic "\x93NUMPY", a version byte pair (1.0, 2.0 or 3.0), the
/// header's length (2 bytes little-endian in 1.0, 4 bytes in 2.0 and 3.0), the header (a
/// Python dict literal with 'descr', 'fortran_order' and 'shape', padded with spaces and a
/// newline so that the data start on a multiple of 64 bytes), then the data.
///
/// Reading accepts float64 ('<f8') and complex128 ('<c16'), and float32 ('<f4') and
/// complex64 ('<c8') widened to them; C order of any shape, and Fortran order where at most
/// one dimension exceeds 1 (a 1-D array, where both orders are the same bytes): an N-D
/// Fortran-ordered array is refused, naming np.ascontiguousarray. Every size is checked
/// before anything is allocated: the header's length (at most 1 MiB), the shape's product
/// (overflow included) times the item size against the bytes the file actually holds, so a
/// truncated file, or one whose header promises more or less than it holds, is an error and
/// never a large allocation. Errors are tsi::Error whose message starts with the file's name.
struct TSI_API NpyHeader {
  int major_version = 1, minor_version = 0;
  std::string descr;                 ///< the dtype as written: "<f8", "<c16", "<f4" or "<c8"
  bool fortran_order = false;
  std::vector<std::uint64_t> shape;  ///< empty for a 0-d array (one value)
  std::uint64_t count = 1;           ///< the number of values: the product of shape
  bool is_complex = false;           ///< complex128 or complex64 in the file
  std::size_t item_size = 8;         ///< bytes per value in the file: 4, 8 or 16
  std::uint64_t data_offset = 0;     ///< where the data start in the file
};

/// Reads and checks the header of a .npy file (the sizes against the file's size included)
/// without reading its data.
TSI_API NpyHeader read_npy_header(const std::string& path);

/// A .npy file's values in C order, widened to complex doubles (a real file's imaginary
/// parts are zero; header.is_complex says which the file held).
struct TSI_API NpyArray {
  NpyHeader header;
  Vector values;
};

/// Reads a .npy file: read_npy_header, then its data.
TSI_API NpyArray read_npy(const std::string& path);

/// Writes a .npy file of float64 ('<f8') or complex128 ('<c16') values in C order with the
/// given shape (empty: 1-D, (n,)), as NumPy's np.save writes it: format 1.0 when the header
/// fits its 2-byte length, else 2.0, the header padded to 64 bytes. Written atomically (a
/// temporary file in the same directory, flushed, renamed over `path`); a failure (a full
/// disk, a file size limit) removes the temporary file and throws tsi::IoError naming `path`.
/// A shape whose product is not the number of values is a tsi::Error.
TSI_API void write_npy(const std::string& path, std::span<const double> values,
                       const std::vector<std::uint64_t>& shape = {});
TSI_API void write_npy(const std::string& path, std::span<const Complex> values,
                       const std::vector<std::uint64_t>& shape = {});
/// A state: its real parts as float64 (complex_values false) or the values as complex128.
TSI_API void write_npy(const std::string& path, const Vector& values, bool complex_values,
                       const std::vector<std::uint64_t>& shape = {});

/// Rows of row_size values each as one array of shape `shape` (its product rows.size() x
/// row_size), written row by row without gathering them: a row of another size (an empty one)
/// is written as NaN. Real parts as float64 (complex_values false), else complex128.
TSI_API void write_npy_rows(const std::string& path, const std::vector<Vector>& rows, Index row_size,
                            bool complex_values, const std::vector<std::uint64_t>& shape);

/// The header np.save writes before the values of a float64 (complex_values false) or complex128
/// array of `shape`: for a file whose values are written by other means (a split run's
/// processes, each at its offset after it).
TSI_API std::string npy_header_bytes(bool complex_values, const std::vector<std::uint64_t>& shape);

/// A shape as Python writes a tuple: "()", "(3,)", "(2, 3)".
TSI_API std::string npy_shape_text(const std::vector<std::uint64_t>& shape);

}  // namespace tsi
