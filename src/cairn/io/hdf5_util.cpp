#include "cairn/io/hdf5_util.hpp"

#include <algorithm>
#include <mutex>
#include <stdexcept>

namespace cairn::h5 {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& what, hid_t loc, const std::string& name) {
  throw std::runtime_error("HDF5: " + what + " " + describe(loc, name));
}

/// Throw if an identifier-returning call failed; otherwise wrap it.
Handle checked(hid_t id, Handle::Closer close, const std::string& what, hid_t loc,
               const std::string& name) {
  if (id < 0) fail(what, loc, name);
  return Handle(id, close);
}

void check(herr_t status, const std::string& what, hid_t loc, const std::string& name) {
  if (status < 0) fail(what, loc, name);
}

Handle simple_space(const std::vector<hsize_t>& dims, hid_t loc, const std::string& name) {
  return checked(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose,
                 "cannot create dataspace for", loc, name);
}

/// How the file holding `loc` is written: by one process, or collectively by the ranks of an
/// MPI communicator (create_file with a parallel Comm).
struct Access {
  bool parallel = false;
  bool root = true;
  Handle transfer;  ///< dataset transfer properties (collective I/O when parallel)
};

Access access_of(hid_t loc) {
  Access a;
#ifdef H5_HAVE_PARALLEL
  Handle file(H5Iget_file_id(loc), H5Fclose);
  Handle fapl(H5Fget_access_plist(file.get()), H5Pclose);
  if (fapl.get() >= 0 && H5Pget_driver(fapl.get()) == H5FD_MPIO) {
    MPI_Comm comm = MPI_COMM_NULL;
    MPI_Info info = MPI_INFO_NULL;
    if (H5Pget_fapl_mpio(fapl.get(), &comm, &info) >= 0) {
      int rank = 0;
      MPI_Comm_rank(comm, &rank);
      a.parallel = true;
      a.root = rank == 0;
      MPI_Comm_free(&comm);
      if (info != MPI_INFO_NULL) MPI_Info_free(&info);
      a.transfer = Handle(H5Pcreate(H5P_DATASET_XFER), H5Pclose);
      H5Pset_dxpl_mpio(a.transfer.get(), H5FD_MPIO_COLLECTIVE);
    }
  }
#else
  (void)loc;
#endif
  return a;
}

hid_t transfer_of(const Access& a) { return a.parallel ? a.transfer.get() : H5P_DEFAULT; }

/// Dataset creation properties: contiguous, or chunked with shuffle + gzip(`deflate`) when
/// asked for and the dataset is large enough (whole rows per chunk, about 1 MiB).
Handle creation_properties(const std::vector<hsize_t>& dims, std::size_t element_size, int deflate,
                           hid_t loc, const std::string& name) {
  Handle dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "cannot create properties for", loc, name);
  hsize_t total = 1;
  for (hsize_t d : dims) total *= d;
  if (deflate <= 0 || dims.empty() || total < min_compressed_elements) return dcpl;
  std::vector<hsize_t> chunk = dims;
  const hsize_t row = total / std::max<hsize_t>(dims[0], 1);
  chunk[0] = std::clamp<hsize_t>((hsize_t{1} << 20) / (row * element_size), 1, dims[0]);
  check(H5Pset_chunk(dcpl.get(), static_cast<int>(chunk.size()), chunk.data()), "cannot chunk", loc, name);
  check(H5Pset_shuffle(dcpl.get()), "cannot set the shuffle filter for", loc, name);
  check(H5Pset_deflate(dcpl.get(), static_cast<unsigned>(std::min(deflate, 9))), "cannot set gzip for", loc, name);
  return dcpl;
}

