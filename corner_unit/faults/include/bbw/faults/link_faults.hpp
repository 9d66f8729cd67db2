// Network and process faults of the schedule as pure questions of time, for whoever executes
// them (the corner process stays silent or delays its messages; the launcher kills and
// restarts processes), and a fixed-capacity delay queue for delayed messages.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "bbw/faults/schedule.hpp"

namespace bbw::faults {

class LinkFaults {
 public:
  // Keeps the network and process faults of `target` (a corner or the CCU).
  LinkFaults(const FaultSchedule& schedule, Target target);

  // The target's messages must not be sent at time_s (network silence).
  bool silenced(double time_s) const;
  // Delay to add to a message sent at time_s (0 when none is active), s.
  double delay_s(double time_s) const;
  // The process is dead at time_s (killed and not yet restarted).
  bool killed(double time_s) const;
  // Whether the process is up at time_s and sends.
  bool sends(double time_s) const { return !killed(time_s) && !silenced(time_s); }

  Target target() const { return target_; }
  const std::vector<FaultSpec>& faults() const { return faults_; }

 private:
  Target target_;
  std::vector<FaultSpec> faults_;
};

// What the launcher must do and when, in time order (kills and restarts of every target; hangs
// of a CCU and their resumption). A link cut is no process action: it needs network namespaces
// (tests/system/test_failover_netns.cpp carries it out).
struct ProcessAction {
  enum class Kind { Kill, Restart, Hang, Resume };
  double at_s = 0.0;
  Target target = Target::FL;
  Kind kind = Kind::Kill;
};
std::vector<ProcessAction> process_actions(const FaultSchedule& schedule);

// Messages held back until their release time (network delay). Fixed capacity, FIFO in
// release order as long as the delay does not shrink while messages wait (a shrinking delay
// releases the newer messages no earlier than the older ones: order is kept). Allocation-free.
template <class T, std::size_t Capacity>
class DelayQueue {
 public:
  // False (and the message is dropped) when full.
  bool push(double release_s, const T& msg) {
    if (size_ == Capacity) return false;
    if (size_ > 0) release_s = std::max(release_s, at(size_ - 1).release_s);
    at(size_) = Slot{release_s, msg};
    ++size_;
    return true;
  }
  // The oldest message due at now_s, if any.
  std::optional<T> pop_due(double now_s) {
    if (size_ == 0 || at(0).release_s > now_s) return std::nullopt;
    T out = at(0).msg;
    head_ = (head_ + 1) % Capacity;
    --size_;
    return out;
  }
  std::size_t size() const { return size_; }
  void clear() { head_ = size_ = 0; }

 private:
  struct Slot {
    double release_s = 0.0;
    T msg{};
  };
  Slot& at(std::size_t i) { return slots_[(head_ + i) % Capacity]; }
  std::array<Slot, Capacity> slots_{};
  std::size_t head_ = 0;
  std::size_t size_ = 0;
};

}  // namespace bbw::faults
