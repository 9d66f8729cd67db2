// DDS Security over real Fast DDS 2.9 in one process, SHM + UDP on 127.0.0.1 only (bbw_localhost
// profile), with keys from `./bbw keys` in a temporary directory. Proves:
//   - certified CCU and corner participants authenticate, match and exchange data (encrypted by
//     the governance document), commands one way and partitioned measurements the other;
//   - a participant with a certificate from a rogue CA (and documents signed by that CA), or with
//     no security at all, never matches a certified participant and none of its samples arrive,
//     while in the same test a certified writer does match (the timeout is not what fails);
//   - access control refuses a certified corner that tries to write commands, calibration state
//     or another corner's measurements, and the CCU writing measurements;
//   - permissions are bound to their certificate subject: a corner cannot use the CCU's.
// Domains 211-215 (one per test) keep ctest -j runs apart.
#include <gtest/gtest.h>

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <chrono>
#include <memory>
#include <string>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/security/dds_security.hpp"
#include "keys_fixture.hpp"
#include "partitioned.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::dds::DdsError;
using bbw::dds::Events;
using bbw::dds::Participant;
using bbw::dds::ParticipantOptions;
using bbw::security::SecurityFiles;
using bbw::test::PartitionReader;
using bbw::test::PartitionWriter;
using CommandT = bbw::msg::ClampCommandPubSubType;
using CalibrationT = bbw::msg::CalibrationStatePubSubType;
using BlockT = bbw::msg::MeasurementBlockPubSubType;
using HealthT = bbw::msg::CornerHealthPubSubType;

// A secure handshake (PKI-DH, permissions exchange, key exchange) on a loaded 2-core machine
// takes well under a second; 15 s is a generous bound for a positive match.
constexpr auto kMatchTimeout = 15s;
// How long a negative (no match, no data) is watched after the positive control matched.
constexpr auto kQuietWindow = 3s;

class SecureDds : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { keys_ = std::make_unique<bbw::test::TempKeys>(); }
  static void TearDownTestSuite() { keys_.reset(); }
  void SetUp() override { ASSERT_EQ(keys_->status(), 0) << keys_->output(); }

  static ParticipantOptions options(int domain, const std::string& name) {
    ParticipantOptions o;
    o.domain_id = domain;
    o.name = name;
    return o;
  }
  static ParticipantOptions secure(int domain, const std::string& identity) {
    ParticipantOptions o = options(domain, "bbw_test_" + identity);
    o.properties = bbw::security::participant_properties(bbw::security::files_for(keys_->dir().string(), identity));
    return o;
  }
  // The intruder: complete and self-consistent, but everything is signed by the rogue CA.
  static ParticipantOptions rogue(int domain) {
    SecurityFiles f;
    f.identity_ca = keys_->path("rogue/ca/ca.pem");
    f.identity_cert = keys_->path("rogue/intruder/cert.pem");
    f.private_key = keys_->path("rogue/intruder/key.pem");
    f.permissions_ca = f.identity_ca;
    f.governance = keys_->path("rogue/governance.p7s");
    f.permissions = keys_->path("rogue/intruder/permissions.p7s");
    ParticipantOptions o = options(domain, "bbw_test_intruder");
    o.properties = bbw::security::participant_properties(f);
    return o;
  }
  static bbw::msg::ClampCommand command(std::uint64_t seq, double force_kN) {
    bbw::msg::ClampCommand c;
    c.corner_id(0);
    c.seq(seq);
    c.step(seq);
    c.clamp_force_kN(force_kN);
    c.mode(1);
    c.valid(true);
    return c;
  }

  static std::unique_ptr<bbw::test::TempKeys> keys_;
};
std::unique_ptr<bbw::test::TempKeys> SecureDds::keys_;

