// Fuzz target for the checkpoint reader: a damaged or edited checkpoint -> restore_engine (which
// reads the file, its engine, dimension, stored input and particles) -> the first step. Every
// outcome must be a restored run or an input error naming the checkpoint file (exit 2 in the
// CLI: InputError, UnknownName, std::invalid_argument); a simulation failure in the first step of
// a restored run (exit 3) also counts as handled. Any other exception (exit 1), a crash, an
// AddressSanitizer report or a hang is a finding (docs/robustness.md, "Files from outside").
//
// An input is either a whole checkpoint file (it starts with the HDF5 signature: byte-level
// mutations, mostly refused by the content checksum or by HDF5 itself), or a program of
// structured mutations applied with the HDF5 C API to one of the seed checkpoints (real files
// written by small runs: MPM in 1D, 2D with contact and state variables, 3D APIC with
// temperature, WLS, WLS bodies in contact, a run on 2 MPI ranks, the FEM;
// tests/robustness/corpus/checkpoint/seeds):
//
//   byte 0: the seed; byte 1: the checksum afterwards (recomputed, so that the reader's own checks
//   are reached; left stale; deleted); then 8-byte operations [op, a, b, c, d0..d3]: delete a
//   dataset or an attribute, rewrite a dataset with another shape or type, an attribute with
//   another type or shape, poke a hostile number (NaN, -1, 2^31, 1e308, ...) into a dataset or
//   attribute, set a string attribute (engine, format), replace a dataset or the stored input by
//   the one of another seed (another dimension, engine or rank count), flip a byte or truncate
//   the file (after the HDF5 edits).
//
// Two builds of this file, as fuzz_input.cpp:
//  - default: a standalone driver that first replays every file of the --corpus folders (whole
//    checkpoints and programs alike: the regression files of earlier findings), then runs random
//    programs and random byte edits for --seconds with a fixed --seed; ctest runs it as
//    robustness.fuzz_checkpoint. On a finding it saves the input as finding-<n>.bin in the
//    scratch folder, prints its path and exits 1.
//  - CAIRN_LIBFUZZER (preset "fuzz"): LLVMFuzzerTestOneInput, e.g.
//    build/fuzz/tests/robustness/cairn_fuzz_checkpoint -max_total_time=600 corpus/checkpoint/...
#include <hdf5.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include "cairn/config/errors.hpp"
#include "cairn/io/checksum.hpp"
#include "cairn/run/engine.hpp"
#include "cairn/run/summary.hpp"
#include "cairn/util/child_process.hpp"
#include "cairn/util/registry.hpp"
#include "fuzz_support.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::string> seeds;  // the bytes of the seed checkpoints, in name order
std::vector<std::string> seed_names;
using fuzz::scratch;
using fuzz::slurp;
using fuzz::spill;

void load_seeds(const fs::path& folder) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder))
    if (e.path().extension() == ".h5") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const auto& f : files) {
    seeds.push_back(slurp(f));
    seed_names.push_back(f.filename().string());
  }
}

void make_scratch() {
  fuzz::make_scratch("fuzz_checkpoint");
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
}

// ---- structured mutations with the HDF5 C API -------------------------------------------------

