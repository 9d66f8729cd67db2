// Test-side DataWriter/DataReader in one partition (own Publisher/Subscriber with a
// PartitionQosPolicy), created on a bbw::dds::Participant from its XML profiles. The permissions
// documents grant corner <C> its measurement and health topics only in partition corner_<C>;
// bbw_dds's Writer/Reader use the participant's partition-less publisher, so these fill the gap.
#pragma once

#include <fastdds/dds/core/status/StatusMask.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>

#include <atomic>
#include <string>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"

namespace bbw::test {

namespace fdds = eprosima::fastdds::dds;

// Null writer_ when access control (or anything else) refused the DataWriter.
template <class PubSubT>
class PartitionWriter : private fdds::DataWriterListener {
 public:
  PartitionWriter(bbw::dds::Participant& p, const std::string& topic_name, const std::string& profile,
                  const std::string& partition, bbw::dds::Events& events)
      : participant_(p), events_(events) {
    fdds::PublisherQos qos = fdds::PUBLISHER_QOS_DEFAULT;
    if (!partition.empty()) qos.partition().push_back(partition.c_str());
    publisher_ = p.get().create_publisher(qos);
    if (publisher_ == nullptr) throw bbw::dds::DdsError("cannot create publisher in partition " + partition);
    auto& topic = p.topic<PubSubT>(topic_name);
    writer_ = publisher_->create_datawriter_with_profile(&topic, profile, this, fdds::StatusMask::all());
  }
  ~PartitionWriter() override {
    if (writer_ != nullptr) {
      writer_->set_listener(nullptr);
      publisher_->delete_datawriter(writer_);
    }
    participant_.get().delete_publisher(publisher_);
  }
  PartitionWriter(const PartitionWriter&) = delete;
  PartitionWriter& operator=(const PartitionWriter&) = delete;

  bool created() const { return writer_ != nullptr; }
  int matched() const { return matched_.load(); }
  bool write(const typename PubSubT::type& sample) {
    return writer_ != nullptr && writer_->write(const_cast<typename PubSubT::type*>(&sample));
  }

 private:
  void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& s) override {
    matched_.store(s.current_count);
    events_.notify();
  }
  bbw::dds::Participant& participant_;
  bbw::dds::Events& events_;
  fdds::Publisher* publisher_ = nullptr;
  fdds::DataWriter* writer_ = nullptr;
  std::atomic<int> matched_{0};
};

template <class PubSubT>
class PartitionReader : private fdds::DataReaderListener {
 public:
  PartitionReader(bbw::dds::Participant& p, const std::string& topic_name, const std::string& profile,
                  const std::string& partition, bbw::dds::Events& events)
      : participant_(p), events_(events) {
    fdds::SubscriberQos qos = fdds::SUBSCRIBER_QOS_DEFAULT;
    if (!partition.empty()) qos.partition().push_back(partition.c_str());
    subscriber_ = p.get().create_subscriber(qos);
    if (subscriber_ == nullptr) throw bbw::dds::DdsError("cannot create subscriber in partition " + partition);
    auto& topic = p.topic<PubSubT>(topic_name);
    reader_ = subscriber_->create_datareader_with_profile(&topic, profile, this, fdds::StatusMask::all());
  }
  ~PartitionReader() override {
    if (reader_ != nullptr) {
      reader_->set_listener(nullptr);
      subscriber_->delete_datareader(reader_);
    }
    participant_.get().delete_subscriber(subscriber_);
  }
  PartitionReader(const PartitionReader&) = delete;
  PartitionReader& operator=(const PartitionReader&) = delete;

  bool created() const { return reader_ != nullptr; }
  int matched() const { return matched_.load(); }
  bool take(typename PubSubT::type& out) {
    fdds::SampleInfo info;
    while (reader_ != nullptr && reader_->take_next_sample(&out, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) return true;
    }
    return false;
  }

 private:
  void on_data_available(fdds::DataReader*) override { events_.notify(); }
  void on_subscription_matched(fdds::DataReader*, const fdds::SubscriptionMatchedStatus& s) override {
    matched_.store(s.current_count);
    events_.notify();
  }
  bbw::dds::Participant& participant_;
  bbw::dds::Events& events_;
  fdds::Subscriber* subscriber_ = nullptr;
  fdds::DataReader* reader_ = nullptr;
  std::atomic<int> matched_{0};
};

}  // namespace bbw::test
