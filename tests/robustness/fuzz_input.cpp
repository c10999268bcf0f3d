// Fuzz target for the input layer: TOML text -> load_config_string -> Simulation set-up (grid,
// materials, particles, conditions, first time step). Every outcome must be a Config or an input
// error (InputError, UnknownName, std::invalid_argument: exit 2 in the CLI); any other exception,
// a crash or a hang is a finding.
//
// Two builds of this file:
//  - default: a standalone driver with its own mutator over seed inputs (--corpus folders of
//    .toml files), deterministic for a --seed, running for --seconds; ctest runs it for 20 s as
//    robustness.fuzz_input. On a finding it prints the input and exits 1; a crash prints the
//    input from the signal handler.
//  - CAIRN_LIBFUZZER (preset "fuzz", clang -fsanitize=fuzzer,address): LLVMFuzzerTestOneInput for
//    libFuzzer, e.g. build/fuzz/tests/robustness/cairn_fuzz_input -max_total_time=600 corpus/
//    (docs/robustness.md).
//
// The set-up runs with simulation.memory_limit = 1/2 GiB (the largest seed, examples/taylor_bar.toml,
// is estimated at 0.34 GiB) and one thread so that valid but large
// inputs are refused quickly instead of allocating the machine's memory.
#include <algorithm>
#include <cctype>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <typeinfo>
#include <unistd.h>
#include <vector>

#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/input/schema.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/util/registry.hpp"

namespace {

const std::vector<std::string> limits = {"simulation.memory_limit = 0.5", "simulation.threads = 1",
                                         "simulation.max_estimated_steps = 1e8"};

template <int D>
void set_up(const cairn::Config& config) {
  cairn::Simulation<D> sim(config);
  (void)sim.next_dt();
}

/// The name an input is read under: files it names (meshes, pictures, point files) resolve
/// against its folder, the first --corpus folder in the standalone driver (so that the examples'
/// meshes/ are found).
std::string input_name = "fuzz.toml";

/// Run one input through the input layer: 1 when it set up a simulation, 0 for an input error,
/// -1 (with `what`) when something else came out.
int exercise(const std::string& text, std::string& what) {
  try {
    const cairn::Config config = cairn::load_config_string(text, input_name, limits);
    switch (config.simulation.dimension) {
      case 1: set_up<1>(config); break;
      case 2: set_up<2>(config); break;
      default: set_up<3>(config); break;
    }
  } catch (const cairn::InputError&) {
    return 0;
  } catch (const cairn::UnknownName&) {
    return 0;
  } catch (const std::invalid_argument&) {
    return 0;
  } catch (const std::exception& e) {
    what = std::string(typeid(e).name()) + ": " + e.what();
    return -1;
  }
  return 1;
}

}  // namespace

#ifdef CAIRN_LIBFUZZER

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string what;
  if (exercise(std::string(reinterpret_cast<const char*>(data), size), what) < 0) {
    std::fprintf(stderr, "fuzz_input: %s\n", what.c_str());
    std::abort();
  }
  return 0;
}

#else

namespace {

// ---- the mutator ----------------------------------------------------------------------------

const std::vector<std::string> numbers = {
    "0", "-1", "1", "2", "3", "16", "17", "1024", "1025", "100000", "0.0", "-0.0", "0.5", "1e-9",
    "1e-300", "1e308", "-1e308", "1.7976931348623157e308", "4294967297", "2147483648", "1e10",
    "9223372036854775807", "-9223372036854775808", "nan", "inf", "-inf", "1e6", "5e-324"};
const std::vector<std::string> strings = {
    "\"\"", "\"-9,81\"", "\"t=1e9\"", "\"x\"", "\"t\"", "\"2*t\"", "\"1/0\"", "\"sin(\"", "\"box\"",
    "\"cpdi\"", "\"linear\"", "\"warn\"", "\"material\"", "\"body\"", "\"x_min\"", "\"periodic\"",
    "\"neo_hookean\"", "\"\\u00e9\"", "\"X*Y*Z\"", "\"tri(t, 1)\"", "\"ramp(t)\"", "\"pi\"", "\"_e\""};
const std::vector<std::string> others = {"[]", "[1.0]", "[0.0, 0.0]", "[0.0, 0.0, 0.0]", "[[1, 2], [3]]",
                                         "{}", "{ box = {} }", "true", "false", "\"a\"", "[\"1\", 2]",
                                         "{ circle = { center = [0.5, 0.5], radius = 1e9 } }",
                                         "{ polygon = { vertices = [[0, 0], [1, 0], [1e-300, 1e-300]] } }"};
const std::vector<std::string> tables = {"[simulation]", "[grid]", "[method]", "[constants]", "[[material]]",
                                         "[[body]]", "[boundary]", "[body_force]", "[thermal]", "[[traction]]",
                                         "[[velocity]]", "[[wall]]", "[contact]", "[[contact_pair]]", "[output]",
                                         "[simulation.grid]", "[[body]]\nshape = 1"};

class Mutator {
 public:
  Mutator(std::uint64_t seed, std::vector<std::string> corpus) : rng_(seed), corpus_(std::move(corpus)) {
    for (const auto& k : cairn::declared_keys()) keys_.push_back(k.name);
  }

