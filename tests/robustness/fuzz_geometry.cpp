// Fuzz target for the geometry readers: Gmsh meshes (.msh, ASCII and binary; geometry/volume_mesh),
// surface meshes (STL ASCII and binary, OBJ, OFF, PLY; geometry/surface_mesh, read by CGAL), CSV
// point files (2D, 3D) and HDF5 point files (3D; geometry/point_set), 2D CSV outlines
// (geometry/outline). Every outcome must be a shape or an input error naming the file
// (std::invalid_argument or InputError: exit 2 in the CLI); any other exception (exit 1), a crash,
// an AddressSanitizer report or a hang is a finding (docs/robustness.md, "Files from outside").
//
// An input is a format tag line ("msh2", "msh3", "stl", "obj", "off", "ply", "points2", "points3",
// "outline", "points3h5") and the file's bytes; without a known tag its first byte chooses the format and the
// rest is the file. The seeds are files from tests/ and examples/ in this form
// (tests/robustness/corpus/geometry, written by make_seeds.py there).
//
// Two builds of this file, as fuzz_input.cpp:
//  - default: a standalone driver that replays every file of the --corpus folders (the seeds and
//    the regression files of earlier findings), then mutates the seeds (bytes, 32-bit words,
//    numbers, lines, spans) for --seconds with a fixed --seed; ctest runs it as
//    robustness.fuzz_geometry. On a finding it prints the input's path and exits 1.
//  - CAIRN_LIBFUZZER (preset "fuzz"): LLVMFuzzerTestOneInput, e.g.
//    build/fuzz/tests/robustness/cairn_fuzz_geometry -max_total_time=600 tests/robustness/corpus/geometry
#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <typeinfo>
#include <vector>

#include <hdf5.h>

#include "cairn/config/errors.hpp"
#include "cairn/geometry/outline.hpp"
#include "cairn/geometry/point_set.hpp"
#include "cairn/geometry/surface_mesh.hpp"
#include "cairn/geometry/volume_mesh.hpp"
#include "fuzz_support.hpp"

namespace {

namespace fs = std::filesystem;

struct Format {
  const char* tag;
  const char* extension;
};
const std::array<Format, 10> formats{{{"msh2", ".msh"},
                                     {"msh3", ".msh"},
                                     {"stl", ".stl"},
                                     {"obj", ".obj"},
                                     {"off", ".off"},
                                     {"ply", ".ply"},
                                     {"points2", ".csv"},
                                     {"points3", ".csv"},
                                     {"outline", ".csv"},
                                     {"points3h5", ".h5"}}};

using fuzz::scratch;
using fuzz::slurp;
using fuzz::spill;

/// The format and the file's bytes of an input.
std::pair<std::size_t, std::string> split(const std::string& input) {
  const std::size_t eol = input.find('\n');
  if (eol != std::string::npos && eol < 16) {
    const std::string tag = input.substr(0, eol);
    for (std::size_t f = 0; f < formats.size(); ++f)
      if (tag == formats[f].tag) return {f, input.substr(eol + 1)};
  }
  if (input.empty()) return {0, std::string()};
  return {static_cast<std::uint8_t>(input[0]) % formats.size(), input.substr(1)};
}

/// -1 (with `what`) when a reading left an HDF5 file or object open (HDF5 point files): its
/// memory stays taken to the end of the process.
int left_open(std::string& what) {
  const ssize_t open = H5Fget_obj_count(H5F_OBJ_ALL, H5F_OBJ_ALL);
  if (open <= 0) return 0;
  what = "the reading left " + std::to_string(open) + " HDF5 objects open";
  return -1;
}

int read_one(const std::string& input, std::string& what);

/// 1: read; 0: an input error naming the file; -1 (with `what`): anything else.
int exercise(const std::string& input, std::string& what) {
  const int outcome = read_one(input, what);
  return outcome < 0 ? outcome : left_open(what) < 0 ? -1 : outcome;
}

int read_one(const std::string& input, std::string& what) {
  const auto [f, bytes] = split(input);
  const fs::path file = scratch / (std::string("fuzz") + formats[f].extension);
  spill(file, bytes);
  const std::string path = file.string();
  auto names_file = [&](const std::string& text) {
    if (fuzz::out_of_memory(text)) {
      what = "an allocation the file does not justify: " + text;
      return -1;
    }
    if (text.find(path) != std::string::npos) return 0;
    what = "an input error that does not name the file: " + text;
    return -1;
  };
  try {
    switch (f) {
      case 0: case 1: {
        const auto set = cairn::geometry::read_volume_mesh(path, f == 0 ? 2 : 3, f == 0 ? 3 : 4, {});
        (void)set->n();
        break;
      }
      case 2: case 3: case 4: case 5: {
        const auto mesh = cairn::geometry::read_surface_mesh(path, {});
        cairn::geometry::LineCache cache;
        const auto& lo = mesh->lo();
        const auto& hi = mesh->hi();
        (void)mesh->inside(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]), cache);
        break;
      }
      case 6: case 7: case 9:
        (void)cairn::geometry::read_point_file(path, f == 6 ? 2 : 3)->n();
        break;
      default: {
        const auto loops = cairn::geometry::read_outline_csv(path, 1.0, {0.0, 0.0});
        (void)cairn::geometry::loops_area(loops);
        break;
      }
    }
  } catch (const cairn::InputError& e) {
    return names_file(e.what());
  } catch (const std::invalid_argument& e) {
    return names_file(e.what());
  } catch (const std::exception& e) {
    what = std::string(typeid(e).name()) + ": " + e.what();
    return -1;
  }
  return 1;
}

}  // namespace

