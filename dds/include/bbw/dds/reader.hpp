// RAII typed DataReader: created from an XML data_reader profile, deleted in the destructor.
// Data, matches and QoS events notify an Events object the owner waits on.
#pragma once

#include <fastdds/dds/core/status/StatusMask.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>

#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"

namespace bbw::dds {

// Optional content filter: only samples matching `expression` are delivered.
struct ContentFilter {
  std::string filtered_topic_name;  // unique per participant, e.g. "ClampCommand_FL"
  std::string expression;           // DDS-SQL, e.g. "corner_id = %0"
  std::vector<std::string> parameters;
};

// A QoS event with the instance (deadline) or writer (liveliness) it concerns, queued by the
// listener thread for the owner's main loop (per-corner fault detection, issue 5).
struct QosEvent {
  // WriterLost: a matched writer went away (its participant's discovery lease expired, or it
  // was deleted). In Fast DDS 2.9 on this machine the liveliness-lost callback of a killed
  // writer came late or never (docs/distributed.md), so the unmatch is the dependable signal.
  enum class Kind { DeadlineMissed, LivelinessLost, LivelinessRecovered, WriterLost };
  Kind kind = Kind::DeadlineMissed;
  // DeadlineMissed: the instance (key) that missed; otherwise the writer (publication handle).
  eprosima::fastrtps::rtps::InstanceHandle_t handle;
  std::chrono::steady_clock::time_point at;
};

template <class PubSubT>
class Reader : private eprosima::fastdds::dds::DataReaderListener {
 public:
  using Type = typename PubSubT::type;

  Reader(Participant& participant, const std::string& topic_name, const std::string& profile,
         Events& events, const ContentFilter* filter = nullptr)
      : Reader(participant, topic_name, profile, events, Partition{}, filter) {}

  // `partition`: read through the participant's subscriber in that partition (docs/security.md).
  Reader(Participant& participant, const std::string& topic_name, const std::string& profile,
         Events& events, const Partition& partition, const ContentFilter* filter = nullptr)
      : participant_(participant), subscriber_(participant.subscriber(partition.name)), events_(events) {
    auto& topic = participant.topic<PubSubT>(topic_name);
    eprosima::fastdds::dds::TopicDescription* description = &topic;
    if (filter != nullptr) {
      description = &participant.filtered_topic(topic, filter->filtered_topic_name,
                                                filter->expression, filter->parameters);
    }
    reader_ = subscriber_.create_datareader_with_profile(
        description, profile, this, eprosima::fastdds::dds::StatusMask::all());
    if (reader_ == nullptr) {
      throw DdsError("cannot create DataReader on topic '" + topic_name + "' with profile '" +
                     profile + "' (unknown profile or inconsistent QoS)");
    }
  }
  ~Reader() override {
    reader_->set_listener(nullptr);
    subscriber_.delete_datareader(reader_);
  }
  Reader(const Reader&) = delete;
  Reader& operator=(const Reader&) = delete;

  // Takes the next valid sample into `out`; false when none is waiting. Never blocks.
  bool take(Type& out) {
    eprosima::fastdds::dds::SampleInfo info;
    while (reader_->take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) {
        taken_.fetch_add(1);
        return true;
      }
    }
    return false;
  }

