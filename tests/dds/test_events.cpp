// dds::Events' data hook (lockstep periods run on the Fast DDS thread that receives their input,
// docs/benchmarks.md): a hook that uses the data keeps the waiters asleep, one that does not wakes
// them, and a busy hook never makes a second receiving thread wait (Fast DDS calls
// on_data_available with its reader's lock held: waiting there could deadlock).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

#include "bbw/dds/events.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::dds::Events;

// A waiter that counts how often its predicate is evaluated (once per wake-up with news).
struct Waiter {
  Events& events;
  std::atomic<int> evaluations{0};
  std::atomic<bool> done{false};
  std::thread thread;
  explicit Waiter(Events& e) : events(e) {
    thread = std::thread([this] {
      events.wait_for(30s, [this] {
        evaluations.fetch_add(1);
        return done.load();
      });
    });
    while (evaluations.load() == 0) std::this_thread::yield();  // it has evaluated once and sleeps
  }
  void finish() {
    done.store(true);
    events.notify();
    thread.join();
  }
};

TEST(EventsDataHook, WithoutAHookDataWakesTheWaiters) {
  Events events;
  Waiter w(events);
  events.data_arrived();
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (w.evaluations.load() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  EXPECT_GE(w.evaluations.load(), 2);
  w.finish();
}

TEST(EventsDataHook, AHookThatUsesTheDataKeepsTheWaitersAsleepAndOneThatDoesNotWakesThem) {
  Events events;
  std::atomic<int> hook_calls{0};
  std::atomic<bool> use{true};
  events.set_data_hook([&] {
    hook_calls.fetch_add(1);
    return use.load();
  });
  Waiter w(events);
  for (int i = 0; i < 100; ++i) events.data_arrived();
  EXPECT_EQ(hook_calls.load(), 100);
  EXPECT_EQ(w.evaluations.load(), 1) << "a used arrival woke the waiter";
  use.store(false);
  events.data_arrived();
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (w.evaluations.load() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  EXPECT_EQ(w.evaluations.load(), 2);
  // Cleared: data wakes the waiters again and the hook is not called.
  events.set_data_hook({});
  events.data_arrived();
  EXPECT_EQ(hook_calls.load(), 101);
  w.finish();
}

TEST(EventsDataHook, ABusyHookDoesNotMakeASecondArrivalWait) {
  Events events;
  std::promise<void> entered, release;
  std::shared_future<void> released = release.get_future().share();
  std::atomic<int> hook_calls{0};
  events.set_data_hook([&] {
    if (hook_calls.fetch_add(1) == 0) {
      entered.set_value();
      released.wait();  // the first receiving thread stays inside the hook
    }
    return true;
  });
  Waiter w(events);
  auto first = std::async(std::launch::async, [&] { events.data_arrived(); });
  entered.get_future().wait();
  // A second receiving thread: returns at once and wakes the waiters instead of using the hook.
  auto second = std::async(std::launch::async, [&] { events.data_arrived(); });
  EXPECT_EQ(second.wait_for(10s), std::future_status::ready) << "a second arrival waited for a busy hook";
  EXPECT_EQ(hook_calls.load(), 1);
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while (w.evaluations.load() < 2 && std::chrono::steady_clock::now() < deadline) std::this_thread::yield();
  EXPECT_EQ(w.evaluations.load(), 2);
  release.set_value();
  first.wait();
  w.finish();
}

}  // namespace