#ifdef CAIRN_LIBFUZZER

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  fuzz::make_scratch("fuzz_geometry");
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string what;
  if (exercise(std::string(reinterpret_cast<const char*>(data), size), what) < 0) {
    std::fprintf(stderr, "fuzz_geometry: %s\n", what.c_str());
    std::abort();
  }
  return 0;
}

#else

namespace {

const char* const numbers[] = {"0", "-1", "1", "2", "3", "4", "-0", "1e308", "-1e308", "1e-320", "nan", "inf",
                               "4294967295", "4294967296", "2147483647", "2147483648", "9223372036854775807",
                               "18446744073709551615", "100000000", "0.5", "1e400", "0x10", "+", "-", "."};
const std::uint32_t words[] = {0u, 1u, 2u, 3u, 0xffffffffu, 0x7fffffffu, 0x80000000u, 1000000u, 0x10000u, 100u};

class Mutator {
 public:
  Mutator(std::uint64_t seed, const std::vector<std::string>& corpus) : rng_(seed), corpus_(corpus) {}

  std::string next() {
    const std::string& input = corpus_[below(corpus_.size())];
    const std::size_t eol = input.find('\n');
    const std::string tag = input.substr(0, eol + 1);
    std::string body = input.substr(eol + 1);
    const int n = 1 + static_cast<int>(below(4));
    for (int i = 0; i < n; ++i) mutate(body, tag);
    return tag + body;
  }

 private:
  std::size_t below(std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }

  /// Spans of digits, signs, dots and exponents: the numbers of a text file.
  static std::vector<std::pair<std::size_t, std::size_t>> number_spans(const std::string& s) {
    std::vector<std::pair<std::size_t, std::size_t>> out;
    for (std::size_t i = 0; i < s.size();) {
      if (std::isdigit(static_cast<unsigned char>(s[i]))) {
        std::size_t j = i;
        while (j < s.size() && (std::isdigit(static_cast<unsigned char>(s[j])) || std::strchr(".eE+-", s[j]))) ++j;
        out.emplace_back(i, j);
        i = j;
      } else {
        ++i;
      }
    }
    return out;
  }

  static std::vector<std::string> lines(const std::string& s) {
    std::vector<std::string> out;
    std::stringstream in(s);
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
  }

