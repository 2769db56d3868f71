#include <CppUTest/TestHarness.h>

#include "sdpslam/core/ring_buffer.h"

TEST_GROUP(RingBuffer){};

TEST(RingBuffer, fifo_order_across_wrap) {
  sdpslam::RingBuffer<int, 3> r;
  int out = 0;
  for (int round = 0; round < 5; ++round) {
    CHECK_TRUE(r.push(round * 2));
    CHECK_TRUE(r.push(round * 2 + 1));
    CHECK_TRUE(r.pop(out));
    LONGS_EQUAL(round * 2, out);
    CHECK_TRUE(r.pop(out));
    LONGS_EQUAL(round * 2 + 1, out);
  }
  CHECK_TRUE(r.empty());
}

TEST(RingBuffer, push_on_full_is_refused_and_counted) {
  sdpslam::RingBuffer<int, 2> r;
  r.push(1);
  r.push(2);
  CHECK_FALSE(r.push(3));
  LONGS_EQUAL(1, r.refused_count());
  LONGS_EQUAL(1, r.front());
}

TEST(RingBuffer, push_overwrite_drops_oldest_and_counts) {
  sdpslam::RingBuffer<int, 2> r;
  r.push_overwrite(1);
  r.push_overwrite(2);
  r.push_overwrite(3);
  LONGS_EQUAL(1, r.overwritten_count());
  LONGS_EQUAL(2, r[0]);
  LONGS_EQUAL(3, r[1]);
  LONGS_EQUAL(3, r.back());
}

TEST(RingBuffer, pop_on_empty_is_refused) {
  sdpslam::RingBuffer<int, 2> r;
  int out = 7;
  CHECK_FALSE(r.pop(out));
  LONGS_EQUAL(7, out);
}