/// Closes an HDF5 id on scope exit.
struct Id {
  hid_t id;
  herr_t (*close)(hid_t);
  Id(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~Id() {
    if (id >= 0) close(id);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
};

struct Objects {
  std::vector<std::string> datasets;                             // absolute paths
  std::vector<std::pair<std::string, std::string>> attributes;   // object path, attribute name
};

void collect_attributes(hid_t obj, const std::string& path, Objects& out) {
  std::vector<std::string> names;
  auto add = [](hid_t, const char* name, const H5A_info_t*, void* to) -> herr_t {
    static_cast<std::vector<std::string>*>(to)->emplace_back(name);
    return 0;
  };
  hsize_t index = 0;
  H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &index, add, &names);
  for (auto& name : names) out.attributes.emplace_back(path, std::move(name));
}

void collect(hid_t group, const std::string& path, Objects& out, int depth) {
  collect_attributes(group, path.empty() ? "/" : path, out);
  if (depth > 4) return;
  H5G_info_t info{};
  if (H5Gget_info(group, &info) < 0) return;
  for (hsize_t i = 0; i < info.nlinks && i < 64; ++i) {
    const ssize_t n = H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, nullptr, 0, H5P_DEFAULT);
    if (n <= 0) continue;
    std::string name(static_cast<std::size_t>(n) + 1, '\0');
    H5Lget_name_by_idx(group, ".", H5_INDEX_NAME, H5_ITER_INC, i, name.data(), name.size(), H5P_DEFAULT);
    name.resize(static_cast<std::size_t>(n));
    const std::string child = path + "/" + name;
    Id obj(H5Oopen(group, name.c_str(), H5P_DEFAULT), H5Oclose);
    if (obj.id < 0) continue;
    const H5I_type_t kind = H5Iget_type(obj.id);
    if (kind == H5I_GROUP) {
      collect(obj.id, child, out, depth + 1);
    } else if (kind == H5I_DATASET) {
      out.datasets.push_back(child);
      collect_attributes(obj.id, child, out);
    }
  }
}

/// The content of a dataset or attribute: numbers as doubles, or strings.
struct Content {
  bool numeric = true;
  bool integer = false;
  std::vector<hsize_t> dims;  // empty: scalar
  std::vector<double> numbers;
  std::vector<std::string> strings;
};

std::size_t count_of(const std::vector<hsize_t>& dims) {
  std::size_t n = 1;
  for (hsize_t d : dims) n *= static_cast<std::size_t>(d);
  return n;
}

