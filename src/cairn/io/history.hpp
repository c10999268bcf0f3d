// Time history of global quantities (energies, momentum, ...) written as CSV.
//
// The whole table is kept in memory and history.csv is rewritten atomically on every flush(),
// so the file on disk is always complete. A checkpoint saves rows() and a restarted run puts
// them back with set_rows(), which makes a restarted run's history.csv identical to that of an
// uninterrupted run.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace cairn {

/// Collects rows of (time, step, dt, user columns...) and writes them to a CSV file.
class HistoryWriter {
 public:
  /// `path` is the CSV file to write (e.g. out/case/history.csv). `columns` are the caller's
  /// columns; "time", "step" and "dt" are always prepended (if `columns` already starts with
  /// exactly those three names, as columns() returns them, they are not repeated).
  /// Throws std::invalid_argument if a column name is empty or contains ',' or a newline.
  HistoryWriter(std::filesystem::path path, std::vector<std::string> columns);

  /// All column names, starting with time, step, dt.
  [[nodiscard]] const std::vector<std::string>& columns() const { return columns_; }

  /// The CSV file this writer produces.
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  /// Append one full row: values for every column of columns(), time, step and dt first (step
  /// must be an integer value). Throws std::invalid_argument if the length does not match.
  void add_row(std::vector<double> values);

  /// Append one row from its parts: `values` are the caller's columns (after time, step, dt).
  void add_row(double time, long long step, double dt, const std::vector<double>& values);

  /// Rewrite the CSV file atomically: a header line with the column names, then one line per
  /// row. Values are printed with "{:.17g}" (round-trip exact); the step column as an integer.
  /// Rows are formatted once, when added, but each flush writes the whole file, so call it at
  /// output times rather than after every row.
  void flush() const;

  /// The rows added so far (each row has columns().size() values).
  [[nodiscard]] const std::vector<std::vector<double>>& rows() const { return rows_; }

  /// Replace all rows (restart from a checkpoint). Throws std::invalid_argument if a row's
  /// length differs from columns().size().
  void set_rows(std::vector<std::vector<double>> rows);

  /// The CSV text that flush() writes.
  [[nodiscard]] std::string csv_text() const;

 private:
  std::filesystem::path path_;
  std::vector<std::string> columns_;
  std::vector<std::vector<double>> rows_;
  std::string header_;  ///< formatted header line
  std::string body_;    ///< formatted rows, kept in step with rows_
};

}  // namespace cairn
