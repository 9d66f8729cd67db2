// Run ids, their partitions and the USER_DATA tag a participant announces (issue 17).
#include <gtest/gtest.h>

#include "bbw/dds/run_id.hpp"

namespace {

using namespace bbw::dds;

TEST(RunId, HexRoundTripsAndRejectsWhatIsNoId) {
  EXPECT_EQ(run_id_hex(0x00ab), "00000000000000ab");
  EXPECT_EQ(parse_run_id("00000000000000ab"), 0xabu);
  EXPECT_EQ(parse_run_id("FFffFFffFFffFFff"), 0xffffffffffffffffULL);
  EXPECT_FALSE(parse_run_id(""));
  EXPECT_FALSE(parse_run_id("12345678901234567"));  // 17 digits
  EXPECT_FALSE(parse_run_id("12g4"));
  EXPECT_FALSE(parse_run_id("-1"));
}

TEST(RunId, RandomIdsAreNonZeroAndDiffer) {
  const auto a = random_run_id(), b = random_run_id();
  EXPECT_NE(a, 0u);
  EXPECT_NE(a, b);
}

TEST(RunId, PartitionsOfARunMatchTheSecurityPatterns) {
  EXPECT_EQ(run_partition(0xab), "run_00000000000000ab");
  EXPECT_EQ(corner_run_partition("corner_FL", 0xab), "corner_FL.run_00000000000000ab");
}

TEST(RunId, PeerTagsRoundTripAndForeignTextIsNoTag) {
  const PeerTag t{0x1234, 4242, "bbw_corner_FL"};
  const auto back = decode_peer_tag(encode_peer_tag(t));
  ASSERT_TRUE(back);
  EXPECT_EQ(back->run_id, 0x1234u);
  EXPECT_EQ(back->pid, 4242);
  EXPECT_EQ(back->name, "bbw_corner_FL");
  EXPECT_FALSE(decode_peer_tag(""));
  EXPECT_FALSE(decode_peer_tag("ros2 node"));
  EXPECT_FALSE(decode_peer_tag("bbw run=zz"));
  const auto list = split_peer_tags(join_peer_tags({t, {0x99, 7, "bbw_ccu"}}));
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[1].name, "bbw_ccu");
  EXPECT_TRUE(split_peer_tags("").empty());
}

}  // namespace