TEST_F(SecureDds, CertifiedCcuAndCornerMatchAndExchangeData) {
  Events events;
  Participant ccu(secure(211, "ccu"));
  Participant fl(secure(211, "fl"));

  bbw::dds::Writer<CommandT> commands(ccu, bbw::dds::kCommandTopic, "command_writer_lockstep", events);
  bbw::dds::Reader<CommandT> fl_commands(fl, bbw::dds::kCommandTopic, "command_reader_lockstep", events);
  PartitionWriter<BlockT> blocks(fl, bbw::dds::kMeasurementTopic, "measurement_writer_lockstep",
                                 bbw::security::corner_partition("FL"), events);
  PartitionReader<BlockT> ccu_blocks(ccu, bbw::dds::kMeasurementTopic, "measurement_reader_lockstep",
                                     bbw::security::kCornerPartitionPattern, events);
  ASSERT_TRUE(blocks.created()) << "corner FL may write measurements in partition corner_FL";
  ASSERT_TRUE(ccu_blocks.created());
  ASSERT_TRUE(events.wait_for(kMatchTimeout, [&] {
    return commands.matched() == 1 && fl_commands.matched() == 1 && blocks.matched() == 1 && ccu_blocks.matched() == 1;
  })) << "matched: commands " << commands.matched() << "/" << fl_commands.matched() << ", blocks "
      << blocks.matched() << "/" << ccu_blocks.matched();

  constexpr int kCommands = 20;
  int received = 0;
  bbw::msg::ClampCommand in;
  for (int k = 1; k <= kCommands; ++k) {
    ASSERT_TRUE(commands.write(command(static_cast<std::uint64_t>(k), 0.5 * k)));
    ASSERT_TRUE(events.wait_for(5s, [&] {
      while (fl_commands.take(in)) {
        ++received;
        EXPECT_EQ(in.seq(), static_cast<std::uint64_t>(received));
        EXPECT_DOUBLE_EQ(in.clamp_force_kN(), 0.5 * received);
      }
      return received == k;
    })) << "command " << k << " not received within 5 s";
  }

  bbw::msg::MeasurementBlock b;
  b.corner_id(0);
  b.block_seq(7);
  b.samples().resize(5);
  b.samples()[4].force_internal_kN(12.25);
  ASSERT_TRUE(blocks.write(b));
  bbw::msg::MeasurementBlock got;
  ASSERT_TRUE(events.wait_for(5s, [&] { return ccu_blocks.take(got); })) << "block not received within 5 s";
  EXPECT_EQ(got.block_seq(), 7u);
  ASSERT_EQ(got.samples().size(), 5u);
  EXPECT_DOUBLE_EQ(got.samples()[4].force_internal_kN(), 12.25);
}

TEST_F(SecureDds, RogueAndUnauthenticatedParticipantsNeverMatchNorInjectNorEavesdrop) {
  Events events;
  Participant fl(secure(212, "fl"));
  bbw::dds::Reader<CommandT> fl_commands(fl, bbw::dds::kCommandTopic, "command_reader_lockstep", events);

  // The intruder's participant starts (its own CA vouches for it), so what follows is refused
  // by the certified side, not by a broken local setup. Its reader matches its own writer.
  Participant intruder(rogue(212));
  bbw::dds::Writer<CommandT> rogue_commands(intruder, bbw::dds::kCommandTopic, "command_writer_lockstep", events);
  bbw::dds::Reader<CommandT> rogue_reader(intruder, bbw::dds::kCommandTopic, "command_reader_lockstep", events);
  // Two unsecured participants, which match each other and nobody else.
  Participant plain(options(212, "bbw_test_unsecured_writer"));
  bbw::dds::Writer<CommandT> plain_commands(plain, bbw::dds::kCommandTopic, "command_writer_lockstep", events);
  Participant eavesdropper(options(212, "bbw_test_unsecured_reader"));
  bbw::dds::Reader<CommandT> plain_reader(eavesdropper, bbw::dds::kCommandTopic, "command_reader_lockstep", events);

  Participant ccu(secure(212, "ccu"));
  bbw::dds::Writer<CommandT> commands(ccu, bbw::dds::kCommandTopic, "command_writer_lockstep", events);
  // Positive controls: every pair that should match does, on the same domain.
  ASSERT_TRUE(events.wait_for(kMatchTimeout, [&] {
    return commands.matched() >= 1 && fl_commands.matched() >= 1 && rogue_commands.matched() >= 1 &&
           rogue_reader.matched() >= 1 && plain_commands.matched() >= 1 && plain_reader.matched() >= 1;
  })) << "CCU writer " << commands.matched() << ", corner reader " << fl_commands.matched() << ", rogue "
      << rogue_commands.matched() << "/" << rogue_reader.matched() << ", unsecured " << plain_commands.matched()
      << "/" << plain_reader.matched();

  // Nothing crosses between the certified pair and the others within the quiet window while
  // the intruders keep writing.
  auto crossed = [&] {
    return commands.matched() > 1 || fl_commands.matched() > 1 || rogue_commands.matched() > 1 ||
           rogue_reader.matched() > 1 || plain_commands.matched() > 1 || plain_reader.matched() > 1;
  };
  const auto until = std::chrono::steady_clock::now() + kQuietWindow;
  std::uint64_t seq = 1000;
  bool any_cross_match = false;
  while (!any_cross_match && std::chrono::steady_clock::now() < until) {
    rogue_commands.write(command(++seq, 99.0));
    plain_commands.write(command(++seq, 98.0));
    any_cross_match = events.wait_for(100ms, crossed);
  }
  EXPECT_FALSE(any_cross_match) << "CCU writer matched " << commands.matched() << ", corner reader "
                                << fl_commands.matched() << ", rogue " << rogue_commands.matched() << "/"
                                << rogue_reader.matched() << ", unsecured " << plain_commands.matched() << "/"
                                << plain_reader.matched();

  // The certified command gets through; none of the intruders' ever does.
  ASSERT_TRUE(commands.write(command(1, 3.0)));
  bool got_ccu = false;
  int intruder_samples = 0;
  bbw::msg::ClampCommand in;
  ASSERT_TRUE(events.wait_for(5s, [&] {
    while (fl_commands.take(in)) {
      if (in.clamp_force_kN() == 3.0) {
        got_ccu = true;
      } else {
        ++intruder_samples;
      }
    }
    return got_ccu;
  }));
  EXPECT_EQ(intruder_samples, 0);
  // The eavesdroppers work (they got their own side's commands) but never saw the CCU's.
  auto drain = [&](bbw::dds::Reader<CommandT>& r, double own_kN, int& own, int& foreign) {
    bbw::msg::ClampCommand c;
    while (r.take(c)) (c.clamp_force_kN() == own_kN ? own : foreign)++;
  };
  int rogue_own = 0, rogue_foreign = 0, plain_own = 0, plain_foreign = 0;
  drain(rogue_reader, 99.0, rogue_own, rogue_foreign);
  drain(plain_reader, 98.0, plain_own, plain_foreign);
  EXPECT_GT(rogue_own, 0);
  EXPECT_GT(plain_own, 0);
  EXPECT_EQ(rogue_foreign, 0) << "the rogue participant read commands it did not write";
  EXPECT_EQ(plain_foreign, 0) << "an unsecured participant read commands it did not write";
}

