#include "bbw/runtime/signals.hpp"

#include <signal.h>

#include <stdexcept>

namespace bbw::runtime {

namespace {
sigset_t watched() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGUSR2);  // internal: wakes the watcher when it is destroyed
  return set;
}
}  // namespace

SignalWatcher::SignalWatcher(std::function<void(int)> on_signal) : on_signal_(std::move(on_signal)) {
  const sigset_t set = watched();
  if (pthread_sigmask(SIG_BLOCK, &set, nullptr) != 0) {
    throw std::runtime_error("cannot block SIGINT/SIGTERM");
  }
  thread_ = std::thread([this] {
    const sigset_t s = watched();
    for (;;) {
      int sig = 0;
      if (sigwait(&s, &sig) != 0) continue;
      if (closing_.load()) return;
      if (sig == SIGUSR2) continue;
      received_.store(sig);
      on_signal_(sig);
    }
  });
}

SignalWatcher::~SignalWatcher() {
  closing_.store(true);
  pthread_kill(thread_.native_handle(), SIGUSR2);
  thread_.join();
}

}  // namespace bbw::runtime
