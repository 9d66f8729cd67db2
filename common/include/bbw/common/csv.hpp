// Numeric CSV reading and writing with strict, counted rejection of bad lines. The one reader of
// every tool (calibrate, analyze, tests): only a regular file is opened (a directory, FIFO or
// device is refused before reading); a UTF-8 byte-order mark is skipped; fields may be quoted
// ("a,b" and "say ""x""" as in RFC 4180, within one line); a header naming a column twice is
// refused; a time column, when named, must increase strictly (or lines that do not are dropped
// and counted when asked); bytes outside printable ASCII are escaped (\xNN) in messages.
// Errors are one line: "FILE:LINE: reason".
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
  // Lines longer than this are rejected (characters); a longer header line is an error. The
  // reader never holds more than this many characters of one line.
  std::size_t max_line_chars = 1 << 16;
  // A header with more columns than this is refused (tools load a column per name).
  std::size_t max_columns = 1024;
  // When set (a loaded column), its values must increase strictly from one usable line to the
  // next: a line that does not is an error naming its line number, unless allow_unsorted_time,
  // which drops such lines and counts them in Table::lines_unsorted_time.
  std::string time_column;
  bool allow_unsorted_time = false;
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
  std::size_t lines_unsorted_time = 0;       // usable lines dropped: time did not increase
  std::size_t first_unsorted_time_line = 0;  // 1-based, 0 when none

  bool has(const std::string& name) const;
  const std::vector<double>& column(const std::string& name) const;  // throws CsvError
  std::size_t rows() const { return values.empty() ? 0 : values.front().size(); }
  std::string rejection_summary() const;  // "rejected 3 of 1000 lines (first: 12 (NaN in 'x'), ...)"
};

// Reads a comma-separated file with one header row. Throws CsvError when the file cannot be
// read, a required column is missing, the file is too large, or no usable line remains.
Table read(const std::string& file, const ReadOptions& options);
Table read_stream(std::istream& in, const std::string& name, const ReadOptions& options);

// The column names of a file's header (BOM skipped, quotes removed, duplicates refused), with
// the same file-kind and size checks as read(); for tools that choose columns by the header.
std::vector<std::string> read_header(const std::string& file, const ReadOptions& options = {});
std::vector<std::string> read_header_stream(std::istream& in, const std::string& name,
                                            const ReadOptions& options = {});

// `text` with every byte outside printable ASCII written as \xNN, cut to `max_chars`
// (then "..."): safe to print whatever a file held.
std::string printable(const std::string& text, std::size_t max_chars = 64);

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
