#include "bbw/dds/run_id.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <stdexcept>

namespace bbw::dds {

std::string run_id_hex(std::uint64_t run_id) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(run_id));
  return text;
}

std::optional<std::uint64_t> parse_run_id(const std::string& text) {
  if (text.empty() || text.size() > 16) return std::nullopt;
  std::uint64_t v = 0;
  for (char c : text) {
    int d = -1;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    if (d < 0) return std::nullopt;
    v = (v << 4) | static_cast<std::uint64_t>(d);
  }
  return v;
}

std::uint64_t random_run_id() {
  std::ifstream f("/dev/urandom", std::ios::binary);
  std::uint64_t v = 0;
  while (v == 0) {
    if (!f.read(reinterpret_cast<char*>(&v), sizeof v)) throw std::runtime_error("cannot read /dev/urandom for a run id");
  }
  return v;
}

std::string run_partition(std::uint64_t run_id) { return "run_" + run_id_hex(run_id); }

std::string corner_run_partition(const std::string& corner_partition, std::uint64_t run_id) {
  return corner_partition + "." + run_partition(run_id);
}

std::string encode_peer_tag(const PeerTag& tag) {
  return "bbw run=" + run_id_hex(tag.run_id) + " pid=" + std::to_string(tag.pid) + " name=" + tag.name;
}

std::optional<PeerTag> decode_peer_tag(const std::string& text) {
  const std::string head = "bbw run=";
  if (text.rfind(head, 0) != 0 || text.size() < head.size() + 16) return std::nullopt;
  PeerTag tag;
  const auto id = parse_run_id(text.substr(head.size(), 16));
  if (!id) return std::nullopt;
  tag.run_id = *id;
  const auto pid_at = text.find(" pid=");
  const auto name_at = text.find(" name=");
  if (pid_at == std::string::npos || name_at == std::string::npos || name_at < pid_at) return std::nullopt;
  tag.pid = std::strtol(text.c_str() + pid_at + 5, nullptr, 10);
  tag.name = text.substr(name_at + 6);
  return tag;
}

std::string join_peer_tags(const std::vector<PeerTag>& tags) {
  std::string out;
  for (const auto& t : tags) out += (out.empty() ? "" : ";") + encode_peer_tag(t);
  return out;
}

std::vector<PeerTag> split_peer_tags(const std::string& text) {
  std::vector<PeerTag> out;
  std::size_t from = 0;
  while (from <= text.size()) {
    const std::size_t end = std::min(text.find(';', from), text.size());
    if (auto tag = decode_peer_tag(text.substr(from, end - from))) out.push_back(*tag);
    from = end + 1;
  }
  return out;
}

}  // namespace bbw::dds
