// The transport seam: what a node's adapter sends and receives, whatever carries it.
// Two implementations: Fast DDS (bbw/dds/ports.hpp, the product) and in memory
// (bbw/transport/in_memory.hpp, tests and fast in-process runs). Node cores never see either:
// they take typed messages in and give typed messages out (docs/architecture.md).
#pragma once

#include <cstdint>

namespace bbw::transport {

// Who sent a message: an opaque id of the sending endpoint, stable for that endpoint's life
// (a restarted process is a new endpoint). 0 means unknown.
using EndpointId = std::uint64_t;

template <class T>
class Outlet {
 public:
  virtual ~Outlet() = default;
  // Hands one message to the transport. False when the transport refused it (counted by the
  // implementation).
  virtual bool send(const T& message) = 0;
  // Receiving endpoints currently matched (for start-up: wait until the peers are there).
  virtual int peers() const = 0;
};

template <class T>
class Inlet {
 public:
  virtual ~Inlet() = default;
  // Takes the oldest waiting message into `out` with the endpoint that sent it; false when
  // none waits. Never blocks.
  virtual bool take(T& out, EndpointId& from) = 0;
  bool take(T& out) {
    EndpointId ignored = 0;
    return take(out, ignored);
  }
  virtual int peers() const = 0;
};

}  // namespace bbw::transport
