// Corner ids on the wire: the @key of every per-corner topic (see idl/bbw_msgs.idl).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace bbw::dds {

enum class Corner : std::uint8_t { FL = 0, FR = 1, RL = 2, RR = 3 };

inline constexpr std::array<Corner, 4> kAllCorners{Corner::FL, Corner::FR, Corner::RL, Corner::RR};
inline constexpr std::size_t kCornerCount = kAllCorners.size();

constexpr const char* corner_name(Corner c) {
  constexpr const char* names[] = {"FL", "FR", "RL", "RR"};
  return names[static_cast<std::size_t>(c)];
}
constexpr std::size_t corner_index(Corner c) { return static_cast<std::size_t>(c); }
// "FL", "FR", "RL", "RR" (exact, upper case); nullopt for anything else.
std::optional<Corner> parse_corner(std::string_view name);
// A wire id 0..3; nullopt for anything else (a sample from a corner that does not exist).
std::optional<Corner> corner_from_wire(std::uint8_t id);
constexpr bool is_front(Corner c) { return c == Corner::FL || c == Corner::FR; }

}  // namespace bbw::dds
