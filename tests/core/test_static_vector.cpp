#include <CppUTest/TestHarness.h>

#include "sdpslam/core/static_vector.h"

namespace {
struct Counted {
  static int live;
  int v;
  Counted(int x = 0) : v(x) { ++live; }
  Counted(const Counted& o) : v(o.v) { ++live; }
  Counted& operator=(const Counted&) = default;
  ~Counted() { --live; }
};
int Counted::live = 0;
}  // namespace

TEST_GROUP(StaticVector) {
  void setup() override { Counted::live = 0; }
};

TEST(StaticVector, push_until_full_then_refuse_and_count) {
  sdpslam::StaticVector<int, 3> v;
  CHECK_TRUE(v.push_back(1));
  CHECK_TRUE(v.push_back(2));
  CHECK_TRUE(v.push_back(3));
  CHECK_TRUE(v.full());
  CHECK_FALSE(v.push_back(4));
  LONGS_EQUAL(1, v.overflow_count());
  LONGS_EQUAL(3, v.size());
  LONGS_EQUAL(3, v.back());
}

TEST(StaticVector, pop_on_empty_is_refused) {
  sdpslam::StaticVector<int, 2> v;
  CHECK_FALSE(v.pop_back());
  CHECK_TRUE(v.empty());
}

TEST(StaticVector, elements_are_destroyed_on_clear_and_destruction) {
  {
    sdpslam::StaticVector<Counted, 4> v;
    v.emplace_back(1);
    v.emplace_back(2);
    LONGS_EQUAL(2, Counted::live);
    v.clear();
    LONGS_EQUAL(0, Counted::live);
    v.emplace_back(3);
  }
  LONGS_EQUAL(0, Counted::live);
}

TEST(StaticVector, swap_remove_moves_last_into_hole) {
  sdpslam::StaticVector<int, 4> v;
  for (int i = 0; i < 4; ++i) v.push_back(i * 10);
  CHECK_TRUE(v.swap_remove(1));
  LONGS_EQUAL(3, v.size());
  LONGS_EQUAL(30, v[1]);
  CHECK_FALSE(v.swap_remove(3));
}

TEST(StaticVector, resize_beyond_capacity_is_refused) {
  sdpslam::StaticVector<int, 4> v;
  CHECK_TRUE(v.resize(2));
  LONGS_EQUAL(0, v[1]);
  CHECK_FALSE(v.resize(5));
  LONGS_EQUAL(2, v.size());
}

TEST(StaticVector, copy_is_deep_and_independent) {
  sdpslam::StaticVector<int, 4> a;
  a.push_back(1);
  sdpslam::StaticVector<int, 4> b = a;
  b[0] = 2;
  LONGS_EQUAL(1, a[0]);
  LONGS_EQUAL(2, b[0]);
}
