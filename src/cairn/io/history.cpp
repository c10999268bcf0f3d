#include "cairn/io/history.hpp"

#include <fmt/format.h>

#include <stdexcept>
#include <utility>

#include "cairn/io/atomic_file.hpp"

namespace cairn {

namespace {

/// Append one CSV line for `row` (step column printed as an integer).
void format_row(std::string& out, const std::vector<double>& row) {
  fmt::memory_buffer line;
  for (std::size_t c = 0; c < row.size(); ++c) {
    if (c > 0) line.push_back(',');
    if (c == 1) {
      fmt::format_to(std::back_inserter(line), "{}", static_cast<long long>(row[c]));
    } else {
      fmt::format_to(std::back_inserter(line), "{:.17g}", row[c]);
    }
  }
  line.push_back('\n');
  out.append(line.data(), line.size());
}

}  // namespace

HistoryWriter::HistoryWriter(std::filesystem::path path, std::vector<std::string> columns)
    : path_(std::move(path)) {
  columns_ = {"time", "step", "dt"};
  std::size_t first = 0;
  if (columns.size() >= 3 && columns[0] == "time" && columns[1] == "step" && columns[2] == "dt") {
    first = 3;
  }
  for (std::size_t i = first; i < columns.size(); ++i) {
    const std::string& name = columns[i];
    if (name.empty() || name.find_first_of(",\n\r") != std::string::npos) {
      throw std::invalid_argument("history column name '" + name +
                                  "' must be non-empty and contain no ',' or newline");
    }
    columns_.push_back(name);
  }
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    if (c > 0) header_ += ',';
    header_ += columns_[c];
  }
  header_ += '\n';
}

void HistoryWriter::add_row(std::vector<double> values) {
  if (values.size() != columns_.size()) {
    throw std::invalid_argument(fmt::format("history row has {} values but {} has {} columns",
                                            values.size(), path_.string(), columns_.size()));
  }
  format_row(body_, values);
  rows_.push_back(std::move(values));
}

void HistoryWriter::add_row(double time, long long step, double dt,
                            const std::vector<double>& values) {
  std::vector<double> row;
  row.reserve(3 + values.size());
  row.push_back(time);
  row.push_back(static_cast<double>(step));
  row.push_back(dt);
  row.insert(row.end(), values.begin(), values.end());
  add_row(std::move(row));
}

void HistoryWriter::set_rows(std::vector<std::vector<double>> rows) {
  for (const auto& row : rows) {
    if (row.size() != columns_.size()) {
      throw std::invalid_argument(
          fmt::format("restored history row has {} values but {} has {} columns", row.size(),
                      path_.string(), columns_.size()));
    }
  }
  rows_ = std::move(rows);
  body_.clear();
  for (const auto& row : rows_) format_row(body_, row);
}

std::string HistoryWriter::csv_text() const { return header_ + body_; }

void HistoryWriter::flush() const { write_text_atomically(path_, csv_text()); }

}  // namespace cairn
