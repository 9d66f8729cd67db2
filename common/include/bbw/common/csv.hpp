// Numeric CSV reading and writing with strict, counted rejection of bad lines.
#pragma once

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <vector>

namespace bbw::csv {

class CsvError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ReadOptions {
  // Columns that must exist (by header name) and be finite on a usable line.
  std::vector<std::string> required;
  // Columns read when present; a non-finite value in one rejects the line too.
  std::vector<std::string> optional;
  // Files larger than this are refused before reading (bytes).
  std::uint64_t max_bytes = 2ull << 30;
  // Lines longer than this are rejected (characters).
  std::size_t max_line_chars = 1 << 16;
};

// Columns in the order required + optional-present; rows of finite values only.
struct Table {
  std::string file;
  std::vector<std::string> columns;          // names actually loaded
  std::vector<std::vector<double>> values;   // values[c][row]
  std::size_t lines_read = 0;                // data lines seen (header excluded)
  std::size_t lines_rejected = 0;
  std::vector<std::size_t> first_rejected_lines;  // 1-based file line numbers, at most 5
  std::vector<std::string> first_rejected_reasons;

  bool has(const std::string& name) const;
  const std::vector<double>& column(const std::string& name) const;  // throws CsvError
  std::size_t rows() const { return values.empty() ? 0 : values.front().size(); }
  std::string rejection_summary() const;  // "rejected 3 of 1000 lines (first: 12 (NaN in 'x'), ...)"
};

// Reads a comma-separated file with one header row. Throws CsvError when the file cannot be
// read, a required column is missing, the file is too large, or no usable line remains.
Table read(const std::string& file, const ReadOptions& options);
Table read_stream(std::istream& in, const std::string& name, const ReadOptions& options);

// Writes a header and rows with a fixed precision; used by simulate, calibrate, analyze.
class Writer {
 public:
  Writer(const std::string& file, const std::vector<std::string>& columns);
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;
  void row(const double* values, std::size_t n);
  void row(const std::vector<double>& values) { row(values.data(), values.size()); }
  void close();

 private:
  struct Impl;
  Impl* impl_;
  std::size_t n_columns_;
};

}  // namespace bbw::csv
