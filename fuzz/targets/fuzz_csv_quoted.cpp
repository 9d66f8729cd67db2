// libFuzzer target: bbw::fuzz::csv_quoted (see fuzz/src/entry_points.hpp). Built by ./bbw fuzz.
#include <cstddef>
#include <cstdint>

#include "entry_points.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  bbw::fuzz::csv_quoted(data, size);
  return 0;
}
