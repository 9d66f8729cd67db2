#include "bbw/common/json.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

namespace bbw::json {

std::string Writer::escape(const std::string& s) {
  std::string o;
  o.reserve(s.size() + 2);
  for (const char c : s) {
    switch (c) {
      case '"': o += "\\\""; break;
      case '\\': o += "\\\\"; break;
      case '\n': o += "\\n"; break;
      case '\t': o += "\\t"; break;
      case '\r': o += "\\r"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          o += buf;
        } else {
          o += c;
        }
    }
  }
  return o;
}

void Writer::prefix(const std::string& key) {
  if (depth_ > 0) {
    if (!first_.back()) out_ += ",";
    first_.back() = false;
    out_ += "\n" + std::string(static_cast<std::size_t>(depth_) * 2, ' ');
  }
  if (!key.empty()) out_ += "\"" + escape(key) + "\": ";
}

Writer& Writer::begin_object(const std::string& key) {
  prefix(key);
  out_ += "{";
  first_.push_back(true);
  ++depth_;
  return *this;
}

Writer& Writer::end_object() {
  --depth_;
  const bool empty = first_.back();
  first_.pop_back();
  if (!empty) out_ += "\n" + std::string(static_cast<std::size_t>(depth_) * 2, ' ');
  out_ += "}";
  return *this;
}

Writer& Writer::begin_array(const std::string& key) {
  prefix(key);
  out_ += "[";
  first_.push_back(true);
  ++depth_;
  return *this;
}

Writer& Writer::end_array() {
  --depth_;
  const bool empty = first_.back();
  first_.pop_back();
  if (!empty) out_ += "\n" + std::string(static_cast<std::size_t>(depth_) * 2, ' ');
  out_ += "]";
  return *this;
}

Writer& Writer::value(const std::string& key, double v) {
  prefix(key);
  if (!std::isfinite(v)) {
    out_ += "null";
  } else {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.9g", v);
    out_ += buf;
  }
  return *this;
}

Writer& Writer::value(const std::string& key, long long v) {
  prefix(key);
  out_ += std::to_string(v);
  return *this;
}

Writer& Writer::value(const std::string& key, bool v) {
  prefix(key);
  out_ += v ? "true" : "false";
  return *this;
}

Writer& Writer::value(const std::string& key, const std::string& v) {
  prefix(key);
  out_ += "\"" + escape(v) + "\"";
  return *this;
}

Writer& Writer::numbers(const std::string& key, const std::vector<double>& v) {
  prefix(key);
  out_ += "[";
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) out_ += ", ";
    if (!std::isfinite(v[i])) {
      out_ += "null";
    } else {
      char buf[32];
      std::snprintf(buf, sizeof buf, "%.9g", v[i]);
      out_ += buf;
    }
  }
  out_ += "]";
  return *this;
}

void Writer::save(const std::string& file) const {
  std::ofstream f(file);
  if (!f) throw std::runtime_error(file + ": cannot open for writing");
  f << out_ << "\n";
  if (!f) throw std::runtime_error(file + ": write error");
}

}  // namespace bbw::json