TEST_F(SecureDds, AccessControlRefusesWritersThePermissionsDoNotGrant) {
  Events events;
  Participant fl(secure(213, "fl"));
  Participant ccu(secure(213, "ccu"));

  // A certified corner may not command, nor publish calibration state.
  EXPECT_THROW(bbw::dds::Writer<CommandT>(fl, bbw::dds::kCommandTopic, "command_writer_lockstep", events), DdsError);
  EXPECT_THROW(bbw::dds::Writer<CalibrationT>(fl, bbw::dds::kCalibrationTopic, "state_writer", events), DdsError);
  // Measurements only in its own partition: not in another corner's, not in none.
  {
    PartitionWriter<BlockT> as_fr(fl, bbw::dds::kMeasurementTopic, "measurement_writer_lockstep",
                                  bbw::security::corner_partition("FR"), events);
    EXPECT_FALSE(as_fr.created()) << "corner FL wrote measurements in partition corner_FR";
    PartitionWriter<BlockT> unpartitioned(fl, bbw::dds::kMeasurementTopic, "measurement_writer_lockstep", "", events);
    EXPECT_FALSE(unpartitioned.created()) << "corner FL wrote measurements outside any partition";
    PartitionWriter<HealthT> health_as_rr(fl, bbw::dds::kHealthTopic, "state_writer",
                                          bbw::security::corner_partition("RR"), events);
    EXPECT_FALSE(health_as_rr.created());
    PartitionWriter<BlockT> wildcard(fl, bbw::dds::kMeasurementTopic, "measurement_writer_lockstep",
                                     bbw::security::kCornerPartitionPattern, events);
    EXPECT_FALSE(wildcard.created()) << "corner FL wrote measurements in partition corner_*";
  }
  // Topics outside the grants are refused (default DENY).
  EXPECT_THROW(bbw::dds::Writer<CommandT>(fl, "bbw/SomethingElse", "command_writer_lockstep", events), DdsError);
  // The CCU may not publish measurements.
  PartitionWriter<BlockT> ccu_blocks(ccu, bbw::dds::kMeasurementTopic, "measurement_writer_lockstep",
                                     bbw::security::corner_partition("FL"), events);
  EXPECT_FALSE(ccu_blocks.created());

  // What is granted still works on the same participants.
  PartitionWriter<HealthT> health(fl, bbw::dds::kHealthTopic, "state_writer", bbw::security::corner_partition("FL"),
                                  events);
  // The CCU reads each corner in that corner's own partition (so it knows who wrote a sample);
  // its grant "corner_*" covers every one of them.
  PartitionReader<HealthT> ccu_health(ccu, bbw::dds::kHealthTopic, "state_reader",
                                      bbw::security::corner_partition("FL"), events);
  PartitionReader<HealthT> ccu_health_rr(ccu, bbw::dds::kHealthTopic, "state_reader",
                                         bbw::security::corner_partition("RR"), events);
  ASSERT_TRUE(health.created());
  ASSERT_TRUE(ccu_health.created());
  ASSERT_TRUE(ccu_health_rr.created());
  ASSERT_TRUE(events.wait_for(kMatchTimeout, [&] { return health.matched() == 1 && ccu_health.matched() == 1; }));
  EXPECT_EQ(ccu_health_rr.matched(), 0) << "a reader in partition corner_RR matched corner FL's writer";
  bbw::msg::CornerHealth h;
  h.corner_id(0);
  h.status(1);
  ASSERT_TRUE(health.write(h));
  bbw::msg::CornerHealth got;
  ASSERT_TRUE(events.wait_for(5s, [&] { return ccu_health.take(got); }));
  EXPECT_EQ(got.status(), 1);
}

