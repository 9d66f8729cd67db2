#include "bbw/common/csv.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <unordered_map>
#include <sys/stat.h>

namespace bbw::csv {

namespace {

std::string trim(const std::string& s) {
  std::size_t b = 0;
  std::size_t e = s.size();
  while (b < e && (s[b] == ' ' || s[b] == '\t')) ++b;
  while (e > b && (s[e - 1] == ' ' || s[e - 1] == '\t' || s[e - 1] == '\r')) --e;
  return s.substr(b, e - b);
}

std::string where(const std::string& name, std::size_t line_no) { return name + ":" + std::to_string(line_no) + ": "; }

// Reads one line (without '\n' and a trailing '\r'); holds at most max + 1 characters of it and
// skips the rest, setting too_long. Returns false at the end of the input.
bool next_line(std::streambuf& sb, std::string& line, std::size_t max, bool& too_long) {
  line.clear();
  too_long = false;
  int c = sb.sbumpc();
  if (c == std::char_traits<char>::eof()) return false;
  for (; c != std::char_traits<char>::eof() && c != '\n'; c = sb.sbumpc()) {
    if (line.size() <= max) line.push_back(static_cast<char>(c));
    else too_long = true;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  if (line.size() > max) too_long = true;
  return true;
}

// Splits on commas; a field whose first non-blank character is '"' is quoted (a comma inside it
// is data, "" is one quote). Fields are trimmed of blanks. Returns "" or the reason it failed.
std::string split(const std::string& line, std::vector<std::string>& out) {
  out.clear();
  std::size_t i = 0;
  const std::size_t n = line.size();
  for (;;) {
    while (i < n && (line[i] == ' ' || line[i] == '\t')) ++i;
    std::string field;
    if (i < n && line[i] == '"') {
      const std::size_t open = i++;
      bool closed = false;
      while (i < n) {
        if (line[i] == '"') {
          if (i + 1 < n && line[i + 1] == '"') {
            field.push_back('"');
            i += 2;
            continue;
          }
          closed = true;
          ++i;
          break;
        }
        field.push_back(line[i++]);
      }
      if (!closed) return "quote opened at column " + std::to_string(open + 1) + " is not closed on this line";
      while (i < n && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
      if (i < n && line[i] != ',') {
        return "unexpected '" + printable(std::string(1, line[i])) + "' after a closing quote at column " +
               std::to_string(i + 1);
      }
    } else {
      const std::size_t pos = line.find(',', i);
      field = trim(line.substr(i, pos == std::string::npos ? std::string::npos : pos - i));
      i = pos == std::string::npos ? n : pos;
    }
    out.push_back(std::move(field));
    if (i >= n) return "";
    ++i;  // the comma
    if (i >= n) {
      out.emplace_back();  // a trailing comma: one more, empty field
      return "";
    }
  }
}

// Parses a whole field as a finite double; returns false on any trailing junk or non-finite.
bool parse_field(const std::string& t, double& v, std::string& why) {
  if (t.empty()) {
    why = "empty";
    return false;
  }
  const char* b = t.data();
  const char* e = t.data() + t.size();
  if (*b == '+') ++b;
  const auto res = std::from_chars(b, e, v);
  if (res.ec != std::errc() || res.ptr != e) {
    why = "not a number '" + printable(t, 24) + "'";
    return false;
  }
  if (!std::isfinite(v)) {
    why = std::isnan(v) ? "NaN" : "infinite";
    return false;
  }
  return true;
}

// Reads the header (the first non-blank line). Sets line_no to its line.
std::vector<std::string> header_from(std::streambuf& sb, const std::string& name, const ReadOptions& options,
                                     std::size_t& line_no) {
  std::string line;
  bool too_long = false;
  bool any = false;
  line_no = 0;
  while (next_line(sb, line, options.max_line_chars, too_long)) {
    ++line_no;
    if (too_long) {
      throw CsvError(where(name, line_no) + "header line is longer than " + std::to_string(options.max_line_chars) +
                     " characters");
    }
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 byte-order mark
    if (line_no == 1 && (line.rfind("\xFF\xFE", 0) == 0 || line.rfind("\xFE\xFF", 0) == 0)) {
      throw CsvError(where(name, line_no) + "UTF-16 text (byte-order mark); save the file as UTF-8 or ASCII");
    }
    if (!trim(line).empty()) {
      any = true;
      break;
    }
  }
  if (!any) throw CsvError(name + ": empty file, expected a header row");
  std::vector<std::string> header;
  if (const std::string why = split(line, header); !why.empty()) throw CsvError(where(name, line_no) + "header: " + why);
  if (header.size() > options.max_columns) {
    throw CsvError(where(name, line_no) + "header has " + std::to_string(header.size()) +
                   " columns, more than the limit of " + std::to_string(options.max_columns));
  }
  std::unordered_map<std::string, std::size_t> first_field;
  for (std::size_t i = 0; i < header.size(); ++i) {
    const auto [it, fresh] = first_field.emplace(header[i], i);
    if (!fresh) {
      throw CsvError(where(name, line_no) + "column '" + printable(header[i]) + "' appears twice in the header (fields " +
                     std::to_string(it->second + 1) + " and " + std::to_string(i + 1) + ")");
    }
  }
  return header;
}

void check_file(const std::string& file, const ReadOptions& options) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) throw CsvError(file + ": cannot open file");
  if (S_ISDIR(st.st_mode)) throw CsvError(file + ": is a directory, not a CSV file");
  // A FIFO or a device would block on open or never end.
  if (!S_ISREG(st.st_mode)) throw CsvError(file + ": is not a regular file");
  if (static_cast<std::uint64_t>(st.st_size) > options.max_bytes) {
    throw CsvError(file + ": file is " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                   std::to_string(options.max_bytes));
  }
}

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

}  // namespace

std::string printable(const std::string& text, std::size_t max_chars) {
  std::string out;
  std::size_t shown = 0;
  for (const char ch : text) {
    if (shown == max_chars) return out + "...";
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x20 && c < 0x7f) {
      out.push_back(ch);
    } else {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02X", c);
      out += buf;
    }
    ++shown;
  }
  return out;
}

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
  throw CsvError(file + ": no column '" + printable(name) + "'");
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
  if (lines_unsorted_time > 0) {
    os << "; dropped " << lines_unsorted_time << " whose time did not increase (first: line " << first_unsorted_time_line
       << ")";
  }
  return os.str();
}

