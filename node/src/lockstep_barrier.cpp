#include "bbw/node/lockstep_barrier.hpp"

#include <algorithm>
#include <stdexcept>

namespace bbw::node {

std::size_t LockstepBarrier::add(const std::string& name) {
  for (const Part& p : parts_) {
    if (p.name == name) throw std::invalid_argument("lockstep participant '" + name + "' declared twice");
  }
  parts_.push_back(Part{name});
  return parts_.size() - 1;
}

void LockstepBarrier::done(std::size_t participant, std::uint64_t step) {
  Part& p = parts_.at(participant);
  p.next = std::max(p.next, step + 1);
}

void LockstepBarrier::rejoin(std::size_t participant, std::uint64_t step) { parts_.at(participant).next = step; }

void LockstepBarrier::set_alive(std::size_t participant, bool alive) { parts_.at(participant).alive = alive; }

void LockstepBarrier::set_failed(std::size_t participant, bool failed) { parts_.at(participant).failed = failed; }

bool LockstepBarrier::complete(std::uint64_t step) const {
  if (any_failed()) return true;
  for (const Part& p : parts_) {
    if (p.next <= step && p.alive) return false;
  }
  return true;
}

bool LockstepBarrier::any_failed() const {
  return std::any_of(parts_.begin(), parts_.end(), [](const Part& p) { return p.failed; });
}

std::string LockstepBarrier::lagging(std::uint64_t step) const {
  std::string out;
  for (const Part& p : parts_) {
    if (p.next <= step) out += (out.empty() ? "" : ", ") + p.name;
  }
  return out;
}

}  // namespace bbw::node