  void mutate(std::string& s, const std::string& tag) {
    switch (below(10)) {
      case 0:  // flip a bit
        if (!s.empty()) s[below(s.size())] ^= static_cast<char>(1u << below(8));
        break;
      case 1: {  // a 32-bit little-endian word: counts of binary STL, PLY, .msh
        if (s.size() < 4) break;
        const std::size_t at = below(s.size() - 3);
        const std::uint32_t w = words[below(std::size(words))];
        for (int k = 0; k < 4; ++k) s[at + static_cast<std::size_t>(k)] = static_cast<char>((w >> (8 * k)) & 0xffu);
        break;
      }
      case 2: case 3: {  // a number of a text file
        const auto spans = number_spans(s);
        if (spans.empty()) break;
        const auto [b, e] = spans[below(spans.size())];
        s.replace(b, e - b, numbers[below(std::size(numbers))]);
        break;
      }
      case 4:  // cut the file
        if (!s.empty()) s.resize(below(s.size()));
        break;
      case 5: {  // delete a span
        if (s.empty()) break;
        const std::size_t at = below(s.size());
        s.erase(at, 1 + below(32));
        break;
      }
      case 6: {  // duplicate a span
        if (s.empty()) break;
        const std::size_t at = below(s.size()), len = 1 + below(64);
        s.insert(below(s.size()), s.substr(at, len));
        break;
      }
      case 7: case 8: {  // delete, duplicate or swap lines; a line from another seed of the format
        auto ls = lines(s);
        if (ls.empty()) break;
        const std::size_t i = below(ls.size()), j = below(ls.size());
        switch (below(4)) {
          case 0: ls.erase(ls.begin() + static_cast<std::ptrdiff_t>(i)); break;
          case 1: ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(i), ls[j]); break;
          case 2: std::swap(ls[i], ls[j]); break;
          default: {
            const std::string& other = corpus_[below(corpus_.size())];
            if (other.compare(0, tag.size(), tag) != 0) break;
            const auto ol = lines(other.substr(tag.size()));
            if (!ol.empty()) ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(i), ol[below(ol.size())]);
          }
        }
        s.clear();
        for (const auto& l : ls) s += l + "\n";
        break;
      }
      default:  // a byte: random or punctuation
        if (!s.empty()) {
          const char special[] = ",\n \t#-.0123456789e$";
          s[below(s.size())] = below(2) ? special[below(sizeof special - 1)] : static_cast<char>(below(256));
        }
        break;
    }
  }

  std::mt19937_64 rng_;
  const std::vector<std::string>& corpus_;
};

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10.0;
  long long max_inputs = -1;
  int keep_going = 0;  // > 0: go on after findings, saving up to this many different ones
  std::uint64_t seed = 1;
  std::vector<std::string> folders;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::atof(argv[i + 1]);
    else if (a == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
    else if (a == "--inputs") max_inputs = std::atoll(argv[i + 1]);
    else if (a == "--keep-going") keep_going = std::atoi(argv[i + 1]);
    else if (a == "--corpus") folders.emplace_back(argv[i + 1]);
    else {
      std::fprintf(stderr,
                   "usage: cairn_fuzz_geometry [--seconds S] [--inputs N] [--seed N] [--keep-going N] --corpus DIR...\n");
      return 2;
    }
  }
  fuzz::make_scratch("fuzz_geometry");
  fuzz::catch_crashes();
  fuzz::limit_memory(std::size_t{8} << 30);
  fuzz::Findings findings;
  std::vector<std::string> seeds;
  std::string what;
  long long replayed = 0;
  // Seeds (seed-*) must read; every file (the regression files too) must be handled.
  for (const auto& folder : folders)
    for (const auto& e : fs::recursive_directory_iterator(folder)) {
      if (!e.is_regular_file() || e.path().extension() == ".py" || e.path().extension() == ".md") continue;
      fuzz::current = slurp(e.path());
      const int outcome = exercise(fuzz::current, what);
      ++replayed;
      if (outcome < 0) {
        findings.report(e.path().string(), what);
      } else if (e.path().filename().string().rfind("seed-", 0) == 0) {
        if (outcome != 1) findings.report(e.path().string(), "an input error for a seed (seeds must read)");
        seeds.push_back(fuzz::current);
      }
    }
  if (findings.count > 0) return 1;
  if (seeds.empty()) {
    std::fprintf(stderr, "fuzz_geometry: no seed-* file in the --corpus folders\n");
    return 2;
  }
  std::sort(seeds.begin(), seeds.end());
  Mutator mutator(seed, seeds);
  const fuzz::Campaign c =
      fuzz::run_campaign(seconds, max_inputs, keep_going, seed, [&] { return mutator.next(); }, exercise, findings);
  std::printf("fuzz_geometry: %lld corpus files replayed, %lld mutated files from %zu seeds in %.1f s (seed %llu), "
              "%lld of them read, slowest %lld ms: %s\n",
              replayed, c.inputs, seeds.size(), c.seconds, static_cast<unsigned long long>(seed), c.accepted,
              c.slowest_ms, c.findings == 0 ? "every one read or refused naming the file" : "FINDINGS (above)");
  if (c.findings > 0) return 1;
  std::error_code ec;
  fs::remove_all(scratch, ec);
  return 0;
}

#endif
