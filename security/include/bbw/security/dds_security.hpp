// DDS Security settings for bbw processes: identities, the files `./bbw keys DIR` writes, the
// participant properties that enable Fast DDS 2.9's builtin plugins (PKI-DH authentication,
// Access-Permissions access control, AES-GCM-GMAC cryptography), and the per-corner partitions
// the permissions documents grant. See docs/security.md.
#pragma once

#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace bbw::security {

class SecurityError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Identities `./bbw keys` issues, one per process.
inline constexpr const char* kCcuIdentity = "ccu";
// The hot-standby CCU (issue 16): its own identity, with the CCU's permissions.
inline constexpr const char* kCcuStandbyIdentity = "ccu_standby";
inline const std::vector<std::string>& identities() {  // ccu, ccu_standby, fl, fr, rl, rr
  static const std::vector<std::string> ids{"ccu", "ccu_standby", "fl", "fr", "rl", "rr"};
  return ids;
}

// Partitions in the permissions documents: corner <C> may publish measurements and health only
// in partition "corner_<C>" (e.g. corner_FL); the CCU subscribes to "corner_*".
inline constexpr const char* kCornerPartitionPattern = "corner_*";

// The identity of a corner by its name (FL, FR, RL, RR, any case) or id (0..3); throws
// SecurityError naming the value otherwise.
std::string corner_identity(const std::string& corner_name);
std::string corner_identity(int corner_id);
// "corner_FL" for corner FL / id 0.
std::string corner_partition(const std::string& corner_name);
std::string corner_partition(int corner_id);

// Absolute paths of one identity's files under a keys directory.
struct SecurityFiles {
  std::string identity_ca;     // DIR/ca/ca.pem: CA that signs identities
  std::string identity_cert;   // DIR/<id>/cert.pem
  std::string private_key;     // DIR/<id>/key.pem
  std::string permissions_ca;  // DIR/ca/ca.pem: CA that signs governance and permissions
  std::string governance;      // DIR/governance.p7s
  std::string permissions;     // DIR/<id>/permissions.p7s
};

// The files of `identity` under `keys_dir` (as written by `./bbw keys keys_dir`). Throws
// SecurityError naming the first missing file and how to create it.
SecurityFiles files_for(const std::string& keys_dir, const std::string& identity);

using Properties = std::vector<std::pair<std::string, std::string>>;

// Participant properties enabling authentication, access control and encryption with `files`
// (dds.sec.auth.plugin = builtin.PKI-DH, ...). Paths become file:// URIs.
Properties participant_properties(const SecurityFiles& files);

}  // namespace bbw::security
