// Strict YAML reading: every config loader in bbw goes through this.
//
// An unknown key, a missing required key, a wrong type or an out-of-range value
// throws ConfigError whose message names the file, the line, the key path and the
// rule that was broken, e.g.
//   config/plant/ecaliper.yaml:12: key 'motor.torque_constant_Nm_per_A': must be > 0, got -1
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace bbw::config {

class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, int line, const std::string& key_path,
              const std::string& rule);
  const std::string& file() const { return file_; }
  int line() const { return line_; }  // 1-based; 0 when unknown
  const std::string& key_path() const { return key_path_; }
  const std::string& rule() const { return rule_; }

 private:
  std::string file_;
  int line_;
  std::string key_path_;
  std::string rule_;
};

// Bounds on what a parsed document may expand to, checked before any loader reads it. yaml-cpp
// shares an aliased node, so parsing stays small, but every reader that walks or copies the tree
// pays for each use of an alias: a 44 KB file with one 20 000-entry list aliased 1000 times is a
// 20-million-node document. Nodes are counted the way a reader sees them (an alias counts its
// whole subtree again at each use). docs/security.md, "Inputs", lists the values and tests.
struct DocumentLimits {
  std::size_t max_nodes = 200000;       // scalars, lists and mappings, aliases expanded
  std::size_t max_list_entries = 20000; // entries of one list (or mapping)
  std::size_t max_depth = 64;           // nesting of lists and mappings (an alias to itself is refused)
  std::size_t max_scalar_chars = 4096;  // characters of one scalar
};

// Throws ConfigError naming the file, the line and the key path where a limit was passed.
void check_document(const YAML::Node& root, const std::string& file, const DocumentLimits& limits = {});

// Closed or open numeric interval used as a validation rule.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  static Range any() { return {}; }
  static Range positive() { return {0.0, std::numeric_limits<double>::infinity(), true, false}; }
  static Range non_negative() { return {0.0, std::numeric_limits<double>::infinity(), false, false}; }
  static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range at_least(double lo) { return {lo, std::numeric_limits<double>::infinity(), false, false}; }
  static Range above(double lo) { return {lo, std::numeric_limits<double>::infinity(), true, false}; }

  bool contains(double v) const;
  std::string describe() const;  // e.g. "must be > 0", "must be in [0, 10]"
};

// A YAML mapping being read. Keys read through it are remembered; finish() rejects the
// rest as unknown. Children share the file name and extend the key path.
class Reader {
 public:
  Reader(YAML::Node node, std::string file, std::string path = "");

  // Parses a file: only a regular file of at most 4 MiB is opened (a directory, FIFO or device
  // is refused before reading), then check_document(). Syntax errors become ConfigError with
  // the parser's line.
  static Reader from_file(const std::string& file, const DocumentLimits& limits = {});
  // Parses a string (tests, embedded defaults). `name` stands in for the file.
  static Reader from_string(const std::string& text, const std::string& name, const DocumentLimits& limits = {});

  bool has(const std::string& key) const;

  double number(const std::string& key, const Range& range = Range::any());
  double number_or(const std::string& key, double fallback, const Range& range = Range::any());
  std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi);
  std::int64_t integer_or(const std::string& key, std::int64_t fallback, std::int64_t lo, std::int64_t hi);
  bool boolean(const std::string& key);
  bool boolean_or(const std::string& key, bool fallback);
  std::string string(const std::string& key);
  std::string string_or(const std::string& key, const std::string& fallback);
  // A string that must be one of `allowed`.
  std::string choice(const std::string& key, const std::vector<std::string>& allowed);
  std::string choice_or(const std::string& key, const std::string& fallback,
                        const std::vector<std::string>& allowed);
  std::vector<double> numbers(const std::string& key, const Range& range = Range::any());
  // A non-empty list of strings.
  std::vector<std::string> strings(const std::string& key);

  Reader map(const std::string& key);
  std::optional<Reader> optional_map(const std::string& key);
  std::vector<Reader> maps(const std::string& key);  // a sequence of mappings

  // Throws for every key in this mapping that was never read.
  void finish() const;

  // Throws a ConfigError located at `key` (or at this mapping when key is empty).
  [[noreturn]] void fail(const std::string& key, const std::string& rule) const;

  const std::string& file() const { return file_; }
  const std::string& path() const { return path_; }
  int line() const;
  const YAML::Node& node() const { return node_; }

 private:
  YAML::Node required(const std::string& key);
  std::string child_path(const std::string& key) const;
  double as_number(const YAML::Node& n, const std::string& key) const;

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
};

// Directory part of a path ("" for a bare file name), to resolve relative references.
std::string directory_of(const std::string& file);
// Resolves `ref` relative to the directory of `from_file` unless it is absolute.
std::string resolve_relative(const std::string& from_file, const std::string& ref);

}  // namespace bbw::config
