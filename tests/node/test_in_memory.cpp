#include "bbw/transport/in_memory.hpp"

#include <gtest/gtest.h>

#include <string>

namespace bbw::transport {

TEST(InMemoryTopic, EveryReceiverGetsEveryMessageInOrderWithItsSender) {
  InMemoryTopic<std::string> topic("t");
  auto a = topic.receiver();
  auto b = topic.receiver();
  auto s1 = topic.sender(7);
  auto s2 = topic.sender(9);
  EXPECT_EQ(s1->peers(), 2);
  EXPECT_EQ(a->peers(), 2);
  EXPECT_TRUE(s1->send("one"));
  EXPECT_TRUE(s2->send("two"));
  std::string m;
  EndpointId from = 0;
  ASSERT_TRUE(a->take(m, from));
  EXPECT_EQ(m, "one");
  EXPECT_EQ(from, 7u);
  ASSERT_TRUE(a->take(m, from));
  EXPECT_EQ(m, "two");
  EXPECT_EQ(from, 9u);
  EXPECT_FALSE(a->take(m, from));
  EXPECT_EQ(b->waiting(), 2u);  // b's copies are its own
  ASSERT_TRUE(b->take(m));
  EXPECT_EQ(m, "one");
  EXPECT_EQ(topic.sent(), 2u);
}

TEST(InMemoryTopic, AReceiverGoneIsNoLongerServed) {
  InMemoryTopic<int> topic("t");
  auto s = topic.sender(1);
  {
    auto r = topic.receiver();
    EXPECT_EQ(s->peers(), 1);
  }
  EXPECT_EQ(s->peers(), 0);
  EXPECT_TRUE(s->send(3));  // nobody listening: delivered to nobody, no crash
}

}  // namespace bbw::transport
