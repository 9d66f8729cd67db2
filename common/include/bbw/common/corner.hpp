// The corner id: one type for every layer (plant scenario, node cores, faults, wire). Its value
// is the wire's corner_id, the @key of every per-corner topic (idl/bbw_msgs.idl). Header-only,
// no dependencies (target bbw_corner_id).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

namespace bbw {

enum class Corner : std::uint8_t { FL = 0, FR = 1, RL = 2, RR = 3 };

inline constexpr std::array<Corner, 4> kAllCorners{Corner::FL, Corner::FR, Corner::RL, Corner::RR};
inline constexpr std::size_t kCornerCount = kAllCorners.size();

constexpr const char* corner_name(Corner c) {
  constexpr const char* names[] = {"FL", "FR", "RL", "RR"};
  return names[static_cast<std::size_t>(c)];
}
constexpr std::size_t corner_index(Corner c) { return static_cast<std::size_t>(c); }
// "FL", "FR", "RL", "RR" (exact, upper case); nullopt for anything else.
constexpr std::optional<Corner> parse_corner(std::string_view name) {
  for (Corner c : kAllCorners) {
    if (name == corner_name(c)) return c;
  }
  return std::nullopt;
}
// A wire id 0..3; nullopt for anything else (a sample from a corner that does not exist).
constexpr std::optional<Corner> corner_from_wire(std::uint8_t id) {
  if (id < kCornerCount) return static_cast<Corner>(id);
  return std::nullopt;
}
constexpr bool is_front(Corner c) { return c == Corner::FL || c == Corner::FR; }

}  // namespace bbw
