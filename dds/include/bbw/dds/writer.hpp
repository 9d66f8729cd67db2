// RAII typed DataWriter: created from an XML data_writer profile, deleted in the destructor.
#pragma once

#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>

#include <atomic>
#include <chrono>
#include <string>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"

namespace bbw::dds {

template <class PubSubT>
class Writer : private eprosima::fastdds::dds::DataWriterListener {
 public:
  using Type = typename PubSubT::type;

  // `events` (must outlive the writer) is notified on matches and QoS events.
  // `partition`: write through the participant's publisher in that partition (docs/security.md).
  Writer(Participant& participant, const std::string& topic_name, const std::string& profile,
         Events& events, const Partition& partition = {})
      : participant_(participant), publisher_(participant.publisher(partition.name)), events_(events) {
    auto& topic = participant.topic<PubSubT>(topic_name);
    writer_ = publisher_.create_datawriter_with_profile(
        &topic, profile, this, eprosima::fastdds::dds::StatusMask::all());
    if (writer_ == nullptr) {
      throw DdsError("cannot create DataWriter on topic '" + topic_name + "' with profile '" +
                     profile + "' (unknown profile or inconsistent QoS)");
    }
  }
  ~Writer() override {
    writer_->set_listener(nullptr);
    publisher_.delete_datawriter(writer_);
  }
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Publishes one sample. Returns false when Fast DDS refused it (e.g. reliable history full
  // past max_blocking_time); the failure is counted.
  bool write(const Type& sample) {
    if (writer_->write(const_cast<Type*>(&sample))) return true;
    write_failures_.fetch_add(1);
    return false;
  }

  int matched() const { return matched_.load(); }
  std::uint64_t write_failures() const { return write_failures_.load(); }
  std::uint64_t deadlines_missed() const { return deadlines_missed_.load(); }
  std::uint64_t liveliness_lost() const { return liveliness_lost_.load(); }
  std::uint64_t incompatible_qos() const { return incompatible_qos_.load(); }

  // Waits (on a condition variable) until at least `n` readers are matched.
  bool wait_for_matched(int n, std::chrono::steady_clock::duration timeout) {
    return events_.wait_for(timeout, [&] { return matched_.load() >= n; });
  }

  eprosima::fastdds::dds::DataWriter& get() { return *writer_; }

 private:
  void wake() { events_.notify(); }
  void on_publication_matched(eprosima::fastdds::dds::DataWriter*,
                              const eprosima::fastdds::dds::PublicationMatchedStatus& s) override {
    matched_.store(s.current_count);
    wake();
  }
  void on_offered_deadline_missed(eprosima::fastdds::dds::DataWriter*,
                                  const eprosima::fastdds::dds::OfferedDeadlineMissedStatus&) override {
    deadlines_missed_.fetch_add(1);
    wake();
  }
  void on_liveliness_lost(eprosima::fastdds::dds::DataWriter*,
                          const eprosima::fastdds::dds::LivelinessLostStatus&) override {
    liveliness_lost_.fetch_add(1);
    wake();
  }
  void on_offered_incompatible_qos(eprosima::fastdds::dds::DataWriter*,
                                   const eprosima::fastdds::dds::OfferedIncompatibleQosStatus&) override {
    incompatible_qos_.fetch_add(1);
    wake();
  }

  Participant& participant_;
  eprosima::fastdds::dds::Publisher& publisher_;
  Events& events_;
  eprosima::fastdds::dds::DataWriter* writer_ = nullptr;
  std::atomic<int> matched_{0};
  std::atomic<std::uint64_t> write_failures_{0};
  std::atomic<std::uint64_t> deadlines_missed_{0};
  std::atomic<std::uint64_t> liveliness_lost_{0};
  std::atomic<std::uint64_t> incompatible_qos_{0};
};

}  // namespace bbw::dds