/// Create dataset `name` of file type `ftype` over `dims` and write `data` (memory type `mtype`).
/// In a parallel file every rank passes the same data and rank 0 writes it.
void write_dataset(hid_t loc, const std::string& name, hid_t ftype, hid_t mtype,
                   const std::vector<hsize_t>& dims, const void* data, int deflate = 0) {
  const Access a = access_of(loc);
  Handle space = simple_space(dims, loc, name);
  Handle dcpl = creation_properties(dims, H5Tget_size(ftype), deflate, loc, name);
  Handle dset = checked(H5Dcreate2(loc, name.c_str(), ftype, space.get(), H5P_DEFAULT,
                                   dcpl.get(), H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, name);
  hsize_t total = 1;
  for (hsize_t d : dims) total *= d;
  if (total > 0) {
    Handle memory = simple_space(dims, loc, name);
    if (!a.root) {
      H5Sselect_none(space.get());
      H5Sselect_none(memory.get());
    }
    check(H5Dwrite(dset.get(), mtype, memory.get(), space.get(), transfer_of(a), data),
          "cannot write dataset", loc, name);
  }
}

/// Create dataset `name` of `rows.total` x cols (cols = 0: 1D) and write this rank's rows.
void write_dataset_rows(hid_t loc, const std::string& name, hid_t ftype, hid_t mtype, Rows rows,
                        std::size_t cols, const void* data, int deflate = 0) {
  std::vector<hsize_t> dims{rows.total};
  if (cols > 0) dims.push_back(cols);
  const Access a = access_of(loc);
  if (!a.parallel) {  // one process writes every row
    if (rows.first != 0 || rows.count != rows.total) fail("a partial row range in a serial file for", loc, name);
    write_dataset(loc, name, ftype, mtype, dims, data, deflate);
    return;
  }
  Handle space = simple_space(dims, loc, name);
  // Filtered (compressed) datasets are written collectively, each rank its rows: parallel HDF5
  // >= 1.10.2 compresses a chunk that several ranks' rows share on one of them.
  Handle dcpl = creation_properties(dims, H5Tget_size(ftype), deflate, loc, name);
  Handle dset = checked(H5Dcreate2(loc, name.c_str(), ftype, space.get(), H5P_DEFAULT,
                                   dcpl.get(), H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, name);
  if (rows.total == 0) return;
  const double dummy = 0.0;
  if (data == nullptr) data = &dummy;  // a rank without rows passes no buffer
  std::vector<hsize_t> start(dims.size(), 0), count = dims;
  start[0] = rows.first;
  count[0] = rows.count;
  std::vector<hsize_t> memory_dims = count;
  memory_dims[0] = std::max<hsize_t>(count[0], 1);
  Handle memory = simple_space(memory_dims, loc, name);
  if (rows.count > 0) {
    check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, count.data(), nullptr),
          "cannot select rows of", loc, name);
  } else {
    H5Sselect_none(space.get());
    H5Sselect_none(memory.get());
  }
  check(H5Dwrite(dset.get(), mtype, memory.get(), space.get(), transfer_of(a), data), "cannot write dataset",
        loc, name);
}

Handle open_dataset(hid_t loc, const std::string& name) {
  if (!has_child(loc, name)) fail("missing dataset", loc, name);
  return checked(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose, "cannot open dataset", loc,
                 name);
}

std::vector<std::size_t> space_shape(hid_t space, hid_t loc, const std::string& name) {
  int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0) fail("cannot query the shape of", loc, name);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  if (rank > 0 && H5Sget_simple_extent_dims(space, dims.data(), nullptr) < 0) {
    fail("cannot query the shape of", loc, name);
  }
  return {dims.begin(), dims.end()};
}

std::string shape_str(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(shape[i]);
  }
  return s + ")";
}

/// Open `name` and check that it is a numeric dataset of the given shape.
Handle open_numeric(hid_t loc, const std::string& name, H5T_class_t cls,
                    const std::vector<std::size_t>& shape) {
  Handle dset = open_dataset(loc, name);
  Handle type = checked(H5Dget_type(dset.get()), H5Tclose, "cannot get the type of", loc, name);
  if (H5Tget_class(type.get()) != cls) {
    fail(cls == H5T_FLOAT ? "expected a floating-point dataset:" : "expected an integer dataset:",
         loc, name);
  }
  Handle space = checked(H5Dget_space(dset.get()), H5Sclose, "cannot get the dataspace of", loc, name);
  std::vector<std::size_t> actual = space_shape(space.get(), loc, name);
  if (actual != shape) {
    fail("shape " + shape_str(actual) + " differs from the expected " + shape_str(shape) + " in",
         loc, name);
  }
  return dset;
}

