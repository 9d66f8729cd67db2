#include "bbw/common/strict_yaml.hpp"

#include <sys/stat.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace bbw::config {

namespace {

// Config files are a few kB; anything near this limit is a mistake or an attack.
constexpr std::uint64_t kMaxConfigBytes = 4u << 20;

std::string format_message(const std::string& file, int line, const std::string& key_path,
                           const std::string& rule) {
  std::ostringstream os;
  os << file;
  if (line > 0) os << ":" << line;
  os << ": ";
  if (!key_path.empty()) os << "key '" << key_path << "': ";
  os << rule;
  return os.str();
}

std::string fmt_number(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

int mark_line(const YAML::Node& n) {
  if (!n.IsDefined()) return 0;
  const YAML::Mark m = n.Mark();
  return m.line >= 0 ? m.line + 1 : 0;
}

const char* type_name(const YAML::Node& n) {
  switch (n.Type()) {
    case YAML::NodeType::Null: return "null";
    case YAML::NodeType::Scalar: return "a scalar";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a mapping";
    default: return "nothing";
  }
}

// Walks a parsed document the way a reader would see it (aliases expanded) and stops at the
// first limit passed. Recursion is bounded by limits.max_depth.
class DocumentWalk {
 public:
  DocumentWalk(const std::string& file, const DocumentLimits& limits) : file_(file), limits_(limits) {}

  void visit(const YAML::Node& n, std::size_t depth) {
    if (++nodes_ > limits_.max_nodes) {
      fail(n, "document has more than " + std::to_string(limits_.max_nodes) +
                  " nodes when its aliases are expanded (each use of an alias counts its whole value again)");
    }
    if (depth > limits_.max_depth) {
      fail(n, "nested deeper than " + std::to_string(limits_.max_depth) + " levels (or an alias refers to itself)");
    }
    switch (n.Type()) {
      case YAML::NodeType::Scalar:
        scalar_chars_ += n.Scalar().size();
        if (scalar_chars_ > kMaxScalarChars) {
          fail(n, "document holds more than " + std::to_string(kMaxScalarChars) +
                      " characters of values when its aliases are expanded");
        }
        break;
      case YAML::NodeType::Sequence: {
        if (n.size() > limits_.max_list_entries) {
          fail(n, "list has " + std::to_string(n.size()) + " entries, more than the limit of " +
                      std::to_string(limits_.max_list_entries));
        }
        std::size_t i = 0;
        for (const auto& item : n) {
          const std::size_t mark = path_.size();
          path_ += "[" + std::to_string(i++) + "]";
          visit(item, depth + 1);
          path_.resize(mark);
        }
        break;
      }
      case YAML::NodeType::Map: {
        if (n.size() > limits_.max_list_entries) {
          fail(n, "mapping has " + std::to_string(n.size()) + " keys, more than the limit of " +
                      std::to_string(limits_.max_list_entries));
        }
        for (const auto& kv : n) {
          const std::size_t mark = path_.size();
          visit(kv.first, depth + 1);
          path_ += (path_.empty() ? "" : ".") + (kv.first.IsScalar() ? kv.first.Scalar() : std::string("?"));
          visit(kv.second, depth + 1);
          path_.resize(mark);
        }
        break;
      }
      default:
        break;
    }
  }

 private:
  // Expanded characters of all scalars; the file itself is at most kMaxConfigBytes.
  static constexpr std::size_t kMaxScalarChars = 16u << 20;

  [[noreturn]] void fail(const YAML::Node& n, const std::string& rule) const {
    throw ConfigError(file_, mark_line(n), path_, rule);
  }

  const std::string& file_;
  const DocumentLimits& limits_;
  std::size_t nodes_ = 0;
  std::size_t scalar_chars_ = 0;
  std::string path_;
};

}  // namespace

void check_document(const YAML::Node& root, const std::string& file, const DocumentLimits& limits) {
  DocumentWalk(file, limits).visit(root, 0);
}

ConfigError::ConfigError(const std::string& file, int line, const std::string& key_path,
                         const std::string& rule)
    : std::runtime_error(format_message(file, line, key_path, rule)),
      file_(file),
      line_(line),
      key_path_(key_path),
      rule_(rule) {}

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (lo_open ? !(v > lo) : !(v >= lo)) return false;
  if (hi_open ? !(v < hi) : !(v <= hi)) return false;
  return true;
}

std::string Range::describe() const {
  const bool has_lo = std::isfinite(lo);
  const bool has_hi = std::isfinite(hi);
  if (!has_lo && !has_hi) return "must be a finite number";
  if (has_lo && !has_hi) return std::string("must be ") + (lo_open ? "> " : ">= ") + fmt_number(lo);
  if (!has_lo && has_hi) return std::string("must be ") + (hi_open ? "< " : "<= ") + fmt_number(hi);
  return std::string("must be in ") + (lo_open ? "(" : "[") + fmt_number(lo) + ", " +
         fmt_number(hi) + (hi_open ? ")" : "]");
}

