// A small JSON writer for reports (summary.json, analysis.json). Values are written in
// order; the writer tracks commas and nesting. Non-finite numbers are written as null.
#pragma once

#include <string>
#include <vector>

namespace bbw::json {

class Writer {
 public:
  Writer& begin_object(const std::string& key = "");
  Writer& end_object();
  Writer& begin_array(const std::string& key = "");
  Writer& end_array();
  Writer& value(const std::string& key, double v);
  Writer& value(const std::string& key, long long v);
  Writer& value(const std::string& key, int v) { return value(key, static_cast<long long>(v)); }
  Writer& value(const std::string& key, std::size_t v) { return value(key, static_cast<long long>(v)); }
  Writer& value(const std::string& key, bool v);
  Writer& value(const std::string& key, const std::string& v);
  Writer& value(const std::string& key, const char* v) { return value(key, std::string(v)); }
  Writer& numbers(const std::string& key, const std::vector<double>& v);
  // Array elements: key must be empty inside arrays.
  const std::string& str() const { return out_; }
  void save(const std::string& file) const;  // throws std::runtime_error

  static std::string escape(const std::string& s);

 private:
  void prefix(const std::string& key);
  std::string out_;
  std::vector<bool> first_;  // per nesting level: no element written yet
  int depth_ = 0;
};

}  // namespace bbw::json