TEST_F(SecureDds, PermissionsAreBoundToTheirCertificateSubject) {
  // Corner FL's certificate with the CCU's (validly signed) permissions document.
  auto files = bbw::security::files_for(keys_->dir().string(), "fl");
  files.permissions = bbw::security::files_for(keys_->dir().string(), "ccu").permissions;
  ParticipantOptions o = options(214, "bbw_test_fl_as_ccu");
  o.properties = bbw::security::participant_properties(files);
  EXPECT_THROW(Participant p(o), DdsError);
  // The unsigned XML instead of the signed document.
  auto unsigned_files = bbw::security::files_for(keys_->dir().string(), "fl");
  unsigned_files.permissions = keys_->path("fl/permissions.xml");
  o.properties = bbw::security::participant_properties(unsigned_files);
  EXPECT_THROW(Participant p(o), DdsError);
  // The rogue CA's governance with our identity.
  auto rogue_gov = bbw::security::files_for(keys_->dir().string(), "fl");
  rogue_gov.governance = keys_->path("rogue/governance.p7s");
  o.properties = bbw::security::participant_properties(rogue_gov);
  EXPECT_THROW(Participant p(o), DdsError);
  // Control: the matching documents work.
  o.properties = bbw::security::participant_properties(bbw::security::files_for(keys_->dir().string(), "fl"));
  EXPECT_NO_THROW(Participant p(o));
}

// bbw_intruder (security/tools) as a separate process next to a certified corner: as rogue and
// as unsecured it starts and writes but never matches, as a certified corner it is refused the
// command writer; the corner receives nothing. Its JSON line is what system tests will read.
TEST_F(SecureDds, IntruderProcessNeverReachesACertifiedCorner) {
  Events events;
  Participant fl(secure(215, "fl"));
  bbw::dds::Reader<CommandT> fl_commands(fl, bbw::dds::kCommandTopic, "command_reader_lockstep", events);
  const std::string tool = std::string(BBW_TEST_BINARY_DIR) + "/bin/bbw_intruder";
  for (const std::string as : {"rogue", "none", "corner"}) {
    const auto r = bbw::test::run_shell(bbw::test::quote(tool) + " --as " + as + " --corner RR --domain 215 --keys " +
                                        bbw::test::quote(keys_->dir().string()) + " --duration-s 2 2>/dev/null");
    ASSERT_EQ(r.status, 0) << as << ": " << r.output;
    const std::string writer = as == "corner" ? "false" : "true";
    EXPECT_NE(r.output.find("{\"as\":\"" + as + "\",\"participant\":true,\"writer\":" + writer + ",\"max_matched\":0,"),
              std::string::npos)
        << r.output;
    if (as != "corner") {
      EXPECT_EQ(r.output.find("\"written\":0}"), std::string::npos) << as << " wrote nothing: " << r.output;
    }
  }
  bbw::msg::ClampCommand in;
  EXPECT_FALSE(fl_commands.take(in)) << "a certified corner received an intruder's command";
  EXPECT_EQ(fl_commands.matched(), 0);
  // Control: the corner is reachable; a certified CCU on this domain matches it.
  Participant ccu(secure(215, "ccu"));
  bbw::dds::Writer<CommandT> commands(ccu, bbw::dds::kCommandTopic, "command_writer_lockstep", events);
  EXPECT_TRUE(events.wait_for(kMatchTimeout, [&] { return fl_commands.matched() == 1; }));
}

}  // namespace
