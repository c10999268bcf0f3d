// Internal helpers over the HDF5 C API for Cairn's snapshot and checkpoint files.
//
// Handles are RAII-owned; every failing HDF5 call throws std::runtime_error naming the file and
// the object involved. HDF5's own automatic error printing is switched off (silence_errors() is
// called by create_file() and open_file()), so the exceptions are the only report.
// Not part of the public interface of the io module: use snapshot.hpp and checkpoint.hpp.
#pragma once

#include <hdf5.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "cairn/parallel/comm.hpp"

namespace cairn {
struct OutputMetadata;
}

namespace cairn::h5 {

/// Switch off HDF5's automatic printing of its error stack (idempotent, thread-safe).
void silence_errors();

/// Owning wrapper of an HDF5 identifier; closes it with the matching H5?close on destruction.
class Handle {
 public:
  using Closer = herr_t (*)(hid_t);
  Handle() = default;
  /// Take ownership of `id`, to be released with `close`.
  Handle(hid_t id, Closer close) : id_(id), close_(close) {}
  ~Handle() { reset(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = H5I_INVALID_HID; }
  Handle& operator=(Handle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = other.id_;
      close_ = other.close_;
      other.id_ = H5I_INVALID_HID;
    }
    return *this;
  }
  /// The identifier (still owned by this handle).
  [[nodiscard]] hid_t get() const { return id_; }
  /// Close the identifier now (no-op if empty).
  void reset() {
    if (id_ >= 0 && close_ != nullptr) close_(id_);
    id_ = H5I_INVALID_HID;
  }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer close_ = nullptr;
};

/// Create (truncate) an HDF5 file for writing; with a `comm` of several ranks every rank calls
/// this and every write below collectively (parallel HDF5, docs/parallel.md): the plain writes
/// then take the same data on every rank (rank 0 writes it), the *_rows writes each rank's rows.
[[nodiscard]] Handle create_file(const std::filesystem::path& path, const Comm& comm = Comm::serial());
/// This rank's rows [first, first + count) of a dataset of `total` rows.
struct Rows {
  std::size_t first = 0;
  std::size_t count = 0;
  std::size_t total = 0;
};
/// Rows of the ranks' local counts n, rank after rank (collective).
[[nodiscard]] inline Rows rows_of(const Comm& comm, std::size_t n) {
  const auto local = static_cast<std::int64_t>(n);
  return Rows{static_cast<std::size_t>(comm.exclusive_prefix(local)), n, static_cast<std::size_t>(comm.sum(local))};
}
/// Distributed datasets: rows.total rows (x cols when cols > 0), this rank writing its rows. In
/// a file of one process (rows = all of them) they are write_doubles/write_ints with `deflate`;
/// a parallel file stores them uncompressed.
void write_doubles_rows(hid_t loc, const std::string& name, const double* data, Rows rows, std::size_t cols = 0,
                        int deflate = 0);
void write_ints_rows(hid_t loc, const std::string& name, const std::int32_t* data, Rows rows, int deflate = 0);
void write_int64s_rows(hid_t loc, const std::string& name, const std::int64_t* data, Rows rows, int deflate = 0);
/// write_doubles_blocked for this rank's rows of a distributed dataset.
void write_doubles_blocked(hid_t loc, const std::string& name, Rows rows, std::size_t cols,
                           const std::function<void(std::size_t, std::size_t, double*)>& fill, int deflate = 0);
/// A double dataset of `shape` of which this rank writes the box [start, start + count) from
/// `data` (the box's values, row-major); an empty box writes nothing. One process: the box is
/// the whole dataset (write_doubles_shaped with `deflate`).
void write_doubles_box(hid_t loc, const std::string& name, const double* data, const std::vector<std::size_t>& shape,
                       const std::vector<std::size_t>& start, const std::vector<std::size_t>& count,
                       int deflate = 0);
/// Rows [first, first + count) of a 1D (cols = 0) or rows x cols dataset.
[[nodiscard]] std::vector<double> read_doubles_rows(hid_t loc, const std::string& name, std::size_t first,
                                                    std::size_t count, std::size_t cols = 0);
[[nodiscard]] std::vector<std::int32_t> read_ints_rows(hid_t loc, const std::string& name, std::size_t first,
                                                       std::size_t count);
[[nodiscard]] std::vector<std::int64_t> read_int64s_rows(hid_t loc, const std::string& name, std::size_t first,
                                                         std::size_t count);
/// Whether a file of `file_bytes` bytes can hold a dataset of `declared_bytes` bytes of values:
/// gzip stores at most about 1000 values in the bytes of one, so a shape above 1100 x the file's
/// size (plus 1 MB) is damaged and is refused before anything of that size is allocated (the
/// checkpoint readers and the content checksum's traversal; docs/robustness.md).
[[nodiscard]] inline bool file_can_hold(double declared_bytes, double file_bytes) {
  return declared_bytes <= 1100.0 * file_bytes + 1e6;
}
/// Open an existing HDF5 file read-only. Throws if it does not exist or is not HDF5.
[[nodiscard]] Handle open_file(const std::filesystem::path& path);
/// Create a group `name` below `loc`.
[[nodiscard]] Handle create_group(hid_t loc, const std::string& name);
/// Open the existing group `name` below `loc`.
[[nodiscard]] Handle open_group(hid_t loc, const std::string& name);
/// Whether `loc` has a direct child link called `name`.
[[nodiscard]] bool has_child(hid_t loc, const std::string& name);

// `deflate` (0-9, output.compression): datasets of at least `min_compressed_elements` values are
// stored chunked (about 1 MiB per chunk, whole rows) with the shuffle and gzip filters at that
// level; 0 stores every dataset contiguous and uncompressed. In a file written by several ranks
// the writes are collective, which parallel HDF5 (>= 1.10.2) needs for filtered datasets.
inline constexpr std::size_t min_compressed_elements = 4096;

/// Write a double dataset: 1D of length `rows` if `cols` == 0, else rows x cols (row-major).
void write_doubles(hid_t loc, const std::string& name, const double* data, std::size_t rows,
                   std::size_t cols = 0, int deflate = 0);
/// Write a double dataset of any rank with the given shape (row-major, last index fastest).
void write_doubles_shaped(hid_t loc, const std::string& name, const double* data,
                          const std::vector<std::size_t>& shape, int deflate = 0);
/// Write a rows x cols double dataset block by block: fill(first, count, buffer) stores rows
/// [first, first + count) row-major in buffer. The buffer holds at most about 1 MiB (one chunk
/// when compressed), so an array whose memory layout differs from the file's is written without
/// a copy of the whole array.
void write_doubles_blocked(hid_t loc, const std::string& name, std::size_t rows, std::size_t cols,
                           const std::function<void(std::size_t, std::size_t, double*)>& fill, int deflate = 0);
/// Write a rows x `file_cols` double dataset from rows x `mem_cols` values in memory (row-major,
/// mem_cols <= file_cols): columns mem_cols.. are zero. Space vectors of D < 3 components are
/// stored this way with 3 columns, without a padded copy.
void write_doubles_padded(hid_t loc, const std::string& name, const double* data, std::size_t rows,
                          std::size_t mem_cols, std::size_t file_cols, int deflate = 0);
/// The same for this rank's rows of a distributed dataset (parallel HDF5).
void write_doubles_padded(hid_t loc, const std::string& name, const double* data, Rows rows,
                          std::size_t mem_cols, std::size_t file_cols, int deflate = 0);
/// Create `view` below `loc` as an HDF5 virtual dataset showing columns [first, first + cols) of
/// the rows x source_cols double dataset `source_path` (absolute path in the same file): no data
/// is copied, and every reader of HDF5 >= 1.10 (h5py, ParaView) sees an ordinary array.
void write_column_view(hid_t loc, const std::string& view, const std::string& source_path,
                       std::size_t rows, std::size_t source_cols, std::size_t first, std::size_t cols);
/// Write a 1D int32 dataset of length `n`.
void write_ints(hid_t loc, const std::string& name, const std::int32_t* data, std::size_t n,
                int deflate = 0);
/// Write a text (any length, no embedded NUL) as a scalar fixed-length string dataset.
void write_text(hid_t loc, const std::string& name, const std::string& text);
/// Write a 1D dataset of fixed-length strings.
void write_text_list(hid_t loc, const std::string& name, const std::vector<std::string>& list);

/// Shape of the dataset `name` below `loc` (empty for a scalar dataset).
[[nodiscard]] std::vector<std::size_t> dataset_shape(hid_t loc, const std::string& name);
/// Read a double dataset whose shape must be exactly `shape`; throws otherwise.
[[nodiscard]] std::vector<double> read_doubles(hid_t loc, const std::string& name,
                                               const std::vector<std::size_t>& shape);
/// Read a 1D int32 dataset of length exactly `n`; throws otherwise.
[[nodiscard]] std::vector<std::int32_t> read_ints(hid_t loc, const std::string& name, std::size_t n);
/// Read a scalar string dataset written by write_text().
[[nodiscard]] std::string read_text(hid_t loc, const std::string& name);
/// Read a 1D string dataset written by write_text_list().
[[nodiscard]] std::vector<std::string> read_text_list(hid_t loc, const std::string& name);

/// Whether the object `obj` (file, group or dataset) has an attribute `name`.
[[nodiscard]] bool has_attribute(hid_t obj, const std::string& name);
/// Attach a string attribute (variable-length UTF-8) to `obj`.
void write_string_attribute(hid_t obj, const std::string& name, const std::string& value);
/// Attach a scalar double attribute to `obj`.
void write_double_attribute(hid_t obj, const std::string& name, double value);
/// Attach a 1D double array attribute to `obj`.
void write_doubles_attribute(hid_t obj, const std::string& name, const std::vector<double>& values);
/// Attach a scalar int64 attribute to `obj`.
void write_int64_attribute(hid_t obj, const std::string& name, long long value);
/// Read a string attribute (fixed- or variable-length).
[[nodiscard]] std::string read_string_attribute(hid_t obj, const std::string& name);
/// Read a scalar numeric attribute as double.
[[nodiscard]] double read_double_attribute(hid_t obj, const std::string& name);
/// Read a 1D numeric array attribute as doubles.
[[nodiscard]] std::vector<double> read_doubles_attribute(hid_t obj, const std::string& name);
/// Read a scalar integer attribute as int64.
[[nodiscard]] long long read_int64_attribute(hid_t obj, const std::string& name);

/// Attach "units", "description" and (if not empty) "components" string attributes to the
/// dataset `name` below `loc` (metadata.cpp).
void describe_dataset(hid_t loc, const std::string& name, const std::string& units,
                      const std::string& description, const std::string& components = {});

/// "'<file>:<object path>/<name>'" for error messages.
[[nodiscard]] std::string describe(hid_t loc, const std::string& name);

/// Root attributes cairn_version, title, units, unit_length, unit_mass, unit_time,
/// unit_temperature, input_sha256 (of the resolved input), the datasets material_names and
/// body_names and, if `with_input`, the resolved input as the text dataset `input` (metadata.cpp).
void write_metadata(hid_t root, const OutputMetadata& meta, bool with_input);

}  // namespace cairn::h5
