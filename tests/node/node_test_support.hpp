// Shared set-up for the node tests: paths, the shipped calibrator config, sha256 of a file.
#pragma once

#include <array>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "bbw/calibration/config_yaml.hpp"

namespace bbw::node::test {

inline std::string source_path(const std::string& rel) { return std::string(BBW_TEST_SOURCE_DIR) + "/" + rel; }

inline calibration::CalibratorConfig robust_config() {
  return calibration::load_config(source_path("config/calibrator/robust.yaml"));
}

// sha256 of a file through coreutils' sha256sum (the digests in data/ were made the same way).
inline std::string sha256_of(const std::string& file) {
  const std::string cmd = "sha256sum '" + file + "'";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) throw std::runtime_error("cannot run " + cmd);
  std::array<char, 65> hex{};
  const std::size_t n = std::fread(hex.data(), 1, 64, p);
  ::pclose(p);
  if (n != 64) throw std::runtime_error(cmd + ": no digest");
  return std::string(hex.data(), 64);
}

}  // namespace bbw::node::test
