// Lockstep on the receiving thread (docs/benchmarks.md, "Node cores and transports"): a lockstep
// participant's periods run on the Fast DDS thread that delivers the input completing them (a
// corner's grant, the CCU's last block, the vehicle's last block, the pedal's grant) instead of
// being handed to the process's main thread: one sleeping thread fewer per hop. The main thread
// waits meanwhile and takes over for whatever is not the plain run of periods (the end, a stop,
// a lost peer, a failure) or when no period completes for `stall` (its own loop then re-sends,
// times out and reports as before).
#pragma once

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <functional>
#include <mutex>
#include <string>

#include "bbw/dds/events.hpp"

namespace bbw::dds {

// On unless the environment sets BBW_LOCKSTEP_ON_RECEIVE=0 (every period on the main thread: the
// loop before this change, for comparisons; the logs are the same bytes either way).
inline bool lockstep_on_receive() {
  const char* e = std::getenv("BBW_LOCKSTEP_ON_RECEIVE");
  return !(e != nullptr && std::string(e) == "0");
}

enum class ReceiveRunEnd {
  HandedBack,   // advance() returned true: the caller's loop carries on
  Stalled,      // no progress for `stall`: the caller's loop carries on (and re-sends, times out)
  Interrupted,  // events.interrupt()
};

// `advance` runs every period its inputs allow and returns true when the caller must take over;
// `progress` counts the periods completed. Both are called with one lock held, from a receiving
// thread (through the Events data hook, which never waits for the lock) or from this thread.
inline ReceiveRunEnd run_on_receive(Events& events, const std::function<bool()>& advance,
                                    const std::function<std::uint64_t()>& progress,
                                    std::chrono::milliseconds stall = std::chrono::milliseconds(200)) {
  std::mutex mutex;
  bool handed_back = false;
  auto step = [&] {
    if (!handed_back) handed_back = advance();
    return handed_back;
  };
  std::uint64_t seen = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    step();
    seen = progress();
  }
  events.set_data_hook([&] {
    std::unique_lock<std::mutex> lock(mutex, std::try_to_lock);
    if (!lock.owns_lock() || handed_back) return false;  // this thread's loop takes the data
    return !step();
  });
  ReceiveRunEnd end = ReceiveRunEnd::HandedBack;
  for (;;) {
    // Woken by what is not data (matches, QoS events, a signal), by data the hook left, or
    // after `stall`.
    if (events.wait_for(stall, [&] {
          std::lock_guard<std::mutex> lock(mutex);
          return step();
        })) {
      break;
    }
    if (events.interrupted()) {
      end = ReceiveRunEnd::Interrupted;
      break;
    }
    std::lock_guard<std::mutex> lock(mutex);
    const std::uint64_t now = progress();
    if (now == seen) {
      end = ReceiveRunEnd::Stalled;
      break;
    }
    seen = now;
  }
  events.set_data_hook({});  // waits for a hook call in progress: none runs after this
  return end;
}

}  // namespace bbw::dds
