#include "bbw/dds/participant.hpp"

#include <bbw/idl/bbw_msgsTypeObject.h>
#include <bbw/idl/bbw_vehicle_msgsTypeObject.h>

#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>
#include <fastdds/dds/log/Log.hpp>
#include <fastdds/dds/publisher/qos/PublisherQos.hpp>
#include <fastdds/dds/subscriber/qos/SubscriberQos.hpp>

#include <unistd.h>

#include <cstdlib>
#include <iostream>
#include <filesystem>
#include <mutex>
#include <set>

#include "bbw/dds/run_id.hpp"

#include "bbw/common/data_path.hpp"

namespace bbw::dds {

namespace fdds = eprosima::fastdds::dds;

std::string default_profiles_file() {
  if (const char* env = std::getenv("BBW_DDS_PROFILES"); env != nullptr && *env != '\0') return env;
  return bbw::data::path("config/dds/bbw_profiles.xml");
}

void load_profiles(const std::string& file) {
  static std::mutex mutex;
  static std::set<std::string> loaded;
  std::lock_guard<std::mutex> lock(mutex);
  std::error_code ec;
  const std::string key = std::filesystem::weakly_canonical(file, ec).string();
  if (loaded.count(key) != 0) return;
  if (!std::filesystem::is_regular_file(file)) {
    throw DdsError("DDS profiles file '" + file + "' does not exist (set BBW_DDS_PROFILES or pass --dds-profiles)");
  }
  if (fdds::DomainParticipantFactory::get_instance()->load_XML_profiles_file(file) !=
      ReturnCode_t::RETCODE_OK) {
    throw DdsError("DDS profiles file '" + file + "' could not be parsed (see Fast DDS log above)");
  }
  loaded.insert(key);
}

Participant::Participant(const ParticipantOptions& options)
    : domain_id_(options.domain_id), run_id_(options.run_id) {
  auto* factory = fdds::DomainParticipantFactory::get_instance();
  // Diagnostics: env BBW_DDS_LOG=warning|info raises Fast DDS's log verbosity (errors only by
  // default; info messages exist only in Fast DDS builds with them compiled in).
  if (const char* log = std::getenv("BBW_DDS_LOG"); log != nullptr && *log != '\0') {
    const std::string level = log;
    fdds::Log::SetVerbosity(level == "info" ? fdds::Log::Kind::Info
                            : level == "warning" ? fdds::Log::Kind::Warning
                                                 : fdds::Log::Kind::Error);
  }
  // Content filters need the TypeObjects, which are otherwise registered only when a message
  // object is first constructed. Every process registers all of them, the vehicle's too, before
  // its participant exists: Fast DDS 2.9 builds a discovered writer's type from its TypeObject on a
  // receive thread (PDP::check_and_notify_type_discovery) and adds the identifiers it does not
  // know to the process's TypeObjectFactory, unguarded against the other threads doing the same.
  // A sequence type a process had not registered (a pedal message tried on 2026-11-26, in the
  // corners) crashed a corner in 3 of 12 vehicle runs (TypeIdentifier::_d under
  // TypeObjectFactory::get_sequence_identifier); registered here, 0 of 20. Known, they are only
  // looked up.
  registerbbw_msgsTypes();
  registerbbw_vehicle_msgsTypes();
  const std::string file = options.profiles_file.empty() ? default_profiles_file() : options.profiles_file;
  load_profiles(file);

  // QoS read from the named profile (never from PARTICIPANT_QOS_DEFAULT, which ignores XML).
  fdds::DomainParticipantQos qos;
  if (factory->get_participant_qos_from_profile(options.profile, qos) != ReturnCode_t::RETCODE_OK) {
    throw DdsError("participant profile '" + options.profile + "' not found in " + file);
  }
  if (!options.name.empty()) qos.name(options.name);
  for (const auto& [key, value] : options.properties) {
    qos.properties().properties().emplace_back(key, value);
  }
  {
    const std::string tag = encode_peer_tag({options.run_id, static_cast<long>(::getpid()), qos.name().to_string()});
    qos.user_data().setValue(std::vector<eprosima::fastrtps::rtps::octet>(tag.begin(), tag.end()));
  }
  // The listener only sees participant discovery (no status callback is routed here).
  participant_ = factory->create_participant(options.domain_id, qos, this, fdds::StatusMask::none());
  if (participant_ == nullptr) {
    throw DdsError("cannot create DomainParticipant on domain " + std::to_string(options.domain_id) +
                   " with profile '" + options.profile + "'");
  }
  publisher_ = participant_->create_publisher(fdds::PUBLISHER_QOS_DEFAULT);
  subscriber_ = participant_->create_subscriber(fdds::SUBSCRIBER_QOS_DEFAULT);
  if (publisher_ == nullptr || subscriber_ == nullptr) {
    participant_->delete_contained_entities();
    factory->delete_participant(participant_);
    throw DdsError("cannot create publisher/subscriber on domain " + std::to_string(options.domain_id));
  }
}

Participant::~Participant() {
  participant_->set_listener(nullptr);
  // Writers and readers are owned (and deleted) by their RAII wrappers, which must not outlive
  // this object; delete_contained_entities() releases whatever remains.
  participant_->delete_contained_entities();
  fdds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
}

void Participant::on_participant_discovery(fdds::DomainParticipant* /*participant*/,
                                           eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) {
  if (info.status != eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) return;
  const auto& data = info.info.m_userData.data_vec();
  const auto tag = decode_peer_tag(std::string(data.begin(), data.end()));
  if (!tag) return;
  {
    std::array<std::uint8_t, 12> prefix{};
    for (std::size_t i = 0; i < prefix.size(); ++i) prefix[i] = info.info.m_guid.guidPrefix.value[i];
    std::lock_guard<std::mutex> lock(foreign_mutex_);
    peers_[prefix] = *tag;
  }
  if (tag->run_id == run_id_) return;
  {
    std::lock_guard<std::mutex> lock(foreign_mutex_);
    for (const auto& f : foreign_) {
      if (f.run_id == tag->run_id && f.pid == tag->pid && f.name == tag->name) return;
    }
    foreign_.push_back({tag->run_id, tag->pid, tag->name});
  }
  std::cerr << "another bbw run (run id " << run_id_hex(tag->run_id) << ", pid " << tag->pid << ", " << tag->name
            << ") is on domain " << domain_id_ << "; run ids keep the two apart (this run: " << run_id_hex(run_id_)
            << ")" << std::endl;
}

std::optional<PeerTag> Participant::peer_tag(const std::array<std::uint8_t, 12>& guid_prefix) const {
  std::lock_guard<std::mutex> lock(foreign_mutex_);
  const auto it = peers_.find(guid_prefix);
  if (it == peers_.end()) return std::nullopt;
  return it->second;
}

std::vector<ForeignRun> Participant::foreign_runs() const {
  std::lock_guard<std::mutex> lock(foreign_mutex_);
  return foreign_;
}

fdds::Publisher& Participant::publisher(const std::string& partition) {
  if (partition.empty()) return *publisher_;
  if (auto it = partition_publishers_.find(partition); it != partition_publishers_.end()) return *it->second;
  fdds::PublisherQos qos = fdds::PUBLISHER_QOS_DEFAULT;
  qos.partition().push_back(partition.c_str());
  fdds::Publisher* pub = participant_->create_publisher(qos);
  if (pub == nullptr) throw DdsError("cannot create publisher in partition '" + partition + "'");
  partition_publishers_.emplace(partition, pub);
  return *pub;
}

fdds::Subscriber& Participant::subscriber(const std::string& partition) {
  if (partition.empty()) return *subscriber_;
  if (auto it = partition_subscribers_.find(partition); it != partition_subscribers_.end()) return *it->second;
  fdds::SubscriberQos qos = fdds::SUBSCRIBER_QOS_DEFAULT;
  qos.partition().push_back(partition.c_str());
  fdds::Subscriber* sub = participant_->create_subscriber(qos);
  if (sub == nullptr) throw DdsError("cannot create subscriber in partition '" + partition + "'");
  partition_subscribers_.emplace(partition, sub);
  return *sub;
}

fdds::Topic& Participant::topic_impl(const std::string& name, fdds::TypeSupport type) {
  if (auto it = topics_.find(name); it != topics_.end()) {
    if (it->second->get_type_name() != type.get_type_name()) {
      throw DdsError("topic '" + name + "' already exists with type " + it->second->get_type_name());
    }
    return *it->second;
  }
  if (participant_->find_type(type.get_type_name()).empty()) {
    if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
      throw DdsError("cannot register type " + type.get_type_name());
    }
  }
  fdds::Topic* topic = participant_->create_topic(name, type.get_type_name(), fdds::TOPIC_QOS_DEFAULT);
  if (topic == nullptr) throw DdsError("cannot create topic '" + name + "'");
  topics_.emplace(name, topic);
  return *topic;
}

fdds::ContentFilteredTopic& Participant::filtered_topic(fdds::Topic& topic, const std::string& name,
                                                        const std::string& expression,
                                                        const std::vector<std::string>& parameters) {
  if (auto it = filtered_.find(name); it != filtered_.end()) return *it->second;
  fdds::ContentFilteredTopic* cft =
      participant_->create_contentfilteredtopic(name, &topic, expression, parameters);
  if (cft == nullptr) {
    throw DdsError("cannot create content-filtered topic '" + name + "' with '" + expression + "'");
  }
  filtered_.emplace(name, cft);
  return *cft;
}

}  // namespace bbw::dds