/// Fixed-length string type of `size` bytes (at least 1), NUL-padded.
Handle string_type(std::size_t size, hid_t loc, const std::string& name) {
  Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, "cannot create string type for", loc, name);
  check(H5Tset_size(type.get(), std::max<std::size_t>(size, 1)), "cannot size string type for",
        loc, name);
  check(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), "cannot set string padding for", loc, name);
  return type;
}

/// Text up to the first NUL of a fixed-length string buffer.
std::string trim_nul(const char* data, std::size_t size) {
  const char* end = std::find(data, data + size, '\0');
  return {data, end};
}

Handle open_attribute(hid_t obj, const std::string& name) {
  if (!has_attribute(obj, name)) fail("missing attribute", obj, name);
  return checked(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "cannot open attribute", obj,
                 name);
}

/// Open a numeric attribute and return its number of elements.
Handle open_numeric_attribute(hid_t obj, const std::string& name, bool integer_only,
                              hssize_t& count) {
  Handle attr = open_attribute(obj, name);
  Handle type = checked(H5Aget_type(attr.get()), H5Tclose, "cannot get the type of attribute", obj, name);
  H5T_class_t cls = H5Tget_class(type.get());
  if (cls != H5T_INTEGER && (integer_only || cls != H5T_FLOAT)) {
    fail(integer_only ? "expected an integer attribute:" : "expected a numeric attribute:", obj, name);
  }
  Handle space = checked(H5Aget_space(attr.get()), H5Sclose, "cannot get the dataspace of attribute", obj, name);
  count = H5Sget_simple_extent_npoints(space.get());
  if (count < 0) fail("cannot query the size of attribute", obj, name);
  return attr;
}

void write_attribute(hid_t obj, const std::string& name, hid_t ftype, hid_t mtype, hid_t space,
                     const void* data) {
  if (has_attribute(obj, name)) check(H5Adelete(obj, name.c_str()), "cannot replace attribute", obj, name);
  Handle attr = checked(H5Acreate2(obj, name.c_str(), ftype, space, H5P_DEFAULT, H5P_DEFAULT),
                        H5Aclose, "cannot create attribute", obj, name);
  check(H5Awrite(attr.get(), mtype, data), "cannot write attribute", obj, name);
}

Handle scalar_space(hid_t obj, const std::string& name) {
  return checked(H5Screate(H5S_SCALAR), H5Sclose, "cannot create dataspace for attribute", obj, name);
}

}  // namespace

void silence_errors() {
  static std::once_flag once;
  std::call_once(once, [] { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); });
}

std::string describe(hid_t loc, const std::string& name) {
  std::string file = "?";
  std::string path;
  ssize_t len = H5Fget_name(loc, nullptr, 0);
  if (len >= 0) {
    file.assign(static_cast<std::size_t>(len) + 1, '\0');
    H5Fget_name(loc, file.data(), file.size());
    file.resize(static_cast<std::size_t>(len));
  }
  len = H5Iget_name(loc, nullptr, 0);
  if (len > 0) {
    path.assign(static_cast<std::size_t>(len) + 1, '\0');
    H5Iget_name(loc, path.data(), path.size());
    path.resize(static_cast<std::size_t>(len));
  }
  if (path == "/") path.clear();
  std::string object = name.empty() ? (path.empty() ? "/" : path) : path + "/" + name;
  return "'" + file + ":" + object + "'";
}

Handle create_file(const fs::path& path, const Comm& comm) {
  silence_errors();
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose);
  if (fapl.get() < 0 || H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_STRONG) < 0) {
    throw std::runtime_error("HDF5: cannot set up file access for '" + path.string() + "'");
  }
#if defined(H5_HAVE_PARALLEL) && defined(CAIRN_HAVE_MPI)
  if (comm.parallel() && H5Pset_fapl_mpio(fapl.get(), comm.handle(), MPI_INFO_NULL) < 0)
    throw std::runtime_error("HDF5: cannot set up parallel access for '" + path.string() + "'");
#else
  if (comm.parallel()) throw std::runtime_error("HDF5: this build has no parallel HDF5 for '" + path.string() + "'");
#endif
  hid_t id = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get());
  if (id < 0) throw std::runtime_error("HDF5: cannot create file '" + path.string() + "'");
  return Handle(id, H5Fclose);
}

