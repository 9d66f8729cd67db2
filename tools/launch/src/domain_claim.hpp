// The DDS domain a run uses when none is given (no --domain, no BBW_DOMAIN): a free one.
//
// Rule (docs/distributed.md, "Runs on one host"): the launcher walks the domains
// kFreeDomainFirst..kFreeDomainLast, starting at an offset taken from its run id, and takes the
// first one that (1) no other bbw_launch holds (an flock on /tmp/bbw-domain-<d>.lock, held until
// this launcher exits, so two launchers never pick the same one) and (2) no DDS participant on
// this host uses (the UDP port of its participant 0, 7410 + 250 d, can be bound on 127.0.0.1).
// Runs stay isolated by their run id on any domain; the rule only keeps them apart as well.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace bbw::launch {

inline constexpr int kFreeDomainFirst = 100;
inline constexpr int kFreeDomainLast = 159;

// Holds the claim on one domain (its lock file) until destroyed.
class DomainClaim {
 public:
  DomainClaim() = default;
  ~DomainClaim();
  DomainClaim(DomainClaim&& other) noexcept;
  DomainClaim& operator=(DomainClaim&& other) noexcept;
  DomainClaim(const DomainClaim&) = delete;
  DomainClaim& operator=(const DomainClaim&) = delete;

  // Claims `domain` when nobody else holds its lock; nullopt otherwise.
  static std::optional<DomainClaim> try_claim(int domain);
  int domain() const { return domain_; }

 private:
  int domain_ = -1;
  int fd_ = -1;
};

// True when a process on this host has bound the UDP port of participant 0 of `domain`.
bool domain_port_in_use(int domain);

// The first free domain of the range by the rule above (throws std::runtime_error when none).
DomainClaim claim_free_domain(std::uint64_t run_id);

}  // namespace bbw::launch
