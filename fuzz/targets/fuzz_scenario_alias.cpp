// libFuzzer target: bbw::fuzz::scenario_alias (see fuzz/src/entry_points.hpp). Built by ./bbw fuzz.
#include <cstddef>
#include <cstdint>

#include "entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  bbw::fuzz::scenario_alias(data, size, BBW_SOURCE_DIR);
  return 0;
}