Reader::Reader(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    throw ConfigError(file_, mark_line(node_), path_,
                      std::string("must be a mapping of keys to values, got ") + type_name(node_));
  }
  // yaml-cpp keeps every duplicate and node[key] returns the first: a repeated key would
  // silently shadow the later value. Keys must also be plain scalars.
  std::set<std::string> seen;
  for (const auto& kv : node_) {
    if (!kv.first.IsScalar()) {
      throw ConfigError(file_, mark_line(kv.first), path_,
                        std::string("keys must be plain names, got ") + type_name(kv.first));
    }
    const std::string& k = kv.first.Scalar();
    if (!seen.insert(k).second) {
      throw ConfigError(file_, mark_line(kv.first), child_path(k), "duplicate key");
    }
  }
}

Reader Reader::from_file(const std::string& file, const DocumentLimits& limits) {
  // Refuse what is not a small regular file before yaml-cpp opens it: a directory makes it
  // throw std::ios_base::failure, a FIFO or a device would block or never end.
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) throw ConfigError(file, 0, "", "cannot open file");
  if (!S_ISREG(st.st_mode)) throw ConfigError(file, 0, "", "is not a regular file");
  if (static_cast<std::uint64_t>(st.st_size) > kMaxConfigBytes) {
    throw ConfigError(file, 0, "", "file is " + std::to_string(st.st_size) + " bytes, more than the limit of " +
                                       std::to_string(kMaxConfigBytes));
  }
  std::string text;
  {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw ConfigError(file, 0, "", "cannot open file");
    // Read at most one byte past the limit: the file may have grown since stat().
    text.resize(kMaxConfigBytes + 1);
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (in.bad()) throw ConfigError(file, 0, "", "cannot read file");
    if (text.size() > kMaxConfigBytes) {
      throw ConfigError(file, 0, "", "file is more than the limit of " + std::to_string(kMaxConfigBytes) + " bytes");
    }
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(file, e.mark.line >= 0 ? e.mark.line + 1 : 0, "",
                      "YAML syntax error: " + e.msg);
  } catch (const std::exception& e) {
    throw ConfigError(file, 0, "", std::string("cannot read file: ") + e.what());
  }
  check_document(root, file, limits);
  return Reader(root, file, "");
}

Reader Reader::from_string(const std::string& text, const std::string& name, const DocumentLimits& limits) {
  if (text.size() > kMaxConfigBytes) {
    throw ConfigError(name, 0, "", "text is " + std::to_string(text.size()) + " bytes, more than the limit of " +
                                       std::to_string(kMaxConfigBytes));
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw ConfigError(name, e.mark.line >= 0 ? e.mark.line + 1 : 0, "",
                      "YAML syntax error: " + e.msg);
  }
  check_document(root, name, limits);
  return Reader(root, name, "");
}

int Reader::line() const { return mark_line(node_); }

std::string Reader::child_path(const std::string& key) const {
  return path_.empty() ? key : path_ + "." + key;
}

bool Reader::has(const std::string& key) const {
  const YAML::Node n = node_[key];
  return n.IsDefined() && !n.IsNull();
}

void Reader::fail(const std::string& key, const std::string& rule) const {
  if (key.empty()) throw ConfigError(file_, line(), path_, rule);
  const YAML::Node n = node_[key];
  const int l = n.IsDefined() ? mark_line(n) : line();
  throw ConfigError(file_, l, child_path(key), rule);
}

YAML::Node Reader::required(const std::string& key) {
  used_.insert(key);
  const YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) fail(key, "required key is missing");
  return n;
}

double Reader::as_number(const YAML::Node& n, const std::string& key) const {
  if (!n.IsScalar()) fail(key, std::string("must be a number, got ") + type_name(n));
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "must be a number, got '" + n.Scalar() + "'");
  }
  if (!std::isfinite(v)) fail(key, "must be a finite number, got '" + n.Scalar() + "'");
  return v;
}

double Reader::number(const std::string& key, const Range& range) {
  const double v = as_number(required(key), key);
  if (!range.contains(v)) fail(key, range.describe() + ", got " + fmt_number(v));
  return v;
}

double Reader::number_or(const std::string& key, double fallback, const Range& range) {
  used_.insert(key);
  if (!has(key)) return fallback;
  return number(key, range);
}

std::int64_t Reader::integer(const std::string& key, std::int64_t lo, std::int64_t hi) {
  const YAML::Node n = required(key);
  if (!n.IsScalar()) fail(key, std::string("must be an integer, got ") + type_name(n));
  std::int64_t v = 0;
  try {
    v = n.as<std::int64_t>();
  } catch (const YAML::Exception&) {
    fail(key, "must be an integer, got '" + n.Scalar() + "'");
  }
  if (v < lo || v > hi) {
    fail(key, "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
                  "], got " + std::to_string(v));
  }
  return v;
}