Handle open_file(const fs::path& path) {
  silence_errors();
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw std::runtime_error("file '" + path.string() + "' does not exist or is not a regular file");
  }
  hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw std::runtime_error("'" + path.string() + "' is not a readable HDF5 file");
  return Handle(id, H5Fclose);
}

Handle create_group(hid_t loc, const std::string& name) {
  return checked(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose,
                 "cannot create group", loc, name);
}

Handle open_group(hid_t loc, const std::string& name) {
  if (!has_child(loc, name)) fail("missing group", loc, name);
  return checked(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), H5Gclose, "cannot open group", loc, name);
}

bool has_child(hid_t loc, const std::string& name) {
  htri_t exists = H5Lexists(loc, name.c_str(), H5P_DEFAULT);
  if (exists < 0) fail("cannot look up", loc, name);
  return exists > 0;
}

void write_doubles(hid_t loc, const std::string& name, const double* data, std::size_t rows,
                   std::size_t cols, int deflate) {
  std::vector<hsize_t> dims{rows};
  if (cols > 0) dims.push_back(cols);
  write_dataset(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, data, deflate);
}

void write_doubles_shaped(hid_t loc, const std::string& name, const double* data,
                          const std::vector<std::size_t>& shape, int deflate) {
  std::vector<hsize_t> dims(shape.begin(), shape.end());
  write_dataset(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, data, deflate);
}

void write_doubles_blocked(hid_t loc, const std::string& name, std::size_t rows, std::size_t cols,
                           const std::function<void(std::size_t, std::size_t, double*)>& fill, int deflate) {
  write_doubles_blocked(loc, name, Rows{0, rows, rows}, cols, fill, deflate);
}

void write_doubles_blocked(hid_t loc, const std::string& name, Rows rows, std::size_t cols,
                           const std::function<void(std::size_t, std::size_t, double*)>& fill, int deflate) {
  const Access a = access_of(loc);
  const std::vector<hsize_t> dims{rows.total, cols};
  Handle space = simple_space(dims, loc, name);
  Handle dcpl = creation_properties(dims, sizeof(double), deflate, loc, name);
  Handle dset = checked(H5Dcreate2(loc, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                   dcpl.get(), H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, name);
  if (rows.total == 0 || cols == 0) return;
  // 2^17 doubles: the rows of one chunk when compressed (creation_properties), so blocks align.
  const std::size_t block = std::max<std::size_t>(1, (std::size_t{1} << 17) / cols);
  std::vector<double> buffer(std::max<std::size_t>(std::min(rows.count, block), 1) * cols);
  // Collective I/O: every rank takes part in the same number of writes (an empty selection
  // once its rows are done).
  std::size_t n_blocks = (rows.count + block - 1) / block;
  if (a.parallel) {
    std::int64_t most = static_cast<std::int64_t>(n_blocks);
    Comm::world().max(&most, 1);
    n_blocks = static_cast<std::size_t>(most);
  }
  for (std::size_t b = 0; b < n_blocks; ++b) {
    const std::size_t first = b * block;
    const std::size_t count = first < rows.count ? std::min(block, rows.count - first) : 0;
    if (count > 0) fill(first, count, buffer.data());
    const hsize_t start[2] = {rows.first + first, 0}, extent[2] = {count, cols};
    Handle memory = simple_space({std::max<hsize_t>(count, 1), cols}, loc, name);
    if (count > 0) {
      check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, extent, nullptr),
            "cannot select rows of", loc, name);
    } else {
      H5Sselect_none(space.get());
      H5Sselect_none(memory.get());
    }
    check(H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, memory.get(), space.get(), transfer_of(a), buffer.data()),
          "cannot write dataset", loc, name);
  }
}

void write_doubles_rows(hid_t loc, const std::string& name, const double* data, Rows rows, std::size_t cols,
                        int deflate) {
  write_dataset_rows(loc, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, rows, cols, data, deflate);
}

void write_ints_rows(hid_t loc, const std::string& name, const std::int32_t* data, Rows rows, int deflate) {
  write_dataset_rows(loc, name, H5T_STD_I32LE, H5T_NATIVE_INT32, rows, 0, data, deflate);
}

