// The one exception type for mistakes in an input file or a `--set` override.
//
// Every input error names where it happened (file and line, or the `--set` text), which key,
// what was expected and what was found, so that the user can fix it without reading the source:
//
//   two_blocks.toml:12: key 'method.shape': expected one of linear, ugimp, bspline2; found "cpdii"
//
// The CLI catches it, prints what() and exits with status 2.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace cairn {

/// An invalid input: a TOML syntax error, an unknown or misspelled key, a value of the wrong type
/// or out of range, or an inconsistent combination of keys. `line` is 1-based; 0 when unknown
/// (a missing section, a `--set` override: then `file` holds "--set <text>"). `key` is the
/// dotted key ("method.shape", "material[0].density"), empty for errors not tied to one key.
/// `found` may be empty for cross-key errors whose `expected` text says it all.
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, int line, std::string key, std::string expected, std::string found)
      : std::runtime_error(format(file, line, key, expected, found)),
        file_(std::move(file)),
        line_(line),
        key_(std::move(key)),
        expected_(std::move(expected)),
        found_(std::move(found)) {}

  /// The input file name as given, or "--set <text>" for an override.
  [[nodiscard]] const std::string& file() const { return file_; }
  /// 1-based line in file(); 0 when not known.
  [[nodiscard]] int line() const { return line_; }
  /// Dotted key the error is about; empty when it concerns no single key.
  [[nodiscard]] const std::string& key() const { return key_; }
  /// What a valid input would have had here.
  [[nodiscard]] const std::string& expected() const { return expected_; }
  /// What the input had instead; empty when `expected` says it all.
  [[nodiscard]] const std::string& found() const { return found_; }
  /// "file:line", or just "file" when the line is unknown.
  [[nodiscard]] std::string location() const {
    return line_ > 0 ? file_ + ":" + std::to_string(line_) : file_;
  }

 private:
  static std::string format(const std::string& file, int line, const std::string& key,
                            const std::string& expected, const std::string& found) {
    std::string msg = line > 0 ? file + ":" + std::to_string(line) : file;
    msg += ": ";
    if (!key.empty()) msg += "key '" + key + "': ";
    msg += "expected " + expected;
    if (!found.empty()) msg += "; found " + found;
    return msg;
  }

  std::string file_;
  int line_;
  std::string key_;
  std::string expected_;
  std::string found_;
};

/// Several independent mistakes of one input, found in one reading (io/input.cpp: a key that is
/// declared nowhere in its table, or one whose bad value can give way to its default, does not
/// stop the reading; the first error that leaves the rest unreadable does). The InputError base
/// is the first of them, so a handler of InputError sees what it always saw; errors() has them
/// all in the order of the file and what() lists them one per line.
class InputErrors : public InputError {
 public:
  /// At most this many are collected; `truncated` says the reading stopped there.
  static constexpr std::size_t max_reported = 20;

  InputErrors(std::vector<InputError> errors, bool truncated)
      : InputError(errors.front()), errors_(std::move(errors)), truncated_(truncated) {
    for (const auto& e : errors_) text_ += (text_.empty() ? "" : "\n") + std::string(e.what());
  }

  [[nodiscard]] const std::vector<InputError>& errors() const { return errors_; }
  /// True when reading stopped at max_reported errors (there may be more).
  [[nodiscard]] bool truncated() const { return truncated_; }
  [[nodiscard]] const char* what() const noexcept override { return text_.c_str(); }

 private:
  std::vector<InputError> errors_;
  bool truncated_;
  std::string text_;
};

}  // namespace cairn
