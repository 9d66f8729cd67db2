#include "bbw/dds/corner.hpp"

namespace bbw::dds {

std::optional<Corner> parse_corner(std::string_view name) {
  for (Corner c : kAllCorners) {
    if (name == corner_name(c)) return c;
  }
  return std::nullopt;
}

std::optional<Corner> corner_from_wire(std::uint8_t id) {
  if (id < kCornerCount) return static_cast<Corner>(id);
  return std::nullopt;
}

}  // namespace bbw::dds
