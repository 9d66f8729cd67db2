// The lockstep barrier: period k of a lockstep run is complete when every live participant has
// reported it done. Participants are any processes the scenario declares (corners today; the
// vehicle and pedal processes join the same way): each has a name and reports the last period it
// finished. A participant whose writer is gone (a dead process) no longer holds the barrier; one
// that reported a failure ends the wait. Pure, no clock: the adapter waits on its own events.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bbw::node {

class LockstepBarrier {
 public:
  // Adds a participant; returns its index. Names must be unique (throws std::invalid_argument).
  std::size_t add(const std::string& name);
  std::size_t size() const { return parts_.size(); }

  // The participant finished period `step` (monotone: an older or repeated step never moves it
  // back, so a forged or replayed number cannot make the barrier wait again).
  void done(std::size_t participant, std::uint64_t step);
  // A restarted participant: it joins at `step` (it has done nothing of it yet).
  void rejoin(std::size_t participant, std::uint64_t step);
  void set_alive(std::size_t participant, bool alive);
  void set_failed(std::size_t participant, bool failed);

  // Periods done so far (the next period the participant owes).
  std::uint64_t next(std::size_t participant) const { return parts_[participant].next; }
  bool alive(std::size_t participant) const { return parts_[participant].alive; }
  bool failed(std::size_t participant) const { return parts_[participant].failed; }
  // Every live participant has finished `step`, or one failed.
  bool complete(std::uint64_t step) const;
  bool any_failed() const;
  // The participants still owing `step` (live or not), comma-separated, for error messages.
  std::string lagging(std::uint64_t step) const;
  const std::string& name(std::size_t participant) const { return parts_[participant].name; }

 private:
  struct Part {
    std::string name;
    std::uint64_t next = 0;
    bool alive = true;
    bool failed = false;
  };
  std::vector<Part> parts_;
};

}  // namespace bbw::node