void write_int64s_rows(hid_t loc, const std::string& name, const std::int64_t* data, Rows rows, int deflate) {
  write_dataset_rows(loc, name, H5T_STD_I64LE, H5T_NATIVE_INT64, rows, 0, data, deflate);
}

void write_doubles_box(hid_t loc, const std::string& name, const double* data, const std::vector<std::size_t>& shape,
                       const std::vector<std::size_t>& start, const std::vector<std::size_t>& count, int deflate) {
  const Access a = access_of(loc);
  if (!a.parallel) {  // one process: the box is the whole dataset
    if (start != std::vector<std::size_t>(start.size(), 0) || count != shape)
      fail("a partial box in a serial file for", loc, name);
    write_doubles_shaped(loc, name, data, shape, deflate);
    return;
  }
  const std::vector<hsize_t> dims(shape.begin(), shape.end());
  Handle space = simple_space(dims, loc, name);
  Handle dset = checked(H5Dcreate2(loc, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                   H5P_DEFAULT, H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, name);
  const std::vector<hsize_t> first(start.begin(), start.end()), extent(count.begin(), count.end());
  hsize_t n = 1;
  for (hsize_t c : extent) n *= c;
  std::vector<hsize_t> memory_dims = extent;
  for (hsize_t& d : memory_dims) d = std::max<hsize_t>(d, 1);
  Handle memory = simple_space(memory_dims, loc, name);
  if (n > 0) {
    check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, first.data(), nullptr, extent.data(), nullptr),
          "cannot select a box of", loc, name);
  } else {
    H5Sselect_none(space.get());
    H5Sselect_none(memory.get());
  }
  const double dummy = 0.0;
  check(H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, memory.get(), space.get(), transfer_of(a), n > 0 ? data : &dummy),
        "cannot write dataset", loc, name);
}

std::vector<double> read_doubles_rows(hid_t loc, const std::string& name, std::size_t first, std::size_t count,
                                      std::size_t cols) {
  Handle dset = open_dataset(loc, name);
  Handle space = checked(H5Dget_space(dset.get()), H5Sclose, "cannot get the dataspace of", loc, name);
  const std::vector<std::size_t> shape = space_shape(space.get(), loc, name);
  if (shape.empty() || first + count > shape[0] || (cols == 0 ? shape.size() != 1 : shape.size() != 2 || shape[1] != cols))
    fail("unexpected shape of", loc, name);
  std::vector<double> data(count * std::max<std::size_t>(cols, 1));
  if (count == 0) return data;
  std::vector<hsize_t> start(shape.size(), 0), extent(shape.begin(), shape.end());
  start[0] = first;
  extent[0] = count;
  check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start.data(), nullptr, extent.data(), nullptr),
        "cannot select rows of", loc, name);
  Handle memory = simple_space(extent, loc, name);
  check(H5Dread(dset.get(), H5T_NATIVE_DOUBLE, memory.get(), space.get(), H5P_DEFAULT, data.data()),
        "cannot read dataset", loc, name);
  return data;
}

template <class T>
std::vector<T> read_integers_rows(hid_t loc, const std::string& name, std::size_t first, std::size_t count,
                                  hid_t mtype) {
  Handle dset = open_dataset(loc, name);
  Handle space = checked(H5Dget_space(dset.get()), H5Sclose, "cannot get the dataspace of", loc, name);
  const std::vector<std::size_t> shape = space_shape(space.get(), loc, name);
  if (shape.size() != 1 || first + count > shape[0]) fail("unexpected shape of", loc, name);
  std::vector<T> data(count);
  if (count == 0) return data;
  const hsize_t start[1] = {first}, extent[1] = {count};
  check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, extent, nullptr), "cannot select rows of",
        loc, name);
  Handle memory = simple_space({count}, loc, name);
  check(H5Dread(dset.get(), mtype, memory.get(), space.get(), H5P_DEFAULT, data.data()), "cannot read dataset", loc,
        name);
  return data;
}

std::vector<std::int32_t> read_ints_rows(hid_t loc, const std::string& name, std::size_t first, std::size_t count) {
  return read_integers_rows<std::int32_t>(loc, name, first, count, H5T_NATIVE_INT32);
}

