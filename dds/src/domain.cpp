#include "bbw/dds/domain.hpp"

#include <charconv>
#include <stdexcept>

namespace bbw::dds {

int parse_domain_id(const std::string& text, const std::string& origin) {
  int value = -1;
  const char* first = text.data();
  const char* last = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(first, last, value);
  if (text.empty() || ec != std::errc() || ptr != last) {
    throw std::invalid_argument(origin + ": domain id must be an integer in [0, " +
                                std::to_string(kMaxDomainId) + "], got '" + text + "'");
  }
  if (value < 0 || value > kMaxDomainId) {
    throw std::invalid_argument(origin + ": domain id must be in [0, " + std::to_string(kMaxDomainId) +
                                "] (Fast DDS port range), got " + text);
  }
  return value;
}

int resolve_domain_id(const std::optional<std::string>& cli, const char* env_value, int fallback) {
  if (cli) return parse_domain_id(*cli, "--domain");
  if (env_value != nullptr && *env_value != '\0') return parse_domain_id(env_value, "BBW_DOMAIN");
  return fallback;
}

}  // namespace bbw::dds
