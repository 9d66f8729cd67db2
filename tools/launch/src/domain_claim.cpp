#include "domain_claim.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <unistd.h>

#include <stdexcept>
#include <utility>

namespace bbw::launch {

DomainClaim::~DomainClaim() {
  if (fd_ >= 0) ::close(fd_);  // releases the lock
}

DomainClaim::DomainClaim(DomainClaim&& other) noexcept
    : domain_(std::exchange(other.domain_, -1)), fd_(std::exchange(other.fd_, -1)) {}

DomainClaim& DomainClaim::operator=(DomainClaim&& other) noexcept {
  if (this != &other) {
    if (fd_ >= 0) ::close(fd_);
    domain_ = std::exchange(other.domain_, -1);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

std::optional<DomainClaim> DomainClaim::try_claim(int domain) {
  const std::string file = "/tmp/bbw-domain-" + std::to_string(domain) + ".lock";
  const int fd = ::open(file.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
  if (fd < 0) return std::nullopt;
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    ::close(fd);
    return std::nullopt;
  }
  DomainClaim c;
  c.domain_ = domain;
  c.fd_ = fd;
  return c;
}

bool domain_port_in_use(int domain) {
  const int s = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (s < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(7410 + 250 * domain));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool in_use = ::bind(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0;
  ::close(s);
  return in_use;
}

DomainClaim claim_free_domain(std::uint64_t run_id) {
  const int n = kFreeDomainLast - kFreeDomainFirst + 1;
  const int offset = static_cast<int>(run_id % static_cast<std::uint64_t>(n));
  for (int i = 0; i < n; ++i) {
    const int d = kFreeDomainFirst + (offset + i) % n;
    auto claim = DomainClaim::try_claim(d);
    if (!claim) continue;
    if (domain_port_in_use(d)) continue;  // the claim is released when `claim` goes
    return std::move(*claim);
  }
  throw std::runtime_error("no free DDS domain in " + std::to_string(kFreeDomainFirst) + ".." +
                           std::to_string(kFreeDomainLast) + " (give one with --domain N)");
}

}  // namespace bbw::launch