std::vector<std::int64_t> read_int64s_rows(hid_t loc, const std::string& name, std::size_t first, std::size_t count) {
  return read_integers_rows<std::int64_t>(loc, name, first, count, H5T_NATIVE_INT64);
}

void write_doubles_padded(hid_t loc, const std::string& name, const double* data, std::size_t rows,
                          std::size_t mem_cols, std::size_t file_cols, int deflate) {
  write_doubles_padded(loc, name, data, Rows{0, rows, rows}, mem_cols, file_cols, deflate);
}

void write_doubles_padded(hid_t loc, const std::string& name, const double* data, Rows rows,
                          std::size_t mem_cols, std::size_t file_cols, int deflate) {
  if (mem_cols == file_cols) {
    write_doubles_rows(loc, name, data, rows, file_cols, deflate);
    return;
  }
  if (mem_cols > file_cols) fail("more columns in memory than in the file for", loc, name);
  const Access a = access_of(loc);
  if (a.parallel) deflate = 0;
  const std::vector<hsize_t> dims{rows.total, file_cols};
  Handle space = simple_space(dims, loc, name);
  Handle dcpl = creation_properties(dims, sizeof(double), deflate, loc, name);
  const double zero = 0.0;
  check(H5Pset_fill_value(dcpl.get(), H5T_NATIVE_DOUBLE, &zero), "cannot set the fill value of", loc, name);
  check(H5Pset_alloc_time(dcpl.get(), deflate > 0 ? H5D_ALLOC_TIME_INCR : H5D_ALLOC_TIME_EARLY),
        "cannot set the allocation time of", loc, name);
  Handle dset = checked(H5Dcreate2(loc, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT,
                                   dcpl.get(), H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, name);
  if (rows.total == 0 || mem_cols == 0) return;
  // The first mem_cols columns of this rank's rows, from a dense rows x mem_cols array in memory.
  const hsize_t start[2] = {rows.first, 0}, count[2] = {rows.count, mem_cols};
  Handle mspace = simple_space({std::max<hsize_t>(rows.count, 1), mem_cols}, loc, name);
  if (rows.count > 0) {
    check(H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
          "cannot select columns of", loc, name);
  } else {
    H5Sselect_none(space.get());
    H5Sselect_none(mspace.get());
  }
  const double dummy = 0.0;
  check(H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, mspace.get(), space.get(), transfer_of(a),
                 rows.count > 0 ? data : &dummy),
        "cannot write dataset", loc, name);
}