  std::string next() {
    std::string text = pick(corpus_);
    const int n = 1 + static_cast<int>(below(4));
    for (int i = 0; i < n; ++i) mutate(text);
    return text;
  }

 private:
  std::size_t below(std::size_t n) { return n == 0 ? 0 : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng_); }
  const std::string& pick(const std::vector<std::string>& v) { return v[below(v.size())]; }

  static std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::stringstream in(text);
    for (std::string l; std::getline(in, l);) out.push_back(l);
    return out;
  }
  static std::string join(const std::vector<std::string>& ls) {
    std::string out;
    for (const auto& l : ls) out += l + "\n";
    return out;
  }

  /// The value part of a random "key = value" line, or npos.
  std::pair<std::size_t, std::size_t> value_span(const std::string& text) {
    std::vector<std::pair<std::size_t, std::size_t>> spans;
    std::size_t start = 0;
    while (start < text.size()) {
      std::size_t end = text.find('\n', start);
      if (end == std::string::npos) end = text.size();
      const std::size_t eq = text.find('=', start);
      if (eq != std::string::npos && eq < end) spans.emplace_back(eq + 1, end);
      start = end + 1;
    }
    if (spans.empty()) return {std::string::npos, 0};
    return spans[below(spans.size())];
  }

  void mutate(std::string& text) {
    switch (below(10)) {
      case 0: {  // a byte: random or TOML punctuation
        if (text.empty()) break;
        const char special[] = ",=[]{}\"\n#.-e0123456789 xtXT";
        text[below(text.size())] = below(2) ? special[below(sizeof special - 1)] : static_cast<char>(below(256));
        break;
      }
      case 1: {  // delete a span
        if (text.empty()) break;
        const std::size_t at = below(text.size());
        text.erase(at, 1 + below(24));
        break;
      }
      case 2: case 3: {  // a value -> an interesting number, string or other value
        const auto [b, e] = value_span(text);
        if (b == std::string::npos) break;
        const auto& kind = below(3) == 0 ? strings : below(2) ? numbers : others;
        text.replace(b, e - b, " " + pick(kind));
        break;
      }
      case 4: {  // duplicate, delete or swap lines
        auto ls = lines(text);
        if (ls.empty()) break;
        const std::size_t i = below(ls.size()), j = below(ls.size());
        const int op = static_cast<int>(below(3));
        if (op == 0) ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(i), ls[j]);
        else if (op == 1) ls.erase(ls.begin() + static_cast<std::ptrdiff_t>(i));
        else std::swap(ls[i], ls[j]);
        text = join(ls);
        break;
      }
      case 5: {  // a line from another seed
        auto ls = lines(text);
        const auto other = lines(pick(corpus_));
        if (other.empty()) break;
        ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(below(ls.size() + 1)), pick(other));
        text = join(ls);
        break;
      }
      case 6: case 7: {  // a declared key with an interesting value, somewhere
        auto ls = lines(text);
        const auto& kind = below(3) == 0 ? strings : below(2) ? numbers : others;
        ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(below(ls.size() + 1)), pick(keys_) + " = " + pick(kind));
        text = join(ls);
        break;
      }
      case 8: {  // a table header
        auto ls = lines(text);
        ls.insert(ls.begin() + static_cast<std::ptrdiff_t>(below(ls.size() + 1)), pick(tables));
        text = join(ls);
        break;
      }
      default: {  // scale a number by a power of ten
        const auto [b, e] = value_span(text);
        if (b == std::string::npos) break;
        const std::string value = text.substr(b, e - b);
        if (value.find_first_of("0123456789") == std::string::npos) break;
        static const char* const exponents[] = {"e3", "e6", "e9", "e-9", "e30", "e300", "e-300"};
        std::string v = value;
        while (!v.empty() && (v.back() == ' ' || v.back() == '\r')) v.pop_back();
        if (!v.empty() && std::isdigit(static_cast<unsigned char>(v.back())) && v.find('e') == std::string::npos)
          text.replace(b, e - b, v + exponents[below(7)]);
        break;
      }
    }
  }

  std::mt19937_64 rng_;
  std::vector<std::string> corpus_;
  std::vector<std::string> keys_;
};