std::int64_t Reader::integer_or(const std::string& key, std::int64_t fallback, std::int64_t lo,
                                std::int64_t hi) {
  used_.insert(key);
  if (!has(key)) return fallback;
  return integer(key, lo, hi);
}

bool Reader::boolean(const std::string& key) {
  const YAML::Node n = required(key);
  if (!n.IsScalar()) fail(key, std::string("must be true or false, got ") + type_name(n));
  const std::string& s = n.Scalar();
  if (s == "true") return true;
  if (s == "false") return false;
  fail(key, "must be true or false, got '" + s + "'");
}

bool Reader::boolean_or(const std::string& key, bool fallback) {
  used_.insert(key);
  if (!has(key)) return fallback;
  return boolean(key);
}

std::string Reader::string(const std::string& key) {
  const YAML::Node n = required(key);
  if (!n.IsScalar()) fail(key, std::string("must be a string, got ") + type_name(n));
  return n.Scalar();
}

std::string Reader::string_or(const std::string& key, const std::string& fallback) {
  used_.insert(key);
  if (!has(key)) return fallback;
  return string(key);
}

std::string Reader::choice(const std::string& key, const std::vector<std::string>& allowed) {
  const std::string s = string(key);
  for (const auto& a : allowed) {
    if (a == s) return s;
  }
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  fail(key, "must be one of {" + list + "}, got '" + s + "'");
}

std::string Reader::choice_or(const std::string& key, const std::string& fallback,
                              const std::vector<std::string>& allowed) {
  used_.insert(key);
  if (!has(key)) return fallback;
  return choice(key, allowed);
}

std::vector<double> Reader::numbers(const std::string& key, const Range& range) {
  const YAML::Node n = required(key);
  if (!n.IsSequence()) fail(key, std::string("must be a list of numbers, got ") + type_name(n));
  std::vector<double> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string item_key = key + "[" + std::to_string(i) + "]";
    const YAML::Node item = n[i];
    if (!item.IsScalar()) {
      throw ConfigError(file_, mark_line(item), child_path(item_key),
                        std::string("must be a number, got ") + type_name(item));
    }
    double v = 0.0;
    try {
      v = item.as<double>();
    } catch (const YAML::Exception&) {
      throw ConfigError(file_, mark_line(item), child_path(item_key),
                        "must be a number, got '" + item.Scalar() + "'");
    }
    if (!range.contains(v)) {
      throw ConfigError(file_, mark_line(item), child_path(item_key),
                        range.describe() + ", got '" + item.Scalar() + "'");
    }
    out.push_back(v);
  }
  return out;
}

std::vector<std::string> Reader::strings(const std::string& key) {
  const YAML::Node n = required(key);
  if (!n.IsSequence() || n.size() == 0) fail(key, std::string("must be a non-empty list of strings, got ") + type_name(n));
  std::vector<std::string> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    if (!n[i].IsScalar()) fail(key, "entry " + std::to_string(i) + " must be a string, got " + type_name(n[i]));
    out.push_back(n[i].as<std::string>());
  }
  return out;
}

Reader Reader::map(const std::string& key) {
  const YAML::Node n = required(key);
  if (!n.IsMap()) fail(key, std::string("must be a mapping, got ") + type_name(n));
  return Reader(n, file_, child_path(key));
}

std::optional<Reader> Reader::optional_map(const std::string& key) {
  used_.insert(key);
  if (!has(key)) return std::nullopt;
  return map(key);
}

std::vector<Reader> Reader::maps(const std::string& key) {
  const YAML::Node n = required(key);
  if (!n.IsSequence()) fail(key, std::string("must be a list of mappings, got ") + type_name(n));
  std::vector<Reader> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const YAML::Node item = n[i];
    const std::string p = child_path(key + "[" + std::to_string(i) + "]");
    if (!item.IsMap()) {
      throw ConfigError(file_, mark_line(item), p,
                        std::string("must be a mapping, got ") + type_name(item));
    }
    out.emplace_back(item, file_, p);
  }
  return out;
}

void Reader::finish() const {
  for (const auto& kv : node_) {
    const std::string k = kv.first.Scalar();
    if (used_.count(k) == 0) {
      throw ConfigError(file_, mark_line(kv.first), child_path(k), "unknown key");
    }
  }
}

std::string directory_of(const std::string& file) {
  const auto pos = file.find_last_of('/');
  return pos == std::string::npos ? std::string() : file.substr(0, pos);
}

std::string resolve_relative(const std::string& from_file, const std::string& ref) {
  if (!ref.empty() && ref[0] == '/') return ref;
  const std::string dir = directory_of(from_file);
  return dir.empty() ? ref : dir + "/" + ref;
}

}  // namespace bbw::config
