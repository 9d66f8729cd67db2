// DDS domain id selection: --domain N on the command line, else env BBW_DOMAIN, else 0.
#pragma once

#include <optional>
#include <string>

namespace bbw::dds {

// Fast DDS 2.9 computes ports as 7400 + 250 d + ...; ids above 232 overflow the port range.
inline constexpr int kMaxDomainId = 232;

// Parses a domain id; throws std::invalid_argument naming `origin` (e.g. "--domain") and the rule.
int parse_domain_id(const std::string& text, const std::string& origin);

// cli (if given) wins over the environment value (if non-null and non-empty), else `fallback`.
int resolve_domain_id(const std::optional<std::string>& cli, const char* env_value, int fallback = 0);

}  // namespace bbw::dds