  // As take(), also returning the sample's info (instance and publication handles).
  bool take(Type& out, eprosima::fastdds::dds::SampleInfo& info) {
    while (reader_->take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) {
        taken_.fetch_add(1);
        return true;
      }
    }
    return false;
  }

  // The oldest queued QoS event; false when none. Events beyond the queue's capacity (64) are
  // dropped and counted (events_dropped()).
  bool take_event(QosEvent& out) {
    std::lock_guard<std::mutex> lock(event_mutex_);
    if (event_count_ == 0) return false;
    out = event_queue_[event_head_];
    event_head_ = (event_head_ + 1) % event_queue_.size();
    --event_count_;
    return true;
  }
  std::uint64_t events_dropped() const { return events_dropped_.load(); }

  int matched() const { return matched_.load(); }
  std::uint64_t taken() const { return taken_.load(); }
  std::uint64_t deadlines_missed() const { return deadlines_missed_.load(); }
  std::uint64_t liveliness_lost() const { return liveliness_lost_.load(); }  // alive -> not alive
  int alive_writers() const { return alive_writers_.load(); }
  std::uint64_t samples_lost() const { return samples_lost_.load(); }
  std::uint64_t samples_rejected() const { return samples_rejected_.load(); }
  std::uint64_t incompatible_qos() const { return incompatible_qos_.load(); }

  bool wait_for_matched(int n, std::chrono::steady_clock::duration timeout) {
    return events_.wait_for(timeout, [&] { return matched_.load() >= n; });
  }

  eprosima::fastdds::dds::DataReader& get() { return *reader_; }

 private:
  void on_data_available(eprosima::fastdds::dds::DataReader*) override { events_.data_arrived(); }
  void on_subscription_matched(eprosima::fastdds::dds::DataReader*,
                               const eprosima::fastdds::dds::SubscriptionMatchedStatus& s) override {
    matched_.store(s.current_count);
    if (s.current_count_change < 0) push_event(QosEvent::Kind::WriterLost, s.last_publication_handle);
    events_.notify();
  }
  void on_requested_deadline_missed(
      eprosima::fastdds::dds::DataReader*,
      const eprosima::fastdds::dds::RequestedDeadlineMissedStatus& s) override {
    deadlines_missed_.fetch_add(1);
    push_event(QosEvent::Kind::DeadlineMissed, s.last_instance_handle);
    events_.notify();
  }
  void on_liveliness_changed(eprosima::fastdds::dds::DataReader*,
                             const eprosima::fastdds::dds::LivelinessChangedStatus& s) override {
    alive_writers_.store(s.alive_count);
    if (s.not_alive_count_change > 0) {
      liveliness_lost_.fetch_add(static_cast<std::uint64_t>(s.not_alive_count_change));
      push_event(QosEvent::Kind::LivelinessLost, s.last_publication_handle);
    } else if (s.alive_count_change > 0) {
      push_event(QosEvent::Kind::LivelinessRecovered, s.last_publication_handle);
    }
    events_.notify();
  }
  void on_sample_lost(eprosima::fastdds::dds::DataReader*,
                      const eprosima::fastdds::dds::SampleLostStatus& s) override {
    samples_lost_.fetch_add(static_cast<std::uint64_t>(s.total_count_change));
    events_.notify();
  }
  void on_sample_rejected(eprosima::fastdds::dds::DataReader*,
                          const eprosima::fastdds::dds::SampleRejectedStatus& s) override {
    samples_rejected_.fetch_add(static_cast<std::uint64_t>(s.total_count_change));
    events_.notify();
  }
  void on_requested_incompatible_qos(
      eprosima::fastdds::dds::DataReader*,
      const eprosima::fastdds::dds::RequestedIncompatibleQosStatus&) override {
    incompatible_qos_.fetch_add(1);
    events_.notify();
  }

  void push_event(QosEvent::Kind kind, const eprosima::fastrtps::rtps::InstanceHandle_t& handle) {
    std::lock_guard<std::mutex> lock(event_mutex_);
    if (event_count_ == event_queue_.size()) {
      events_dropped_.fetch_add(1);
      return;
    }
    QosEvent& e = event_queue_[(event_head_ + event_count_) % event_queue_.size()];
    e.kind = kind;
    e.handle = handle;
    e.at = std::chrono::steady_clock::now();
    ++event_count_;
  }

  Participant& participant_;
  eprosima::fastdds::dds::Subscriber& subscriber_;
  Events& events_;
  std::mutex event_mutex_;
  std::array<QosEvent, 64> event_queue_{};
  std::size_t event_head_ = 0;
  std::size_t event_count_ = 0;
  std::atomic<std::uint64_t> events_dropped_{0};
  eprosima::fastdds::dds::DataReader* reader_ = nullptr;
  std::atomic<int> matched_{0};
  std::atomic<int> alive_writers_{0};
  std::atomic<std::uint64_t> taken_{0};
  std::atomic<std::uint64_t> deadlines_missed_{0};
  std::atomic<std::uint64_t> liveliness_lost_{0};
  std::atomic<std::uint64_t> samples_lost_{0};
  std::atomic<std::uint64_t> samples_rejected_{0};
  std::atomic<std::uint64_t> incompatible_qos_{0};
};

}  // namespace bbw::dds
