// One wake-up point per process: DDS listeners, the signal thread and timers notify it; the
// main loop waits on it for a condition with a deadline. Never a bare sleep.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <mutex>

namespace bbw::dds {

class Events {
 public:
  using Clock = std::chrono::steady_clock;

  // Something happened (data, match, QoS event). Cheap; callable from any thread.
  void notify() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      ++generation_;
    }
    cv_.notify_all();
  }

  // Requests a stop (signal, fatal error): every wait returns at once from now on.
  void interrupt() {
    interrupted_.store(true);
    notify();
  }
  bool interrupted() const { return interrupted_.load(); }

  // Waits until pred() holds, the deadline passes or interrupt() was called. pred() is
  // evaluated without the internal lock held, so it may call into DDS. Returns pred().
  template <class Pred>
  bool wait_until(Clock::time_point deadline, Pred pred) {
    for (;;) {
      std::uint64_t seen;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        seen = generation_;
      }
      if (pred()) return true;
      if (interrupted() || Clock::now() >= deadline) return false;
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait_until(lock, deadline, [&] { return generation_ != seen; });
    }
  }

  template <class Pred, class Rep, class Period>
  bool wait_for(std::chrono::duration<Rep, Period> timeout, Pred pred) {
    return wait_until(Clock::now() + std::chrono::duration_cast<Clock::duration>(timeout), pred);
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  std::uint64_t generation_ = 0;
  std::atomic<bool> interrupted_{false};
};

}  // namespace bbw::dds
