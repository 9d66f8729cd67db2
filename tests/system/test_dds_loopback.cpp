// bbw_dds over real Fast DDS on loopback, inside one process: profiles load, writer and
// reader match within a deadline, keyed samples arrive in order, the content filter delivers
// only the addressed corner, and malformed inputs are refused with a clear error.
#include <gtest/gtest.h>

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <chrono>
#include <cstdlib>
#include <string>

#include "bbw/dds/corner.hpp"
#include "bbw/dds/domain.hpp"
#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/writer.hpp"

namespace {

using namespace std::chrono_literals;
using bbw::dds::Events;
using bbw::dds::Participant;
using bbw::dds::ParticipantOptions;
using bbw::dds::Reader;
using bbw::dds::Writer;
using CommandT = bbw::msg::ClampCommandPubSubType;
using BlockT = bbw::msg::MeasurementBlockPubSubType;

// Each test uses its own domain so ctest -j runs them side by side without cross-talk.
ParticipantOptions options(int domain, const std::string& name) {
  ParticipantOptions o;
  o.domain_id = domain;
  o.name = name;
  return o;
}

TEST(DdsLoopback, KeyedBlocksArriveInOrderWithoutLoss) {
  Events events;
  Participant pub(options(141, "test_pub"));
  Participant sub(options(141, "test_sub"));
  Writer<BlockT> writer(pub, "bbw/MeasurementBlock", "measurement_writer_lockstep", events);
  Reader<BlockT> reader(sub, "bbw/MeasurementBlock", "measurement_reader_lockstep", events);
  ASSERT_TRUE(writer.wait_for_matched(1, 10s)) << "writer did not match within 10 s";
  ASSERT_TRUE(reader.wait_for_matched(1, 10s)) << "reader did not match within 10 s";

  constexpr int kBlocks = 200;
  int received = 0;
  std::uint64_t expected_seq[4] = {0, 0, 0, 0};
  bbw::msg::MeasurementBlock in;
  for (int k = 0; k < kBlocks; ++k) {
    bbw::msg::MeasurementBlock b;
    b.corner_id(static_cast<std::uint8_t>(k % 4));
    b.block_seq(static_cast<std::uint64_t>(k / 4));
    b.samples().resize(5);
    for (std::size_t i = 0; i < 5; ++i) b.samples()[i].seq(static_cast<std::uint64_t>(k / 4 * 5) + i);
    ASSERT_TRUE(writer.write(b));
    // Lockstep style: wait for this block before sending the next.
    ASSERT_TRUE(events.wait_for(5s, [&] {
      while (reader.take(in)) {
        EXPECT_EQ(in.block_seq(), expected_seq[in.corner_id()]) << "corner " << int(in.corner_id());
        ++expected_seq[in.corner_id()];
        ++received;
      }
      return received == k + 1;
    })) << "block " << k << " not received within 5 s";
    ASSERT_EQ(in.samples().size(), 5u);
    EXPECT_EQ(in.samples()[4].seq(), static_cast<std::uint64_t>(k / 4 * 5) + 4);
  }
  EXPECT_EQ(received, kBlocks);
  EXPECT_EQ(reader.samples_lost(), 0u);
}

TEST(DdsLoopback, ContentFilterDeliversOnlyTheAddressedCorner) {
  Events events;
  Participant ccu(options(142, "test_ccu"));
  Participant corner(options(142, "test_corner_RL"));
  Writer<CommandT> writer(ccu, "bbw/ClampCommand", "command_writer_lockstep", events);
  const bbw::dds::ContentFilter filter{"ClampCommand_RL", "corner_id = %0", {"2"}};
  Reader<CommandT> reader(corner, "bbw/ClampCommand", "command_reader_lockstep", events, &filter);
  ASSERT_TRUE(writer.wait_for_matched(1, 10s));
  ASSERT_TRUE(reader.wait_for_matched(1, 10s));
  for (std::uint64_t step = 0; step < 10; ++step) {
    for (std::uint8_t c = 0; c < 4; ++c) {
      bbw::msg::ClampCommand cmd;
      cmd.corner_id(c);
      cmd.step(step);
      cmd.clamp_force_kN(static_cast<double>(c) * 10.0 + static_cast<double>(step));
      ASSERT_TRUE(writer.write(cmd));
    }
  }
  int received = 0;
  bbw::msg::ClampCommand in;
  ASSERT_TRUE(events.wait_for(5s, [&] {
    while (reader.take(in)) {
      EXPECT_EQ(in.corner_id(), 2);
      EXPECT_EQ(in.step(), static_cast<std::uint64_t>(received));
      EXPECT_DOUBLE_EQ(in.clamp_force_kN(), 20.0 + static_cast<double>(received));
      ++received;
    }
    return received >= 10;
  }));
  EXPECT_EQ(received, 10);
}

TEST(DdsLoopback, UnknownProfilesAreRefusedByName) {
  ParticipantOptions o = options(143, "bad");
  o.profile = "no_such_participant_profile";
  try {
    Participant p(o);
    FAIL() << "participant with an unknown profile was created";
  } catch (const bbw::dds::DdsError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_participant_profile"), std::string::npos) << e.what();
  }
  Events events;
  Participant p(options(143, "ok"));
  EXPECT_THROW((Writer<CommandT>(p, "bbw/ClampCommand", "no_such_writer_profile", events)),
               bbw::dds::DdsError);
  o = options(143, "missing_file");
  o.profiles_file = "/nonexistent/bbw_profiles.xml";
  EXPECT_THROW(Participant{o}, bbw::dds::DdsError);
}

TEST(DdsDomain, ParsesAndBoundsDomainIds) {
  using bbw::dds::parse_domain_id;
  using bbw::dds::resolve_domain_id;
  EXPECT_EQ(parse_domain_id("0", "--domain"), 0);
  EXPECT_EQ(parse_domain_id("232", "--domain"), 232);
  EXPECT_THROW(parse_domain_id("233", "--domain"), std::invalid_argument);
  EXPECT_THROW(parse_domain_id("-1", "--domain"), std::invalid_argument);
  EXPECT_THROW(parse_domain_id("7x", "--domain"), std::invalid_argument);
  EXPECT_THROW(parse_domain_id("", "--domain"), std::invalid_argument);
  EXPECT_EQ(resolve_domain_id(std::string("12"), "40"), 12);
  EXPECT_EQ(resolve_domain_id(std::nullopt, "40"), 40);
  EXPECT_EQ(resolve_domain_id(std::nullopt, nullptr, 3), 3);
  EXPECT_EQ(resolve_domain_id(std::nullopt, "", 3), 3);
  try {
    resolve_domain_id(std::nullopt, "900");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("BBW_DOMAIN"), std::string::npos);
  }
}

TEST(DdsCorner, ParsesExactNamesOnly) {
  using bbw::dds::Corner;
  EXPECT_EQ(bbw::dds::parse_corner("FL"), Corner::FL);
  EXPECT_EQ(bbw::dds::parse_corner("RR"), Corner::RR);
  EXPECT_FALSE(bbw::dds::parse_corner("fl"));
  EXPECT_FALSE(bbw::dds::parse_corner("XX"));
  EXPECT_FALSE(bbw::dds::corner_from_wire(4));
  EXPECT_EQ(bbw::dds::corner_from_wire(3), Corner::RR);
}

}  // namespace
