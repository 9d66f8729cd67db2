#include "bbw/common/csv.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <sys/stat.h>

namespace bbw::csv {

namespace {

std::string trim(const std::string& s) {
  std::size_t b = 0;
  std::size_t e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t' || s[b] == '"')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r' || s[e - 1] == '"')) --e;
  return s.substr(b, e - b);
}

void split(const std::string& line, std::vector<std::string>& out) {
  out.clear();
  std::size_t start = 0;
  for (;;) {
    const std::size_t pos = line.find(',', start);
    if (pos == std::string::npos) {
      out.push_back(line.substr(start));
      return;
    }
    out.push_back(line.substr(start, pos - start));
    start = pos + 1;
  }
}

// Parses a whole field as a finite double; returns false on any trailing junk or non-finite.
bool parse_field(const std::string& field, double& v, std::string& why) {
  const std::string t = trim(field);
  if (t.empty()) {
    why = "empty";
    return false;
  }
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (*b == '+') ++b;
  const auto res = std::from_chars(b, e, v);
  if (res.ec != std::errc() || res.ptr != e) {
    why = "not a number '" + t.substr(0, 24) + "'";
    return false;
  }
  if (!std::isfinite(v)) {
    why = std::isnan(v) ? "NaN" : "infinite";
    return false;
  }
  return true;
}

}  // namespace

bool Table::has(const std::string& name) const {
  for (const auto& c : columns) {
    if (c == name) return true;
  }
  return false;
}

const std::vector<double>& Table::column(const std::string& name) const {
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return values[i];
  }
  throw CsvError(file + ": no column '" + name + "'");
}

std::string Table::rejection_summary() const {
  std::ostringstream os;
  os << "rejected " << lines_rejected << " of " << lines_read << " data lines";
  if (!first_rejected_lines.empty()) {
    os << " (first: ";
    for (std::size_t i = 0; i < first_rejected_lines.size(); ++i) {
      if (i) os << ", ";
      os << "line " << first_rejected_lines[i] << ": " << first_rejected_reasons[i];
    }
    os << ")";
  }
  return os.str();
}

Table read(const std::string& file, const ReadOptions& options) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) throw CsvError(file + ": cannot open file");
  if (S_ISDIR(st.st_mode)) throw CsvError(file + ": is a directory, not a CSV file");
  // A FIFO or a device would block on open or never end.
  if (!S_ISREG(st.st_mode)) throw CsvError(file + ": is not a regular file");
  if (static_cast<std::uint64_t>(st.st_size) > options.max_bytes) {
    throw CsvError(file + ": file is " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                   std::to_string(options.max_bytes));
  }
  std::ifstream in(file);
  if (!in) throw CsvError(file + ": cannot open file");
  return read_stream(in, file, options);
}

Table read_stream(std::istream& in, const std::string& name, const ReadOptions& options) {
  Table t;
  t.file = name;
  std::string line;
  std::size_t line_no = 0;
  // Header: first non-empty line.
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.size() > options.max_line_chars) throw CsvError(name + ":" + std::to_string(line_no) + ": header line too long");
    if (!trim(line).empty()) break;
  }
  if (line_no == 0 || trim(line).empty()) throw CsvError(name + ": empty file, expected a header row");
  split(line, header);
  for (auto& h : header) h = trim(h);

  std::vector<std::size_t> source;  // header index per loaded column
  auto find = [&](const std::string& c) -> long {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == c) return static_cast<long>(i);
    }
    return -1;
  };
  for (const auto& c : options.required) {
    const long i = find(c);
    if (i < 0) {
      std::string have;
      for (const auto& h : header) have += (have.empty() ? "" : ", ") + h;
      throw CsvError(name + ":" + std::to_string(line_no) + ": required column '" + c +
                     "' is missing (header has: " + have + ")");
    }
    t.columns.push_back(c);
    source.push_back(static_cast<std::size_t>(i));
  }
  for (const auto& c : options.optional) {
    const long i = find(c);
    if (i >= 0 && !t.has(c)) {
      t.columns.push_back(c);
      source.push_back(static_cast<std::size_t>(i));
    }
  }
  t.values.assign(t.columns.size(), {});

  std::vector<std::string> fields;
  std::vector<double> row(t.columns.size());
  auto reject = [&](const std::string& why) {
    ++t.lines_rejected;
    if (t.first_rejected_lines.size() < 5) {
      t.first_rejected_lines.push_back(line_no);
      t.first_rejected_reasons.push_back(why);
    }
  };
  while (std::getline(in, line)) {
    ++line_no;
    if (trim(line).empty()) continue;
    ++t.lines_read;
    if (line.size() > options.max_line_chars) {
      reject("line too long");
      continue;
    }
    split(line, fields);
    if (fields.size() != header.size()) {
      reject("has " + std::to_string(fields.size()) + " fields, header has " + std::to_string(header.size()));
      continue;
    }
    bool ok = true;
    for (std::size_t c = 0; c < source.size() && ok; ++c) {
      std::string why;
      if (!parse_field(fields[source[c]], row[c], why)) {
        reject(why + " in '" + t.columns[c] + "'");
        ok = false;
      }
    }
    if (!ok) continue;
    for (std::size_t c = 0; c < row.size(); ++c) t.values[c].push_back(row[c]);
  }
  if (t.rows() == 0) {
    throw CsvError(name + ": no usable data line (" + t.rejection_summary() + ")");
  }
  return t;
}

struct Writer::Impl {
  std::FILE* f = nullptr;
  std::string file;
};

Writer::Writer(const std::string& file, const std::vector<std::string>& columns)
    : impl_(new Impl), n_columns_(columns.size()) {
  impl_->file = file;
  impl_->f = std::fopen(file.c_str(), "w");
  if (!impl_->f) {
    delete impl_;
    throw CsvError(file + ": cannot open for writing");
  }
  for (std::size_t i = 0; i < columns.size(); ++i) {
    std::fputs(columns[i].c_str(), impl_->f);
    std::fputc(i + 1 < columns.size() ? ',' : '\n', impl_->f);
  }
}

Writer::~Writer() {
  if (impl_ && impl_->f) std::fclose(impl_->f);
  delete impl_;
}

void Writer::row(const double* values, std::size_t n) {
  if (n != n_columns_) throw CsvError(impl_->file + ": row has " + std::to_string(n) + " values for " + std::to_string(n_columns_) + " columns");
  for (std::size_t i = 0; i < n; ++i) {
    std::fprintf(impl_->f, "%.9g", values[i]);
    std::fputc(i + 1 < n ? ',' : '\n', impl_->f);
  }
}

void Writer::close() {
  if (impl_->f) {
    const bool bad = std::ferror(impl_->f) != 0;
    std::fclose(impl_->f);
    impl_->f = nullptr;
    if (bad) throw CsvError(impl_->file + ": write error");
  }
}

}  // namespace bbw::csv