void write_column_view(hid_t loc, const std::string& view, const std::string& source_path,
                       std::size_t rows, std::size_t source_cols, std::size_t first, std::size_t cols) {
  Handle vspace = simple_space({rows, cols}, loc, view);
  Handle sspace = simple_space({rows, source_cols}, loc, view);
  if (rows > 0) {
    const hsize_t start[2] = {0, first}, count[2] = {rows, cols};
    check(H5Sselect_hyperslab(sspace.get(), H5S_SELECT_SET, start, nullptr, count, nullptr),
          "cannot select the source columns of", loc, view);
  }
  Handle dcpl = checked(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "cannot create properties for", loc, view);
  if (rows > 0) {
    check(H5Pset_virtual(dcpl.get(), vspace.get(), ".", source_path.c_str(), sspace.get()),
          "cannot map the virtual dataset", loc, view);
  }
  Handle dset = checked(H5Dcreate2(loc, view.c_str(), H5T_IEEE_F64LE, vspace.get(), H5P_DEFAULT,
                                   dcpl.get(), H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, view);
}

void write_ints(hid_t loc, const std::string& name, const std::int32_t* data, std::size_t n,
                int deflate) {
  write_dataset(loc, name, H5T_STD_I32LE, H5T_NATIVE_INT32, {n}, data, deflate);
}

void write_text(hid_t loc, const std::string& name, const std::string& text) {
  Handle type = string_type(text.size(), loc, name);
  Handle space = checked(H5Screate(H5S_SCALAR), H5Sclose, "cannot create dataspace for", loc, name);
  Handle dset = checked(H5Dcreate2(loc, name.c_str(), type.get(), space.get(), H5P_DEFAULT,
                                   H5P_DEFAULT, H5P_DEFAULT),
                        H5Dclose, "cannot create dataset", loc, name);
  std::string buffer = text;
  buffer.resize(std::max<std::size_t>(text.size(), 1), '\0');
  const Access a = access_of(loc);
  Handle memory = checked(H5Screate(H5S_SCALAR), H5Sclose, "cannot create dataspace for", loc, name);
  if (!a.root) {  // a parallel file: rank 0 writes what every rank passes
    H5Sselect_none(space.get());
    H5Sselect_none(memory.get());
  }
  check(H5Dwrite(dset.get(), type.get(), memory.get(), space.get(), transfer_of(a), buffer.data()),
        "cannot write dataset", loc, name);
}

void write_text_list(hid_t loc, const std::string& name, const std::vector<std::string>& list) {
  std::size_t width = 1;
  for (const auto& s : list) width = std::max(width, s.size());
  std::string buffer(width * list.size(), '\0');
  for (std::size_t i = 0; i < list.size(); ++i) std::copy(list[i].begin(), list[i].end(), buffer.begin() + static_cast<std::ptrdiff_t>(i * width));
  Handle type = string_type(width, loc, name);
  write_dataset(loc, name, type.get(), type.get(), {list.size()}, buffer.data());
}

std::vector<std::size_t> dataset_shape(hid_t loc, const std::string& name) {
  Handle dset = open_dataset(loc, name);
  Handle space = checked(H5Dget_space(dset.get()), H5Sclose, "cannot get the dataspace of", loc, name);
  return space_shape(space.get(), loc, name);
}

std::vector<double> read_doubles(hid_t loc, const std::string& name,
                                 const std::vector<std::size_t>& shape) {
  Handle dset = open_numeric(loc, name, H5T_FLOAT, shape);
  std::size_t total = 1;
  for (std::size_t d : shape) total *= d;
  std::vector<double> data(total);
  if (total > 0) {
    check(H5Dread(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()),
          "cannot read dataset", loc, name);
  }
  return data;
}

std::vector<std::int32_t> read_ints(hid_t loc, const std::string& name, std::size_t n) {
  Handle dset = open_numeric(loc, name, H5T_INTEGER, {n});
  std::vector<std::int32_t> data(n);
  if (n > 0) {
    check(H5Dread(dset.get(), H5T_NATIVE_INT32, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()),
          "cannot read dataset", loc, name);
  }
  return data;
}

std::string read_text(hid_t loc, const std::string& name) {
  Handle dset = open_dataset(loc, name);
  Handle type = checked(H5Dget_type(dset.get()), H5Tclose, "cannot get the type of", loc, name);
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0) {
    fail("expected a fixed-length string dataset:", loc, name);
  }
  std::size_t size = H5Tget_size(type.get());
  Handle space = checked(H5Dget_space(dset.get()), H5Sclose, "cannot get the dataspace of", loc, name);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) fail("expected a scalar string:", loc, name);
  Handle mtype = string_type(size, loc, name);
  std::string buffer(size, '\0');
  check(H5Dread(dset.get(), mtype.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()),
        "cannot read dataset", loc, name);
  return trim_nul(buffer.data(), size);
}

std::vector<std::string> read_text_list(hid_t loc, const std::string& name) {
  Handle dset = open_dataset(loc, name);
  Handle type = checked(H5Dget_type(dset.get()), H5Tclose, "cannot get the type of", loc, name);
  if (H5Tget_class(type.get()) != H5T_STRING || H5Tis_variable_str(type.get()) != 0) {
    fail("expected a fixed-length string dataset:", loc, name);
  }
  std::size_t width = H5Tget_size(type.get());
  Handle space = checked(H5Dget_space(dset.get()), H5Sclose, "cannot get the dataspace of", loc, name);
  std::vector<std::size_t> shape = space_shape(space.get(), loc, name);
  if (shape.size() != 1) fail("expected a 1D string dataset:", loc, name);
  std::vector<std::string> list;
  if (shape[0] == 0) return list;
  Handle mtype = string_type(width, loc, name);
  std::string buffer(width * shape[0], '\0');
  check(H5Dread(dset.get(), mtype.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, buffer.data()),
        "cannot read dataset", loc, name);
  for (std::size_t i = 0; i < shape[0]; ++i) list.push_back(trim_nul(buffer.data() + i * width, width));
  return list;
}

