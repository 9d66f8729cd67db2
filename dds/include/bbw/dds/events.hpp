// One wake-up point per process: DDS listeners, the signal thread and timers notify it; the
// main loop waits on it for a condition with a deadline. Never a bare sleep.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
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

  // New data on a reader (its on_data_available, on the Fast DDS thread that delivered it). It is
  // first offered to the data hook, if one is set: a hook that returns true has used it and the
  // waiters are not woken (a lockstep corner runs its period on the receiving thread instead of
  // handing it to its main thread: one sleeping thread fewer per hop, docs/benchmarks.md).
  // Hook calls are serialised and never wait: Fast DDS calls on_data_available with its
  // reader's lock held, and a hook that takes from another reader while that reader's listener
  // waited here would deadlock; a busy hook wakes the waiters instead, who take the data.
  void data_arrived() {
    {
      std::unique_lock<std::mutex> lock(hook_mutex_, std::try_to_lock);
      if (lock.owns_lock() && hook_ && hook_()) return;
    }
    notify();
  }
  // Sets (or, with an empty function, clears) the data hook. Not from inside the hook.
  void set_data_hook(std::function<bool()> hook) {
    std::lock_guard<std::mutex> lock(hook_mutex_);
    hook_ = std::move(hook);
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
  std::mutex hook_mutex_;
  std::function<bool()> hook_;
};

}  // namespace bbw::dds
