#include "bbw/security/dds_security.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <filesystem>

namespace bbw::security {

namespace {

constexpr std::array<const char*, 4> kCornerNames{"FL", "FR", "RL", "RR"};

std::string upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string checked_corner_name(const std::string& name) {
  const std::string u = upper(name);
  for (const char* c : kCornerNames) {
    if (u == c) return u;
  }
  throw SecurityError("unknown corner '" + name + "': must be one of FL, FR, RL, RR");
}

std::string checked_corner_name(int id) {
  if (id < 0 || id >= static_cast<int>(kCornerNames.size())) {
    throw SecurityError("unknown corner id " + std::to_string(id) + ": must be in [0, 3]");
  }
  return kCornerNames[static_cast<std::size_t>(id)];
}

std::string existing_file(const std::filesystem::path& p, const std::string& keys_dir) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) {
    throw SecurityError("DDS Security file '" + p.string() + "' is missing (create the keys with: ./bbw keys " +
                        keys_dir + ")");
  }
  return std::filesystem::absolute(p).lexically_normal().string();
}

}  // namespace

std::string corner_identity(const std::string& corner_name) { return lower(checked_corner_name(corner_name)); }
std::string corner_identity(int corner_id) { return lower(checked_corner_name(corner_id)); }
std::string corner_partition(const std::string& corner_name) { return "corner_" + checked_corner_name(corner_name); }
std::string corner_partition(int corner_id) { return "corner_" + checked_corner_name(corner_id); }

SecurityFiles files_for(const std::string& keys_dir, const std::string& identity) {
  if (std::find(identities().begin(), identities().end(), identity) == identities().end()) {
    throw SecurityError("unknown identity '" + identity + "': must be one of ccu, ccu_standby, fl, fr, rl, rr");
  }
  if (keys_dir.empty()) throw SecurityError("no keys directory given (create one with: ./bbw keys DIR)");
  const std::filesystem::path dir(keys_dir);
  SecurityFiles f;
  f.identity_ca = existing_file(dir / "ca" / "ca.pem", keys_dir);
  f.identity_cert = existing_file(dir / identity / "cert.pem", keys_dir);
  f.private_key = existing_file(dir / identity / "key.pem", keys_dir);
  f.permissions_ca = f.identity_ca;
  f.governance = existing_file(dir / "governance.p7s", keys_dir);
  f.permissions = existing_file(dir / identity / "permissions.p7s", keys_dir);
  return f;
}

Properties participant_properties(const SecurityFiles& files) {
  const auto uri = [](const std::string& path) { return "file://" + path; };
  return {
      {"dds.sec.auth.plugin", "builtin.PKI-DH"},
      {"dds.sec.auth.builtin.PKI-DH.identity_ca", uri(files.identity_ca)},
      {"dds.sec.auth.builtin.PKI-DH.identity_certificate", uri(files.identity_cert)},
      {"dds.sec.auth.builtin.PKI-DH.private_key", uri(files.private_key)},
      {"dds.sec.access.plugin", "builtin.Access-Permissions"},
      {"dds.sec.access.builtin.Access-Permissions.permissions_ca", uri(files.permissions_ca)},
      {"dds.sec.access.builtin.Access-Permissions.governance", uri(files.governance)},
      {"dds.sec.access.builtin.Access-Permissions.permissions", uri(files.permissions)},
      {"dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC"},
  };
}

}  // namespace bbw::security
