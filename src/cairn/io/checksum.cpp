#include "cairn/io/checksum.hpp"

#include "cairn/io/hdf5_util.hpp"

#include <fmt/format.h>
#include <xxhash.h>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace cairn {
namespace {

constexpr const char* attribute_name = "checksum";

/// Streaming 64-bit XXH3 (libxxhash) over the content; texts carry their length so that field
/// boundaries count (array shapes are hashed before array bytes).
class Hash {
 public:
  Hash() : state_(XXH3_createState()) {
    if (state_ == nullptr || XXH3_64bits_reset(state_) == XXH_ERROR)
      throw std::runtime_error("checksum: cannot create the XXH3 state");
  }
  ~Hash() { XXH3_freeState(state_); }
  Hash(const Hash&) = delete;
  Hash& operator=(const Hash&) = delete;
  void bytes(const void* data, std::size_t n) {
    if (n > 0) XXH3_64bits_update(state_, data, n);
  }
  void text(const std::string& s) {
    word(s.size());
    bytes(s.data(), s.size());
  }
  void word(std::uint64_t w) { XXH3_64bits_update(state_, &w, sizeof w); }
  [[nodiscard]] std::uint64_t value() const { return XXH3_64bits_digest(state_); }

 private:
  XXH3_state_t* state_;
};

/// Closes an HDF5 id on scope exit.
struct Id {
  hid_t id;
  herr_t (*close)(hid_t);
  ~Id() {
    if (id >= 0) close(id);
  }
};

void check(bool ok, const std::string& what) {
  if (!ok) throw std::runtime_error("checksum: cannot read " + what);
}

/// A dataset or attribute of `obj` declaring `dims` of `element` bytes that the file's bytes
/// cannot hold (gzip stores at most about 1000 values in the bytes of one, as read_checkpoint
/// allows) is refused before its values are allocated: a damaged shape, not an allocation.
void check_declared(hid_t obj, const std::vector<hsize_t>& dims, std::size_t element, const std::string& what) {
  double bytes = static_cast<double>(element);
  for (hsize_t d : dims) bytes *= static_cast<double>(d);
  Id file{H5Iget_file_id(obj), H5Fclose};
  hsize_t file_bytes = 0;
  check(file.id >= 0 && H5Fget_filesize(file.id, &file_bytes) >= 0, "the file size for " + what);
  if (!h5::file_can_hold(bytes, static_cast<double>(file_bytes)))
    throw std::runtime_error(fmt::format("checksum: {} declares {:.6g} bytes of values in a file of {} bytes",
                                         what, bytes, file_bytes));
}

/// Type class, element size and (variable-length strings) by content: the shared part of
/// datasets and attributes.
void hash_type(Hash& h, hid_t type) {
  h.word(static_cast<std::uint64_t>(H5Tget_class(type)));
  h.word(H5Tget_size(type));
}

void hash_shape(Hash& h, hid_t space, std::vector<hsize_t>& dims) {
  const int rank = H5Sget_simple_extent_ndims(space);
  dims.assign(static_cast<std::size_t>(std::max(rank, 0)), 0);
  if (rank > 0) H5Sget_simple_extent_dims(space, dims.data(), nullptr);
  h.word(static_cast<std::uint64_t>(rank));
  for (hsize_t d : dims) h.word(d);
}

/// Variable-length strings: read through a char* memory type (of the file type's character set,
/// ASCII or UTF-8: HDF5 converts between neither) and hash their text.
template <class Read>
void hash_vlen_strings(Hash& h, hid_t type, hid_t space, std::size_t count, Read&& read, const std::string& what) {
  Id mtype{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(mtype.id, H5T_VARIABLE);
  H5Tset_cset(mtype.id, H5Tget_cset(type));
  std::vector<char*> strings(count, nullptr);
  check(read(mtype.id, strings.data()) >= 0, what);
  for (char* s : strings) h.text(s ? std::string(s) : std::string());
  H5Dvlen_reclaim(mtype.id, space, H5P_DEFAULT, strings.data());
}

void hash_attribute(Hash& h, hid_t obj, const char* name) {
  Id attr{H5Aopen(obj, name, H5P_DEFAULT), H5Aclose};
  check(attr.id >= 0, std::string("attribute ") + name);
  Id type{H5Aget_type(attr.id), H5Tclose};
  Id space{H5Aget_space(attr.id), H5Sclose};
  h.text(std::string("@") + name);
  hash_type(h, type.id);
  std::vector<hsize_t> dims;
  hash_shape(h, space.id, dims);
  check_declared(obj, dims, std::max<std::size_t>(H5Tget_size(type.id), sizeof(char*)), std::string("attribute ") + name);
  const auto count = static_cast<std::size_t>(std::max<hssize_t>(H5Sget_simple_extent_npoints(space.id), 0));
  if (H5Tis_variable_str(type.id) > 0) {
    hash_vlen_strings(h, type.id, space.id, count, [&](hid_t m, void* buf) { return H5Aread(attr.id, m, buf); },
                      std::string("attribute ") + name);
    return;
  }
  std::vector<unsigned char> data(count * H5Tget_size(type.id));
  if (!data.empty()) check(H5Aread(attr.id, type.id, data.data()) >= 0, std::string("attribute ") + name);
  h.bytes(data.data(), data.size());
}

/// Every attribute of `obj` in name order (the root's checksum attribute left out).
void hash_attributes(Hash& h, hid_t obj, bool is_root) {
  std::vector<std::string> names;
  auto collect = [](hid_t, const char* name, const H5A_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->emplace_back(name);
    return 0;
  };
  hsize_t index = 0;
  check(H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names) >= 0, "attributes");
  std::sort(names.begin(), names.end());
  for (const auto& name : names)
    if (!(is_root && name == attribute_name)) hash_attribute(h, obj, name.c_str());
}

void hash_dataset(Hash& h, hid_t dset, const std::string& path) {
  Id type{H5Dget_type(dset), H5Tclose};
  Id space{H5Dget_space(dset), H5Sclose};
  hash_type(h, type.id);
  std::vector<hsize_t> dims;
  hash_shape(h, space.id, dims);
  check_declared(dset, dims, std::max<std::size_t>(H5Tget_size(type.id), sizeof(char*)), "dataset " + path);
  const auto count = static_cast<std::size_t>(std::max<hssize_t>(H5Sget_simple_extent_npoints(space.id), 0));
  if (count == 0) return;
  if (H5Tis_variable_str(type.id) > 0) {
    hash_vlen_strings(h, type.id, space.id, count,
                      [&](hid_t m, void* buf) { return H5Dread(dset, m, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf); },
                      "dataset " + path);
    return;
  }
  const std::size_t element = H5Tget_size(type.id);
  if (dims.empty()) {  // scalar
    std::vector<unsigned char> data(element);
    check(H5Dread(dset, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data()) >= 0, "dataset " + path);
    h.bytes(data.data(), data.size());
    return;
  }
  // Slabs of whole rows along the first axis, about 8 MiB each, so that a large particle array
  // is not held twice in memory.
  std::size_t row = element;
  for (std::size_t d = 1; d < dims.size(); ++d) row *= dims[d];
  const hsize_t rows_per_slab = std::max<hsize_t>(1, (8u << 20) / std::max<std::size_t>(row, 1));
  std::vector<unsigned char> data;
  for (hsize_t first = 0; first < dims[0]; first += rows_per_slab) {
    std::vector<hsize_t> start(dims.size(), 0), size = dims;
    start[0] = first;
    size[0] = std::min(rows_per_slab, dims[0] - first);
    Id file_space{H5Scopy(space.id), H5Sclose};
    H5Sselect_hyperslab(file_space.id, H5S_SELECT_SET, start.data(), nullptr, size.data(), nullptr);
    Id mem_space{H5Screate_simple(static_cast<int>(size.size()), size.data(), nullptr), H5Sclose};
    data.resize(static_cast<std::size_t>(size[0]) * row);
    check(H5Dread(dset, type.id, mem_space.id, file_space.id, H5P_DEFAULT, data.data()) >= 0, "dataset " + path);
    h.bytes(data.data(), data.size());
  }
}

void hash_group(Hash& h, hid_t group, const std::string& path, bool is_root) {
  hash_attributes(h, group, is_root);
  H5G_info_t info{};
  check(H5Gget_info(group, &info) >= 0, "group " + path);
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks; ++i) {
    const ssize_t n = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    check(n >= 0, "a link name in " + path);
    std::string name(static_cast<std::size_t>(n) + 1, '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(n));
    names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  for (const auto& name : names) {
    const std::string child = path + "/" + name;
    Id obj{H5Oopen(group, name.c_str(), H5P_DEFAULT), H5Oclose};
    check(obj.id >= 0, child);
    h.text(child);
    const H5I_type_t kind = H5Iget_type(obj.id);
    h.word(static_cast<std::uint64_t>(kind));
    if (kind == H5I_GROUP) {
      hash_group(h, obj.id, child, false);
    } else if (kind == H5I_DATASET) {
      hash_dataset(h, obj.id, child);
      hash_attributes(h, obj.id, false);
    }
  }
}

std::string hex(std::uint64_t v) { return fmt::format("{:016x}", v); }

}  // namespace

std::uint64_t h5_content_checksum(hid_t root) {
  Hash h;
  hash_group(h, root, "", true);
  return h.value();
}

void write_content_checksum(hid_t root) {
  const std::string text = hex(h5_content_checksum(root));
  Id type{H5Tcopy(H5T_C_S1), H5Tclose};
  H5Tset_size(type.id, text.size());
  Id space{H5Screate(H5S_SCALAR), H5Sclose};
  Id attr{H5Acreate2(root, attribute_name, type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose};
  if (attr.id < 0 || H5Awrite(attr.id, type.id, text.data()) < 0)
    throw std::runtime_error("cannot write the checksum attribute");
}

bool content_checksum_matches(hid_t root, std::string& stored, std::string& computed) {
  stored.clear();
  computed.clear();
  if (H5Aexists(root, attribute_name) <= 0) return true;
  {
    Id attr{H5Aopen(root, attribute_name, H5P_DEFAULT), H5Aclose};
    Id type{H5Aget_type(attr.id), H5Tclose};
    if (attr.id < 0 || type.id < 0 || H5Tget_class(type.id) != H5T_STRING || H5Tis_variable_str(type.id) > 0) {
      stored = "(unreadable)";
    } else {
      stored.assign(H5Tget_size(type.id), '\0');
      if (H5Aread(attr.id, type.id, stored.data()) < 0) stored = "(unreadable)";
    }
  }
  computed = hex(h5_content_checksum(root));
  return stored == computed;
}

}  // namespace cairn
