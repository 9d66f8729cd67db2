// SIGINT/SIGTERM turned into a callback on a dedicated thread (sigwait), so a process's main
// loop is woken through its Events object instead of polling a flag.
//
// Construct it first thing in main(), before any other thread exists (Fast DDS starts threads),
// so every thread inherits the blocked mask and the signals reach only the watcher.
#pragma once

#include <pthread.h>

#include <atomic>
#include <functional>
#include <thread>

namespace bbw::runtime {

class SignalWatcher {
 public:
  explicit SignalWatcher(std::function<void(int)> on_signal);
  ~SignalWatcher();
  SignalWatcher(const SignalWatcher&) = delete;
  SignalWatcher& operator=(const SignalWatcher&) = delete;

  // The last signal received (0 if none).
  int received() const { return received_.load(); }

 private:
  std::function<void(int)> on_signal_;
  std::atomic<int> received_{0};
  std::atomic<bool> closing_{false};
  std::thread thread_;
};

}  // namespace bbw::runtime
