// RAII owner of one DomainParticipant with its publisher, subscriber and topics.
//
// QoS comes from the XML profiles in config/dds/bbw_profiles.xml (or the file named by
// ParticipantOptions::profiles_file / env BBW_DDS_PROFILES). Constructors throw DdsError when
// an entity cannot be created; destructors release everything the object created.
#pragma once

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/ContentFilteredTopic.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "bbw/dds/run_id.hpp"

namespace bbw::dds {

class DdsError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Participant profile names in bbw_profiles.xml.
inline constexpr const char* kLocalhostProfile = "bbw_localhost";  // SHM + UDPv4 on 127.0.0.1
inline constexpr const char* kNetworkProfile = "bbw_network";      // explicit multi-host config

// The partition of a Writer / Reader (a named type so it cannot be confused with other
// arguments); empty: the participant's partition-less publisher / subscriber.
struct Partition {
  std::string name;
};

struct ParticipantOptions {
  int domain_id = 0;
  std::string profiles_file;            // empty: default_profiles_file()
  std::string profile = kLocalhostProfile;
  std::string name;                     // participant name seen in discovery, e.g. "bbw_corner_FL"
  // Extra participant properties appended to the profile's (e.g. DDS Security plugins, issue 7).
  std::vector<std::pair<std::string, std::string>> properties;
  // The run this participant belongs to (bbw/dds/run_id.hpp); announced in USER_DATA with the
  // process id, so that a participant of another bbw run on the same domain is noticed.
  std::uint64_t run_id = 0;
};

// A participant of another bbw run seen on this domain (its run id, pid and participant name).
using ForeignRun = PeerTag;

// env BBW_DDS_PROFILES if set, else the file in the source tree this binary was built from.
std::string default_profiles_file();

// Loads an XML profiles file into the factory once per process (idempotent per path).
// Throws DdsError naming the file when it is missing or malformed.
void load_profiles(const std::string& file);

class Participant : private eprosima::fastdds::dds::DomainParticipantListener {
 public:
  explicit Participant(const ParticipantOptions& options);
  ~Participant() override;
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  eprosima::fastdds::dds::DomainParticipant& get() { return *participant_; }
  eprosima::fastdds::dds::Publisher& publisher() { return *publisher_; }
  eprosima::fastdds::dds::Subscriber& subscriber() { return *subscriber_; }
  // A publisher / subscriber whose PartitionQosPolicy is exactly `partition` (created on first
  // use, owned by this participant); "" is the partition-less default one. DDS Security grants
  // each corner its measurements and health only in its own partition (docs/security.md).
  eprosima::fastdds::dds::Publisher& publisher(const std::string& partition);
  eprosima::fastdds::dds::Subscriber& subscriber(const std::string& partition);
  int domain_id() const { return domain_id_; }
  std::uint64_t run_id() const { return run_id_; }
  // Participants of other bbw runs discovered on this domain so far (one entry per process).
  std::vector<ForeignRun> foreign_runs() const;
  // The bbw tag a discovered participant announced, by its 12-byte GUID prefix (the first 12
  // bytes of any of its writers' handles); nullopt when it announced none. Not authenticated
  // without DDS Security: any participant can announce any tag.
  std::optional<PeerTag> peer_tag(const std::array<std::uint8_t, 12>& guid_prefix) const;

  // The topic `name` of type PubSubT (registered on first use), owned by this participant.
  template <class PubSubT>
  eprosima::fastdds::dds::Topic& topic(const std::string& name) {
    eprosima::fastdds::dds::TypeSupport type(new PubSubT());
    return topic_impl(name, type);
  }

  // A content-filtered view of `topic` (DDS-SQL expression, e.g. "corner_id = %0").
  eprosima::fastdds::dds::ContentFilteredTopic& filtered_topic(
      eprosima::fastdds::dds::Topic& topic, const std::string& name, const std::string& expression,
      const std::vector<std::string>& parameters);

 private:
  eprosima::fastdds::dds::Topic& topic_impl(const std::string& name,
                                            eprosima::fastdds::dds::TypeSupport type);

  void on_participant_discovery(eprosima::fastdds::dds::DomainParticipant* participant,
                                eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override;

  int domain_id_;
  std::uint64_t run_id_;
  mutable std::mutex foreign_mutex_;
  std::vector<ForeignRun> foreign_;
  std::map<std::array<std::uint8_t, 12>, PeerTag> peers_;
  eprosima::fastdds::dds::DomainParticipant* participant_ = nullptr;
  eprosima::fastdds::dds::Publisher* publisher_ = nullptr;
  eprosima::fastdds::dds::Subscriber* subscriber_ = nullptr;
  std::map<std::string, eprosima::fastdds::dds::Publisher*> partition_publishers_;
  std::map<std::string, eprosima::fastdds::dds::Subscriber*> partition_subscribers_;
  std::map<std::string, eprosima::fastdds::dds::Topic*> topics_;
  std::map<std::string, eprosima::fastdds::dds::ContentFilteredTopic*> filtered_;
};

}  // namespace bbw::dds