// ---- crash reporting ------------------------------------------------------------------------

std::string current;  // the input being exercised, for the signal handler

extern "C" void on_crash(int sig) {
  const char head[] = "\nfuzz_input: crashed (signal) on this input:\n-----\n";
  ssize_t ignored = ::write(2, head, sizeof head - 1);
  ignored = ::write(2, current.data(), current.size());
  const char tail[] = "\n-----\n";
  ignored = ::write(2, tail, sizeof tail - 1);
  (void)ignored;
  ::_exit(128 + sig);
}

std::vector<std::string> read_corpus(const std::vector<std::string>& folders) {
  std::vector<std::string> out;
  for (const auto& folder : folders)
    for (const auto& e : std::filesystem::directory_iterator(folder)) {
      if (e.path().extension() != ".toml") continue;
      std::ifstream in(e.path(), std::ios::binary);
      std::stringstream s;
      s << in.rdbuf();
      out.push_back(s.str());
    }
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 20.0;
  std::uint64_t seed = 1;
  long long max_inputs = -1;
  std::vector<std::string> folders;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--seconds") seconds = std::atof(argv[i + 1]);
    else if (a == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
    else if (a == "--inputs") max_inputs = std::atoll(argv[i + 1]);
    else if (a == "--corpus") folders.emplace_back(argv[i + 1]);
    else {
      std::fprintf(stderr, "usage: cairn_fuzz_input [--seconds S] [--seed N] [--inputs N] --corpus DIR...\n");
      return 2;
    }
  }
  const std::vector<std::string> corpus = read_corpus(folders);
  if (!folders.empty()) input_name = folders.front() + "/fuzz.toml";
  if (corpus.empty()) {
    std::fprintf(stderr, "fuzz_input: no .toml seed in the --corpus folders\n");
    return 2;
  }
  for (int sig : {SIGSEGV, SIGABRT, SIGFPE, SIGBUS, SIGILL}) std::signal(sig, on_crash);
  // The seeds themselves must load and set up.
  std::string what;
  for (const auto& text : corpus) {
    current = text;
    if (exercise(text, what) != 1) {
      std::fprintf(stderr, "fuzz_input: a seed fails: %s\n-----\n%s\n-----\n", what.c_str(), text.c_str());
      return 1;
    }
  }
  Mutator mutator(seed, corpus);
  const auto start = std::chrono::steady_clock::now();
  long long n = 0, slowest_ms = 0, set_up_count = 0;
  for (; max_inputs < 0 || n < max_inputs; ++n) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (elapsed > seconds) break;
    current = mutator.next();
    const auto t0 = std::chrono::steady_clock::now();
    const int outcome = exercise(current, what);
    set_up_count += outcome == 1;
    if (outcome < 0) {
      std::fprintf(stderr, "fuzz_input: input %lld (seed %llu) gives %s\n-----\n%s\n-----\n", n,
                   static_cast<unsigned long long>(seed), what.c_str(), current.c_str());
      return 1;
    }
    const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(std::chrono::steady_clock::now() - t0).count();
    if (ms > 10000) {
      std::fprintf(stderr, "fuzz_input: input %lld took %lld ms (a hang?)\n-----\n%s\n-----\n", n,
                   static_cast<long long>(ms), current.c_str());
      return 1;
    }
    slowest_ms = std::max<long long>(slowest_ms, ms);
  }
  std::printf("fuzz_input: %lld mutated inputs from %zu seeds in %.1f s (seed %llu), %lld of them valid and set "
              "up, slowest %lld ms: no crash, no exception other than input errors\n",
              n, corpus.size(), std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
              static_cast<unsigned long long>(seed), set_up_count, slowest_ms);
  return 0;
}

#endif
