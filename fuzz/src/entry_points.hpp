// The fuzzed entry points, shared by the libFuzzer targets (fuzz/targets/, built with clang by
// `./bbw fuzz`) and the corpus replay test (tests/security/test_fuzz_corpus.cpp, built with g++
// by `./bbw test`). Each feeds arbitrary bytes to one reader of outside data:
//   csv       bbw::csv::read_stream
//   yaml      bbw::config::Reader over any document, every key read by its node type
//   calib     bbw::calibration::read_config (calibrator YAML)
//   scenario  bbw::scenario::load_scenario_string (scenario YAML, plant file resolved)
//   scenario_alias  the same loader on documents built around anchors and aliases (the input
//             follows a fixed head that anchors a drive, a list and a mapping), then the run
//             checks (four-corner names, run size); must answer within the document limits
//   csv_quoted  bbw::csv::read_stream with options chosen by the first byte (BOM prepended,
//             time column, dropping unsorted time); every message must be printable ASCII
// and returns Accepted or Rejected. Rejected means the reader threw its documented exception
// (CsvError, ConfigError). Anything else escapes: another exception type, or InvariantBroken
// when accepted output breaks the reader's contract (e.g. a non-finite CSV value), is a finding.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace bbw::fuzz {

enum class Outcome { Accepted, Rejected };

class InvariantBroken : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

Outcome csv(const std::uint8_t* data, std::size_t size);
Outcome yaml(const std::uint8_t* data, std::size_t size);
Outcome calib(const std::uint8_t* data, std::size_t size);
// `source_dir` is the repository root: the document stands in for
// <source_dir>/config/scenarios/fuzz.yaml, so `plant: ../plant/ecaliper.yaml` resolves.
Outcome scenario(const std::uint8_t* data, std::size_t size, const std::string& source_dir);
Outcome scenario_alias(const std::uint8_t* data, std::size_t size, const std::string& source_dir);
Outcome csv_quoted(const std::uint8_t* data, std::size_t size);

struct Target {
  const char* name;
  Outcome (*run)(const std::uint8_t*, std::size_t, const std::string& source_dir);
};
// csv, yaml, calib, scenario, scenario_alias, csv_quoted: the names of the corpus folders
// under tests/fuzz_corpus/.
const std::vector<Target>& targets();

}  // namespace bbw::fuzz
