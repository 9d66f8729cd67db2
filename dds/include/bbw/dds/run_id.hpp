// The run id: a random 64-bit number bbw_launch draws from /dev/urandom for every run (never
// from the scenario seed) and passes to every child as --run-id HEX. Each run's DDS endpoints
// live in partitions derived from it, every message carries it, and every process drops (and
// counts) a sample or command of another run (docs/distributed.md, "Runs on one host").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace bbw::dds {

// 16 lower-case hex digits.
std::string run_id_hex(std::uint64_t run_id);
// Exactly 1..16 hex digits; nullopt otherwise.
std::optional<std::uint64_t> parse_run_id(const std::string& text);
// A fresh non-zero run id from /dev/urandom; throws std::runtime_error when it cannot be read.
std::uint64_t random_run_id();

// "run_<hex>": the partition of the commands and calibration state of a run.
std::string run_partition(std::uint64_t run_id);
// "<corner_partition>.run_<hex>" (e.g. corner_FL.run_00ab...): a corner's measurements and
// health in one run. DDS Security grants corner C only partitions matching "corner_C.run_*".
std::string corner_run_partition(const std::string& corner_partition, std::uint64_t run_id);

// What a bbw participant announces in its USER_DATA: "bbw run=<hex> pid=<pid> name=<name>".
struct PeerTag {
  std::uint64_t run_id = 0;
  long pid = 0;
  std::string name;
};
std::string encode_peer_tag(const PeerTag& tag);
// nullopt when `text` is not a bbw tag.
std::optional<PeerTag> decode_peer_tag(const std::string& text);
// Tags joined by ';' (a stats-file value) and back (entries that are no tag are skipped).
std::string join_peer_tags(const std::vector<PeerTag>& tags);
std::vector<PeerTag> split_peer_tags(const std::string& text);

}  // namespace bbw::dds