Table read(const std::string& file, const ReadOptions& options) {
  check_file(file, options);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw CsvError(file + ": cannot open file");
  return read_stream(in, file, options);
}

std::vector<std::string> read_header(const std::string& file, const ReadOptions& options) {
  check_file(file, options);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw CsvError(file + ": cannot open file");
  return read_header_stream(in, file, options);
}

std::vector<std::string> read_header_stream(std::istream& in, const std::string& name, const ReadOptions& options) {
  std::size_t line_no = 0;
  return header_from(*in.rdbuf(), name, options, line_no);
}

Table read_stream(std::istream& in, const std::string& name, const ReadOptions& options) {
  Table t;
  t.file = name;
  std::streambuf& sb = *in.rdbuf();
  std::size_t line_no = 0;
  const std::vector<std::string> header = header_from(sb, name, options, line_no);

  std::vector<std::size_t> source;  // header index per loaded column
  auto find = [&](const std::string& c) -> long {
    for (std::size_t i = 0; i < header.size(); ++i) {
      if (header[i] == c) return static_cast<long>(i);
    }
    return -1;
  };
  for (const auto& c : options.required) {
    if (t.has(c)) continue;  // named twice by the caller: loaded once
    const long i = find(c);
    if (i < 0) {
      std::string have;
      for (const auto& h : header) have += (have.empty() ? "" : ", ") + h;
      throw CsvError(where(name, line_no) + "required column '" + printable(c) + "' is missing (header has: " +
                     printable(have, 512) + ")");
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
  long time_index = -1;
  if (!options.time_column.empty()) {
    for (std::size_t c = 0; c < t.columns.size(); ++c) {
      if (t.columns[c] == options.time_column) time_index = static_cast<long>(c);
    }
    if (time_index < 0) {
      throw CsvError(where(name, line_no) + "time column '" + printable(options.time_column) + "' is not loaded");
    }
  }

  std::string line;
  bool too_long = false;
  std::vector<std::string> fields;
  std::vector<double> row(t.columns.size());
  double last_time = 0.0;
  std::size_t last_time_line = 0;
  auto reject = [&](const std::string& why) {
    ++t.lines_rejected;
    if (t.first_rejected_lines.size() < 5) {
      t.first_rejected_lines.push_back(line_no);
      t.first_rejected_reasons.push_back(why);
    }
  };
  while (next_line(sb, line, options.max_line_chars, too_long)) {
    ++line_no;
    if (!too_long && trim(line).empty()) continue;
    ++t.lines_read;
    if (too_long) {
      reject("longer than " + std::to_string(options.max_line_chars) + " characters");
      continue;
    }
    if (const std::string why = split(line, fields); !why.empty()) {
      reject(why);
      continue;
    }
    if (fields.size() != header.size()) {
      reject("has " + std::to_string(fields.size()) + " fields, header has " + std::to_string(header.size()));
      continue;
    }
    bool ok = true;
    for (std::size_t c = 0; c < source.size() && ok; ++c) {
      std::string why;
      if (!parse_field(fields[source[c]], row[c], why)) {
        reject(why + " in '" + printable(t.columns[c]) + "'");
        ok = false;
      }
    }
    if (!ok) continue;
    if (time_index >= 0) {
      const double now = row[static_cast<std::size_t>(time_index)];
      if (last_time_line > 0 && !(now > last_time)) {
        if (!options.allow_unsorted_time) {
          throw CsvError(where(name, line_no) + "time '" + printable(options.time_column) + "' does not increase: " +
                         number_text(now) + " after " + number_text(last_time) + " on line " +
                         std::to_string(last_time_line) + " (sort the file, or allow dropping such lines: --allow-unsorted-time)");
        }
        if (t.lines_unsorted_time++ == 0) t.first_unsorted_time_line = line_no;
        continue;
      }
      last_time = now;
      last_time_line = line_no;
    }
    for (std::size_t c = 0; c < row.size(); ++c) t.values[c].push_back(row[c]);
  }
  if (in.bad()) throw CsvError(name + ": read error after line " + std::to_string(line_no));
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