/// Read through `read(mem_type, buffer)`; false when the content is neither numeric nor a string
/// or too large to be worth it.
template <class Read>
bool read_content(hid_t type, hid_t space, Content& c, Read&& read) {
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 0 || rank > 4) return false;
  c.dims.assign(static_cast<std::size_t>(rank), 0);
  if (rank > 0) H5Sget_simple_extent_dims(space, c.dims.data(), nullptr);
  const std::size_t n = count_of(c.dims);
  if (n > (1u << 22)) return false;
  const H5T_class_t cls = H5Tget_class(type);
  if (cls == H5T_INTEGER || cls == H5T_FLOAT) {
    c.numeric = true;
    c.integer = cls == H5T_INTEGER;
    c.numbers.assign(n, 0.0);
    return n == 0 || read(H5T_NATIVE_DOUBLE, c.numbers.data()) >= 0;
  }
  if (cls != H5T_STRING) return false;
  c.numeric = false;
  if (H5Tis_variable_str(type) > 0) {
    Id m(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(m.id, H5T_VARIABLE);
    H5Tset_cset(m.id, H5Tget_cset(type));
    std::vector<char*> p(n, nullptr);
    if (n > 0 && read(m.id, p.data()) < 0) return false;
    for (char* s : p) {
      c.strings.emplace_back(s ? s : "");
      H5free_memory(s);
    }
    return true;
  }
  const std::size_t width = H5Tget_size(type);
  if (width == 0 || width > (1u << 20)) return false;
  Id m(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(m.id, width);
  std::string buffer(width * n, '\0');
  if (n > 0 && read(m.id, buffer.data()) < 0) return false;
  for (std::size_t i = 0; i < n; ++i) {
    std::string s = buffer.substr(i * width, width);
    s.resize(std::strlen(s.c_str()));
    c.strings.push_back(s);
  }
  return true;
}

bool read_dataset(hid_t file, const std::string& path, Content& c) {
  Id d(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) return false;
  Id t(H5Dget_type(d.id), H5Tclose);
  Id s(H5Dget_space(d.id), H5Sclose);
  return read_content(t.id, s.id, c, [&](hid_t m, void* b) { return H5Dread(d.id, m, H5S_ALL, H5S_ALL, H5P_DEFAULT, b); });
}

bool read_attribute(hid_t file, const std::string& obj, const std::string& name, Content& c) {
  Id a(H5Aopen_by_name(file, obj.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (a.id < 0) return false;
  Id t(H5Aget_type(a.id), H5Tclose);
  Id s(H5Aget_space(a.id), H5Sclose);
  return read_content(t.id, s.id, c, [&](hid_t m, void* b) { return H5Aread(a.id, m, b); });
}

/// The file and memory types for content of kind `kind`: 0 double, 1 int64, 2 int32, 3 float32,
/// 4 uint8, 5 fixed string, 6 variable-length string.
struct Types {
  hid_t file = -1, memory = -1;
  bool owned = false;
};

/// Write `c` as `kind` (see above) through `create(type, space)` -> id and `write(id, mem, buf)`.
template <class Create, class Write>
void write_content(const Content& c, int kind, Create&& create, Write&& write) {
  Id space(c.dims.empty() ? H5Screate(H5S_SCALAR) : H5Screate_simple(static_cast<int>(c.dims.size()), c.dims.data(), nullptr),
           H5Sclose);
  const std::size_t n = count_of(c.dims);
  // Values in the form the kind takes: numbers from strings and strings from numbers.
  std::vector<double> numbers = c.numbers;
  std::vector<std::string> strings = c.strings;
  if (c.numeric) {
    for (double v : c.numbers) {
      std::ostringstream s;
      s << v;
      strings.push_back(s.str());
    }
  } else {
    for (const auto& s : c.strings) numbers.push_back(std::atof(s.c_str()));
  }
  numbers.resize(n, 1.0);
  strings.resize(n, "x");
  if (kind <= 4) {
    const hid_t ftype = kind == 0 ? H5T_IEEE_F64LE : kind == 1 ? H5T_STD_I64LE : kind == 2 ? H5T_STD_I32LE
                        : kind == 3 ? H5T_IEEE_F32LE : H5T_STD_U8LE;
    const hid_t id = create(ftype, space.id);
    if (id < 0) return;
    write(id, H5T_NATIVE_DOUBLE, numbers.data());
    return;
  }
  if (kind == 5) {
    std::size_t width = 1;
    for (const auto& s : strings) width = std::max(width, s.size());
    Id t(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(t.id, width);
    std::string buffer(width * n, '\0');
    for (std::size_t i = 0; i < n; ++i) std::copy(strings[i].begin(), strings[i].end(), buffer.begin() + static_cast<std::ptrdiff_t>(i * width));
    const hid_t id = create(t.id, space.id);
    if (id < 0) return;
    write(id, t.id, buffer.data());
    return;
  }
  Id t(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(t.id, H5T_VARIABLE);
  H5Tset_cset(t.id, H5T_CSET_UTF8);
  std::vector<const char*> p;
  for (const auto& s : strings) p.push_back(s.c_str());
  const hid_t id = create(t.id, space.id);
  if (id < 0) return;
  write(id, t.id, p.data());
}

void rewrite_dataset(hid_t file, const std::string& path, const Content& c, int kind) {
  H5Ldelete(file, path.c_str(), H5P_DEFAULT);
  hid_t made = -1;
  write_content(
      c, kind,
      [&](hid_t type, hid_t space) {
        made = H5Dcreate2(file, path.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        return made;
      },
      [&](hid_t id, hid_t mem, const void* buf) {
        if (count_of(c.dims) > 0) H5Dwrite(id, mem, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf);
      });
  if (made >= 0) H5Dclose(made);
}

void rewrite_attribute(hid_t file, const std::string& obj, const std::string& name, const Content& c, int kind) {
  H5Adelete_by_name(file, obj.c_str(), name.c_str(), H5P_DEFAULT);
  hid_t made = -1;
  write_content(
      c, kind,
      [&](hid_t type, hid_t space) {
        made = H5Acreate_by_name(file, obj.c_str(), name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
        return made;
      },
      [&](hid_t id, hid_t mem, const void* buf) { H5Awrite(id, mem, buf); });
  if (made >= 0) H5Aclose(made);
}

/// The kind write_content takes for content like `c` (its own type, roughly).
int own_kind(const Content& c) { return c.numeric ? (c.integer ? 1 : 0) : 5; }

/// Another shape for `c`, `variant` choosing: a row fewer or more, flattened, a column more or
/// fewer, scalar, empty, a third axis.
void reshape(Content& c, int variant) {
  const std::size_t n = count_of(c.dims);
  auto resize = [&](std::size_t m) {
    if (c.numeric) c.numbers.resize(m, c.numbers.empty() ? 1.0 : c.numbers.back());
    else c.strings.resize(m, c.strings.empty() ? "x" : c.strings.back());
  };
  switch (variant % 8) {
    case 0:
      if (c.dims.empty() || c.dims[0] == 0) break;
      c.dims[0] -= 1;
      break;
    case 1:
      if (c.dims.empty()) c.dims = {1};
      c.dims[0] += 1;
      break;
    case 2: c.dims = {static_cast<hsize_t>(n)}; break;
    case 3:
      if (c.dims.size() < 2) c.dims = {c.dims.empty() ? 1 : c.dims[0], 2};
      else c.dims[1] += 1;
      break;
    case 4:
      if (c.dims.size() >= 2 && c.dims[1] > 0) c.dims[1] -= 1;
      break;
    case 5: c.dims.clear(); break;
    case 6:
      if (c.dims.empty()) c.dims = {0};
      else c.dims[0] = 0;
      break;
    default: c.dims.push_back(1); break;
  }
  resize(count_of(c.dims));
}

const double hostile[] = {0.0, -1.0, 1.0, 2.0, 3.0, std::nan(""), HUGE_VAL, -HUGE_VAL, 1e308, -1e308,
                          2147483647.0, 2147483648.0, -2147483649.0, 4294967297.0, 9.3e18, 1e-300, 0.5, 99.0,
                          1e9, -0.0, 4.0, 1e30};
const char* const hostile_strings[] = {"fem", "wls", "mpm", "", "x", "cairn-checkpoint", "cairn-fem-checkpoint",
                                       "0123456789abcdef", "[simulation]\ndimension = 2\n"};

struct Program {
  const std::string& bytes;
  std::size_t at = 2;
  [[nodiscard]] bool more() const { return at + 8 <= bytes.size(); }
  std::uint8_t byte(std::size_t k) const { return static_cast<std::uint8_t>(bytes[at + k]); }
  std::uint32_t word() const {
    std::uint32_t w = 0;
    for (std::size_t k = 0; k < 4; ++k) w |= static_cast<std::uint32_t>(byte(4 + k)) << (8 * k);
    return w;
  }
};

/// Replace `path` in `file` by the object of the same path in the seed `other` (H5Ocopy between
/// files), when it has one.
void graft(hid_t file, const std::string& path, std::size_t other) {
  const fs::path donor = scratch / "donor.h5";
  spill(donor, seeds[other]);
  Id src(H5Fopen(donor.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (src.id < 0 || H5Lexists(src.id, path.c_str(), H5P_DEFAULT) <= 0) return;
  H5Ldelete(file, path.c_str(), H5P_DEFAULT);
  H5Ocopy(src.id, path.c_str(), file, path.c_str(), H5P_DEFAULT, H5P_DEFAULT);
}

/// Apply a program (see the top of this file) to a copy of its seed at `path`.
void apply_program(const std::string& bytes, const fs::path& path) {
  const std::size_t seed = static_cast<std::uint8_t>(bytes[0]) % seeds.size();
  const int checksum_mode = static_cast<std::uint8_t>(bytes[1]) % 4;  // 0, 1 recompute; 2 stale; 3 delete
  spill(path, seeds[seed]);
  std::vector<std::pair<int, std::uint32_t>> byte_edits;  // after the HDF5 edits: 0 flip, 1 truncate
  for (Program p{bytes}; p.more(); p.at += 8)
    if (p.byte(0) % 12 == 11) byte_edits.emplace_back(p.byte(2) % 4 == 0 ? 1 : 0, p.word() ^ (static_cast<std::uint32_t>(p.byte(3)) << 24));
  // The HDF5 edits run in a child process: writing such files can leave the HDF5 library in a
  // state that crashes later (an edit that fails half-way), which must not be blamed on the
  // reader. A child that fails leaves the file as it got to.
  (void)cairn::run_in_child([&](std::string&) {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    Id file(H5Fopen(path.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    if (file.id < 0) return 0;
    for (Program p{bytes}; p.more(); p.at += 8) {
      Objects objects;
      collect(file.id, "", objects, 0);
      const int op = p.byte(0) % 12;
      const std::uint8_t a = p.byte(1), b = p.byte(2), c = p.byte(3);
      const std::uint32_t w = p.word();
      const bool has_data = !objects.datasets.empty(), has_attr = !objects.attributes.empty();
      const std::string data = has_data ? objects.datasets[a % objects.datasets.size()] : std::string();
      const auto attr = has_attr ? objects.attributes[a % objects.attributes.size()] : std::pair<std::string, std::string>();
      Content content;
      switch (op) {
        case 0:  // delete a dataset
          if (has_data) H5Ldelete(file.id, data.c_str(), H5P_DEFAULT);
          break;
        case 1:  // delete an attribute
          if (has_attr) H5Adelete_by_name(file.id, attr.first.c_str(), attr.second.c_str(), H5P_DEFAULT);
          break;
        case 2:  // a dataset of another shape
          if (has_data && read_dataset(file.id, data, content)) {
            reshape(content, b);
            rewrite_dataset(file.id, data, content, own_kind(content));
          }
          break;
        case 3:  // a dataset of another type
          if (has_data && read_dataset(file.id, data, content)) rewrite_dataset(file.id, data, content, b % 7);
          break;
        case 4:  // an attribute of another type
          if (has_attr && read_attribute(file.id, attr.first, attr.second, content))
            rewrite_attribute(file.id, attr.first, attr.second, content, b % 7);
          break;
        case 5:  // an attribute of another shape
          if (has_attr && read_attribute(file.id, attr.first, attr.second, content)) {
            reshape(content, b);
            rewrite_attribute(file.id, attr.first, attr.second, content, own_kind(content));
          }
          break;
        case 6:  // a hostile number in a dataset
          if (has_data && read_dataset(file.id, data, content) && content.numeric && !content.numbers.empty()) {
            content.numbers[w % content.numbers.size()] = hostile[c % std::size(hostile)];
            rewrite_dataset(file.id, data, content, own_kind(content));
          }
          break;
        case 7:  // a hostile number in an attribute
          if (has_attr && read_attribute(file.id, attr.first, attr.second, content) && content.numeric &&
              !content.numbers.empty()) {
            content.numbers[w % content.numbers.size()] = hostile[c % std::size(hostile)];
            rewrite_attribute(file.id, attr.first, attr.second, content, own_kind(content));
          }
          break;
        case 8:  // a string attribute set to another engine's or format's name
          if (has_attr && read_attribute(file.id, attr.first, attr.second, content) && !content.numeric) {
            content.strings.assign(std::max<std::size_t>(content.strings.size(), 1), hostile_strings[c % std::size(hostile_strings)]);
            rewrite_attribute(file.id, attr.first, attr.second, content, b % 2 ? 6 : 5);
          }
          break;
        case 9:  // a dataset from another seed (another dimension, engine or rank count)
          if (has_data) graft(file.id, data, b % seeds.size());
          break;
        case 10: {  // the stored input of another seed, or a group of another seed
          static const char* const parts[] = {"/config_toml", "/input", "/particles", "/scalars", "/history"};
          graft(file.id, parts[c % std::size(parts)], b % seeds.size());
          break;
        }
        default:  // a byte flipped or the file cut, after the HDF5 edits (above)
          (void)w;
          break;
      }
    }
    if (checksum_mode == 3) {
      H5Adelete(file.id, "checksum");
    } else if (checksum_mode < 2 && H5Aexists(file.id, "checksum") > 0) {
      H5Adelete(file.id, "checksum");
      try {
        cairn::write_content_checksum(file.id);
      } catch (const std::exception&) {
        // an unreadable object: the reader will say so
      }
    }
    return 0;
  }, 60);
  if (byte_edits.empty()) return;
  std::string image = slurp(path);
  for (const auto& [kind, w] : byte_edits) {
    if (image.empty()) break;
    const std::size_t at = (w & 0xffffffu) % image.size();
    if (kind == 1) image.resize(at);
    else image[at] = static_cast<char>(image[at] ^ static_cast<char>(1u << ((w >> 24) % 8)));
  }
  spill(path, image);
}

bool is_hdf5(const std::string& bytes) { return bytes.size() >= 8 && bytes.compare(0, 8, "\x89HDF\r\n\x1a\n") == 0; }

/// -1 (with `what`) when the reading left an HDF5 file or object open: a file left open is closed
/// when the process ends, and HDF5 may crash closing a damaged one then (after the message).
int left_open(std::string& what) {
  const ssize_t open = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
  if (open <= 0) return 0;
  what = "the reading left " + std::to_string(open) + " HDF5 objects open";
  return -1;
}

/// 1: restored and stepped (or its first step failed as a simulation: exit 3); 0: an input
/// error naming the checkpoint; -1 (with `what`): anything else.
int exercise(const std::string& input, std::string& what) {
  const fs::path file = scratch / "fuzz.h5";
  if (is_hdf5(input) || seeds.empty()) spill(file, input);
  else if (input.size() < 2) spill(file, input);
  else apply_program(input, file);
  const std::vector<std::string> overrides = {"simulation.threads=1", "simulation.memory_limit=0.5",
                                              "output.snapshots=false", "output.checkpoints=false",
                                              "output.directory=\"" + (scratch / "out").string() + "\""};
  auto names_file = [&](const std::string& text) {
    if (fuzz::out_of_memory(text)) {
      what = "an allocation the file does not justify: " + text;
      return -1;
    }
    if (text.find(file.string()) != std::string::npos) return 0;
    what = "an input error that does not name the checkpoint file: " + text;
    return -1;
  };
  try {
    cairn::RunOptions options;
    options.quiet = true;
    auto engine = cairn::restore_engine(file, overrides, options);
    try {
      engine->start();
      engine->step();
    } catch (const cairn::RunFailure&) {
      return 1;
    }
  } catch (const cairn::InputError& e) {
    if (const int left = left_open(what); left < 0) return left;
    return names_file(e.what());
  } catch (const cairn::UnknownName& e) {
    return names_file(e.what());
  } catch (const std::invalid_argument& e) {
    return names_file(e.what());
  } catch (const std::exception& e) {
    what = std::string(typeid(e).name()) + ": " + e.what();
    return -1;
  }
  return left_open(what) < 0 ? -1 : 1;
}

#ifndef CAIRN_CHECKPOINT_SEEDS
#define CAIRN_CHECKPOINT_SEEDS ""
#endif

}  // namespace

#ifdef CAIRN_LIBFUZZER

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  make_scratch();
  const char* folder = std::getenv("CAIRN_CHECKPOINT_SEEDS");
  load_seeds(folder != nullptr ? folder : CAIRN_CHECKPOINT_SEEDS);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string what;
  if (exercise(std::string(reinterpret_cast<const char*>(data), size), what) < 0) {
    std::fprintf(stderr, "fuzz_checkpoint: %s\n", what.c_str());
    std::abort();
  }
  return 0;
}

#else

namespace {

/// A random program: a seed, a checksum mode and 1 to 4 operations.
std::string random_program(std::mt19937_64& rng) {
  std::uniform_int_distribution<int> byte(0, 255);
  std::string p;
  p.push_back(static_cast<char>(byte(rng)));
  p.push_back(static_cast<char>(byte(rng) % 8 < 6 ? 0 : byte(rng)));  // mostly a recomputed checksum
  const int n = 1 + byte(rng) % 4;
  for (int i = 0; i < 8 * n; ++i) p.push_back(static_cast<char>(byte(rng)));
  return p;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  long long max_inputs = -1;
  int keep_going = 0;  // > 0: go on after findings, saving up to this many different ones
  std::uint64_t seed = 1;
  std::string seed_folder = CAIRN_CHECKPOINT_SEEDS;
  std::vector<std::string> folders;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::atof(argv[i + 1]);
    else if (a == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
    else if (a == "--inputs") max_inputs = std::atoll(argv[i + 1]);
    else if (a == "--keep-going") keep_going = std::atoi(argv[i + 1]);
    else if (a == "--seeds") seed_folder = argv[i + 1];
    else if (a == "--corpus") folders.emplace_back(argv[i + 1]);
    else {
      std::fprintf(stderr, "usage: cairn_fuzz_checkpoint [--seconds S] [--inputs N] [--seed N] [--keep-going N] "
                           "--seeds DIR [--corpus DIR]...\n");
      return 2;
    }
  }
  make_scratch();
  load_seeds(seed_folder);
  if (seeds.empty()) {
    std::fprintf(stderr, "fuzz_checkpoint: no .h5 seed in '%s'\n", seed_folder.c_str());
    return 2;
  }
  fuzz::catch_crashes();
  fuzz::limit_memory(std::size_t{8} << 30);
  fuzz::Findings findings;
  std::string what;
  // The seeds restore and step.
  for (std::size_t s = 0; s < seeds.size(); ++s) {
    fuzz::current = seeds[s];
    if (exercise(fuzz::current, what) != 1) {
      findings.report("seed " + seed_names[s], what.empty() ? "an input error" : what);
      return 1;
    }
  }
  // The corpus: whole files and programs (the regression files of earlier findings), every one handled.
  long long replayed = 0;
  for (const auto& folder : folders)
    for (const auto& e : fs::recursive_directory_iterator(folder)) {
      if (!e.is_regular_file()) continue;
      fuzz::current = slurp(e.path());
      if (exercise(fuzz::current, what) < 0) findings.report(e.path().string(), what);
      ++replayed;
    }
  if (findings.count > 0) return 1;
  // Mostly structured programs; one in eight a seed with bytes flipped.
  std::mt19937_64 rng(seed);
  auto next = [&] {
    if (rng() % 8 != 0) return random_program(rng);
    std::string bytes = seeds[rng() % seeds.size()];
    const int flips = 1 + static_cast<int>(rng() % 8);
    for (int k = 0; k < flips; ++k) bytes[rng() % bytes.size()] ^= static_cast<char>(1u << (rng() % 8));
    return bytes;
  };
  const fuzz::Campaign c = fuzz::run_campaign(seconds, max_inputs, keep_going, seed, next, exercise, findings);
  std::printf("fuzz_checkpoint: %zu seeds restored, %lld corpus files replayed, %lld mutated checkpoints in %.1f s "
              "(seed %llu), %lld of them restored, slowest %lld ms: %s\n",
              seeds.size(), replayed, c.inputs, c.seconds, static_cast<unsigned long long>(seed), c.accepted,
              c.slowest_ms,
              c.findings == 0 ? "every one restored or refused naming the file" : "FINDINGS (above)");
  if (c.findings > 0) return 1;
  std::error_code ec;
  fs::remove_all(scratch, ec);
  return 0;
}

#endif
