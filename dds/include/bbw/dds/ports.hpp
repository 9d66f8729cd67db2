// The Fast DDS implementation of the transport seam (bbw/transport/ports.hpp): an Outlet is a
// DataWriter, an Inlet a DataReader; the sender's id is its publication handle folded to 64 bits.
// The process adapters (bbw_ccu, bbw_corner) hold these and reach the DDS specifics (QoS events,
// liveliness, acknowledgements) through get().
#pragma once

#include <cstdint>
#include <string>

#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/transport/ports.hpp"

namespace bbw::dds {

// A publication or instance handle as one 64-bit id (FNV-1a over its 16 bytes); 0 is kept for
// "unknown", so a handle that folds to 0 becomes 1.
inline transport::EndpointId endpoint_id(const eprosima::fastrtps::rtps::InstanceHandle_t& h) {
  std::uint64_t x = 1469598103934665603ULL;
  for (std::size_t i = 0; i < 16; ++i) {
    x ^= static_cast<std::uint8_t>(h.value[i]);
    x *= 1099511628211ULL;
  }
  return x == 0 ? 1 : x;
}

template <class PubSubT>
class DdsOutlet final : public transport::Outlet<typename PubSubT::type> {
 public:
  template <class... Args>
  explicit DdsOutlet(Args&&... args) : writer_(std::forward<Args>(args)...) {}
  bool send(const typename PubSubT::type& m) override { return writer_.write(m); }
  int peers() const override { return writer_.matched(); }
  Writer<PubSubT>& get() { return writer_; }
  const Writer<PubSubT>& get() const { return writer_; }

 private:
  Writer<PubSubT> writer_;
};

template <class PubSubT>
class DdsInlet final : public transport::Inlet<typename PubSubT::type> {
 public:
  template <class... Args>
  explicit DdsInlet(Args&&... args) : reader_(std::forward<Args>(args)...) {}
  using transport::Inlet<typename PubSubT::type>::take;
  bool take(typename PubSubT::type& out, transport::EndpointId& from) override {
    if (!reader_.take(out, info_)) return false;
    from = endpoint_id(info_.publication_handle);
    return true;
  }
  int peers() const override { return reader_.matched(); }
  // The info of the last sample taken (instance handle: the corner's key instance).
  const eprosima::fastdds::dds::SampleInfo& last_info() const { return info_; }
  Reader<PubSubT>& get() { return reader_; }
  const Reader<PubSubT>& get() const { return reader_; }

 private:
  Reader<PubSubT> reader_;
  eprosima::fastdds::dds::SampleInfo info_;
};

}  // namespace bbw::dds