bool has_attribute(hid_t obj, const std::string& name) {
  htri_t exists = H5Aexists(obj, name.c_str());
  if (exists < 0) fail("cannot look up attribute", obj, name);
  return exists > 0;
}

void write_string_attribute(hid_t obj, const std::string& name, const std::string& value) {
  // Variable-length UTF-8: h5py and other readers return it as a str, not as bytes.
  Handle type = checked(H5Tcopy(H5T_C_S1), H5Tclose, "cannot create string type for", obj, name);
  check(H5Tset_size(type.get(), H5T_VARIABLE), "cannot size string type for", obj, name);
  check(H5Tset_cset(type.get(), H5T_CSET_UTF8), "cannot set the character set for", obj, name);
  Handle space = scalar_space(obj, name);
  const char* text = value.c_str();
  write_attribute(obj, name, type.get(), type.get(), space.get(), &text);
}

void write_double_attribute(hid_t obj, const std::string& name, double value) {
  Handle space = scalar_space(obj, name);
  write_attribute(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, space.get(), &value);
}

void write_doubles_attribute(hid_t obj, const std::string& name, const std::vector<double>& values) {
  Handle space = simple_space({values.size()}, obj, name);
  write_attribute(obj, name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, space.get(), values.data());
}

void write_int64_attribute(hid_t obj, const std::string& name, long long value) {
  Handle space = scalar_space(obj, name);
  write_attribute(obj, name, H5T_STD_I64LE, H5T_NATIVE_LLONG, space.get(), &value);
}

std::string read_string_attribute(hid_t obj, const std::string& name) {
  Handle attr = open_attribute(obj, name);
  Handle type = checked(H5Aget_type(attr.get()), H5Tclose, "cannot get the type of attribute", obj, name);
  if (H5Tget_class(type.get()) != H5T_STRING) fail("expected a string attribute:", obj, name);
  Handle space = checked(H5Aget_space(attr.get()), H5Sclose, "cannot get the dataspace of attribute", obj, name);
  if (H5Sget_simple_extent_npoints(space.get()) != 1) fail("expected a scalar string attribute:", obj, name);
  if (H5Tis_variable_str(type.get()) > 0) {
    Handle mtype = checked(H5Tcopy(H5T_C_S1), H5Tclose, "cannot create string type for", obj, name);
    check(H5Tset_size(mtype.get(), H5T_VARIABLE), "cannot size string type for", obj, name);
    check(H5Tset_cset(mtype.get(), H5Tget_cset(type.get())), "cannot set the character set for", obj, name);
    char* text = nullptr;
    check(H5Aread(attr.get(), mtype.get(), &text), "cannot read attribute", obj, name);
    std::string value = text != nullptr ? std::string(text) : std::string();
    H5free_memory(text);
    return value;
  }
  std::size_t size = H5Tget_size(type.get());
  Handle mtype = string_type(size, obj, name);
  std::string buffer(size, '\0');
  check(H5Aread(attr.get(), mtype.get(), buffer.data()), "cannot read attribute", obj, name);
  return trim_nul(buffer.data(), size);
}

double read_double_attribute(hid_t obj, const std::string& name) {
  hssize_t count = 0;
  Handle attr = open_numeric_attribute(obj, name, false, count);
  if (count != 1) fail("expected a scalar attribute:", obj, name);
  double value = 0.0;
  check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &value), "cannot read attribute", obj, name);
  return value;
}

std::vector<double> read_doubles_attribute(hid_t obj, const std::string& name) {
  hssize_t count = 0;
  Handle attr = open_numeric_attribute(obj, name, false, count);
  std::vector<double> values(static_cast<std::size_t>(count));
  if (count > 0) check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, values.data()), "cannot read attribute", obj, name);
  return values;
}

long long read_int64_attribute(hid_t obj, const std::string& name) {
  hssize_t count = 0;
  Handle attr = open_numeric_attribute(obj, name, true, count);
  if (count != 1) fail("expected a scalar attribute:", obj, name);
  long long value = 0;
  check(H5Aread(attr.get(), H5T_NATIVE_LLONG, &value), "cannot read attribute", obj, name);
  return value;
}

}  // namespace cairn::h5
