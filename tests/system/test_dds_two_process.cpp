// Two OS processes over the default transport: this test plays a corner, bbw_dds_echo plays
// the CCU. Every block is answered, in order, for the addressed corner only. Domain 144.
#include <gtest/gtest.h>

#include <bbw/idl/bbw_msgsPubSubTypes.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "bbw/dds/events.hpp"
#include "bbw/dds/participant.hpp"
#include "bbw/dds/reader.hpp"
#include "bbw/dds/topics.hpp"
#include "bbw/dds/writer.hpp"
#include "bbw/runtime/child.hpp"

namespace {

using namespace std::chrono_literals;

TEST(DdsTwoProcess, EchoAnswersEveryBlockOfTheAddressedCorner) {
  const std::string bin = std::string(BBW_TEST_BINARY_DIR) + "/bin";
  const auto logs = std::filesystem::temp_directory_path() / ("bbw_two_process_" + std::to_string(::getpid()));
  std::filesystem::create_directories(logs);
  constexpr int kBlocks = 300;
  // The echo answers every corner; we send 2 corners' blocks and expect only RR's replies.
  bbw::runtime::Child echo("bbw_dds_echo",
                          {bin + "/bbw_dds_echo", "--domain", "144", "--mode", "lockstep",
                           "--max-blocks", std::to_string(2 * kBlocks)},
                          (logs / "echo.out").string(), (logs / "echo.err").string());
  bbw::dds::Events events;
  bbw::dds::ParticipantOptions opt;
  opt.domain_id = 144;
  opt.name = "test_corner_RR";
  bbw::dds::Participant participant(opt);
  const auto profiles = bbw::dds::profiles_for(true);
  bbw::dds::Writer<bbw::msg::MeasurementBlockPubSubType> blocks(
      participant, bbw::dds::kMeasurementTopic, profiles.measurement_writer, events);
  const bbw::dds::ContentFilter filter{"ClampCommand_RR", "corner_id = %0", {"3"}};
  bbw::dds::Reader<bbw::msg::ClampCommandPubSubType> commands(
      participant, bbw::dds::kCommandTopic, profiles.command_reader, events, &filter);
  ASSERT_TRUE(blocks.wait_for_matched(1, 15s)) << "echo not discovered within 15 s";
  ASSERT_TRUE(commands.wait_for_matched(1, 15s));

  bbw::msg::MeasurementBlock block;
  block.samples().resize(5);
  bbw::msg::ClampCommand reply;
  std::uint64_t next_expected = 0;
  for (std::uint64_t k = 0; k < kBlocks; ++k) {
    for (std::uint8_t corner : {std::uint8_t{1}, std::uint8_t{3}}) {
      block.corner_id(corner);
      block.block_seq(k);
      block.samples().back().force_internal_kN(static_cast<double>(k) + corner * 1000.0);
      ASSERT_TRUE(blocks.write(block));
    }
    ASSERT_TRUE(events.wait_for(5s, [&] {
      while (commands.take(reply)) {
        EXPECT_EQ(reply.corner_id(), 3);
        EXPECT_EQ(reply.step(), next_expected);
        EXPECT_DOUBLE_EQ(reply.clamp_force_kN(), static_cast<double>(next_expected) + 3000.0);
        ++next_expected;
      }
      return next_expected == k + 1;
    })) << "reply to block " << k << " missing after 5 s";
  }
  const auto status = echo.wait_until(std::chrono::steady_clock::now() + 10s);
  ASSERT_TRUE(status.has_value()) << "echo did not finish";
  EXPECT_TRUE(status->ok()) << status->describe();
  std::filesystem::remove_all(logs);
}

}  // namespace
