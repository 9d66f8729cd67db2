// bbw_dds_echo: answers every MeasurementBlock with a ClampCommand for the same corner and
// step, over the same topics and QoS profiles as bbw_ccu. The peer of the round-trip latency
// benchmark and of the two-process DDS system test.
//
//   bbw_dds_echo [--domain N] [--mode lockstep|realtime] [--max-blocks K]
//                [--partition P] [--secure KEYS_DIR]
// --partition: read the blocks in partition P (e.g. corner_*, as bbw_ccu reads corner_FL...);
// --secure: DDS Security with the CCU's identity from KEYS_DIR (docs/security.md).
// Exits 0 after K blocks (if given) or on SIGINT/SIGTERM; 2 on bad arguments; 1 on DDS errors.
#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <cstdlib>
#include <iostream>
#include <optional>
#include <string>

#include "bbw/dds/domain.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/runtime/signals.hpp"
#include "bbw/security/dds_security.hpp"

int main(int argc, char** argv) {
  bbw::dds::Events events;
  bbw::runtime::SignalWatcher signals([&](int) { events.interrupt(); });
  std::optional<std::string> domain_arg;
  std::string mode = "realtime";
  long long max_blocks = -1;
  std::string partition, secure_dir;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--domain" && i + 1 < argc) {
      domain_arg = argv[++i];
    } else if (a == "--mode" && i + 1 < argc) {
      mode = argv[++i];
    } else if (a == "--partition" && i + 1 < argc) {
      partition = argv[++i];
    } else if (a == "--secure" && i + 1 < argc) {
      secure_dir = argv[++i];
    } else if (a == "--max-blocks" && i + 1 < argc) {
      max_blocks = std::atoll(argv[++i]);
    } else {
      std::cerr << "bbw_dds_echo: unknown argument '" << a << "'\n"
                << "usage: bbw_dds_echo [--domain N] [--mode lockstep|realtime] [--max-blocks K]\n"
                << "                    [--partition P] [--secure KEYS_DIR]\n";
      return 2;
    }
  }
  if (mode != "lockstep" && mode != "realtime") {
    std::cerr << "bbw_dds_echo: --mode must be lockstep or realtime, got '" << mode << "'\n";
    return 2;
  }
  try {
    const int domain = bbw::dds::resolve_domain_id(domain_arg, std::getenv("BBW_DOMAIN"));
    const auto profiles = bbw::dds::profiles_for(mode == "lockstep");
    bbw::dds::ParticipantOptions opt;
    opt.domain_id = domain;
    opt.name = "bbw_dds_echo";
    if (!secure_dir.empty()) {
      opt.properties = bbw::security::participant_properties(
          bbw::security::files_for(secure_dir, bbw::security::kCcuIdentity));
    }
    bbw::dds::Participant participant(opt);
    bbw::dds::Reader<bbw::msg::MeasurementBlockPubSubType> blocks(
        participant, bbw::dds::kMeasurementTopic, profiles.measurement_reader, events,
        bbw::dds::Partition{partition});
    bbw::dds::Writer<bbw::msg::ClampCommandPubSubType> commands(
        participant, bbw::dds::kCommandTopic, profiles.command_writer, events);
    std::cout << "bbw_dds_echo: domain " << domain << ", mode " << mode << ", waiting" << std::endl;
    // A reply written before our command writer has matched the peer's reader is lost (volatile
    // durability): it once cost DdsTwoProcess its 5 s reply wait. Blocks that arrive meanwhile
    // wait in the reader's history.
    if (!commands.wait_for_matched(1, std::chrono::seconds(20))) {
      std::cerr << "bbw_dds_echo: no command reader matched within 20 s\n";
      return 3;
    }
    long long echoed = 0;
    bbw::msg::MeasurementBlock in;
    bbw::msg::ClampCommand out;
    while (!events.interrupted() && (max_blocks < 0 || echoed < max_blocks)) {
      events.wait_until(bbw::dds::Events::Clock::time_point::max(), [&] {
        while (blocks.take(in)) {
          out.corner_id(in.corner_id());
          out.seq(in.block_seq());
          out.step(in.block_seq());
          out.time_s(in.period_start_s());
          out.clamp_force_kN(in.samples().empty() ? 0.0 : in.samples().back().force_internal_kN());
          out.mode(bbw::msg::MODE_FORCE);
          out.valid(true);
          commands.write(out);
          ++echoed;
        }
        return max_blocks >= 0 && echoed >= max_blocks;
      });
    }
    // Deliver the last replies before the writer goes away (otherwise the peer may miss them).
    commands.get().wait_for_acknowledgments(eprosima::fastrtps::Duration_t(2, 0));
    std::cout << "bbw_dds_echo: echoed " << echoed << " blocks" << std::endl;
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "bbw_dds_echo: " << e.what() << "\n";
    return 1;
  }
}
