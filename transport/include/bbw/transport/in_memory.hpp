// The in-memory transport: topics as queues in one process. A message sent on a topic is
// copied to every inlet attached to it (reliable, in order, no loss, no delay). Used by the
// in-process lockstep runner (bbw/node/in_process.hpp) and the closed-loop tests, so they run
// the same node cores as the DDS processes. Single-threaded: no locks.
#pragma once

#include <cstddef>
#include <deque>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bbw/transport/ports.hpp"

namespace bbw::transport {

template <class T>
class InMemoryTopic {
 public:
  class Sender final : public Outlet<T> {
   public:
    Sender(InMemoryTopic& topic, EndpointId id) : topic_(topic), id_(id) {}
    bool send(const T& message) override {
      for (auto* in : topic_.inlets_) in->queue_.emplace_back(message, id_);
      ++topic_.sent_;
      return true;
    }
    int peers() const override { return static_cast<int>(topic_.inlets_.size()); }

   private:
    InMemoryTopic& topic_;
    EndpointId id_;
  };

  class Receiver final : public Inlet<T> {
   public:
    explicit Receiver(InMemoryTopic& topic) : topic_(topic) { topic_.inlets_.push_back(this); }
    ~Receiver() override { std::erase(topic_.inlets_, this); }
    Receiver(const Receiver&) = delete;
    Receiver& operator=(const Receiver&) = delete;
    using Inlet<T>::take;
    bool take(T& out, EndpointId& from) override {
      if (queue_.empty()) return false;
      out = std::move(queue_.front().first);
      from = queue_.front().second;
      queue_.pop_front();
      return true;
    }
    int peers() const override { return static_cast<int>(topic_.senders_); }
    std::size_t waiting() const { return queue_.size(); }

   private:
    friend class Sender;
    InMemoryTopic& topic_;
    std::deque<std::pair<T, EndpointId>> queue_;
  };

  explicit InMemoryTopic(std::string name) : name_(std::move(name)) {}
  InMemoryTopic(const InMemoryTopic&) = delete;
  InMemoryTopic& operator=(const InMemoryTopic&) = delete;

  // Endpoint ids are 1, 2, ... in order of creation over every topic of one bus (next_id).
  std::unique_ptr<Sender> sender(EndpointId id) {
    ++senders_;
    return std::make_unique<Sender>(*this, id);
  }
  std::unique_ptr<Receiver> receiver() { return std::make_unique<Receiver>(*this); }
  const std::string& name() const { return name_; }
  std::size_t sent() const { return sent_; }

 private:
  std::string name_;
  std::vector<Receiver*> inlets_;
  std::size_t senders_ = 0;
  std::size_t sent_ = 0;
};

}  // namespace bbw::transport
