#include <CppUTest/TestHarness.h>

#include <limits>
#include <vector>

#include "sdpslam/eval/error_stats.h"
#include "sdpslam/eval/stamp_match.h"

using sdpslam::eval::StampMatch;
using sdpslam::io::StampedPose;

TEST_GROUP(StampMatch) {
  std::vector<StampedPose> poses{{1000000, {}}, {1100000, {}}, {1200000, {}}};
};

TEST(StampMatch, exact_stamp_is_found_as_exact) {
  std::size_t i = 99;
  CHECK(sdpslam::eval::find_stamp(poses, 1100000, 1000, &i) == StampMatch::kExact);
  LONGS_EQUAL(1, i);
}

TEST(StampMatch, stamp_within_tolerance_matches_nearest) {
  std::size_t i = 99;
  CHECK(sdpslam::eval::find_stamp(poses, 1100999, 1000, &i) == StampMatch::kNearest);
  LONGS_EQUAL(1, i);
  CHECK(sdpslam::eval::find_stamp(poses, 1199001, 1000, &i) == StampMatch::kNearest);
  LONGS_EQUAL(2, i);
}

TEST(StampMatch, stamp_just_beyond_tolerance_is_unmatched) {
  std::size_t i = 99;
  CHECK(sdpslam::eval::find_stamp(poses, 1101001, 1000, &i) == StampMatch::kNone);
  CHECK(sdpslam::eval::find_stamp(poses, 998999, 1000, &i) == StampMatch::kNone);
  CHECK(sdpslam::eval::find_stamp(poses, 1300000, 1000, &i) == StampMatch::kNone);
  LONGS_EQUAL(99, i);
}

TEST(StampMatch, zero_tolerance_accepts_only_exact) {
  std::size_t i = 99;
  CHECK(sdpslam::eval::find_stamp(poses, 1000001, 0, &i) == StampMatch::kNone);
  CHECK(sdpslam::eval::find_stamp(poses, 1000000, 0, &i) == StampMatch::kExact);
}

TEST(StampMatch, empty_list_matches_nothing) {
  std::vector<StampedPose> none;
  std::size_t i = 99;
  CHECK(sdpslam::eval::find_stamp(none, 0, 1000000, &i) == StampMatch::kNone);
}

TEST(StampMatch, extreme_stamps_do_not_overflow) {
  std::vector<StampedPose> p{{std::numeric_limits<std::int64_t>::min(), {}}, {std::numeric_limits<std::int64_t>::max(), {}}};
  std::size_t i = 99;
  CHECK(sdpslam::eval::find_stamp(p, 0, 1000, &i) == StampMatch::kNone);
}

TEST(StampMatch, non_increasing_stamps_are_reported_at_first_offender) {
  std::vector<StampedPose> p{{1, {}}, {2, {}}, {2, {}}, {1, {}}};
  std::size_t bad = 0;
  CHECK_FALSE(sdpslam::eval::stamps_strictly_increasing(p, &bad));
  LONGS_EQUAL(2, bad);
  CHECK_TRUE(sdpslam::eval::stamps_strictly_increasing(poses, &bad));
}

TEST_GROUP(ErrorStats){};

TEST(ErrorStats, mean_and_sample_std_dev) {
  const auto s = sdpslam::eval::summarize({2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0});
  LONGS_EQUAL(8, s.count);
  DOUBLES_EQUAL(5.0, s.mean, 1e-12);
  DOUBLES_EQUAL(std::sqrt(32.0 / 7.0), s.std_dev, 1e-12);  // n - 1, not n
  DOUBLES_EQUAL(9.0, s.max, 0.0);
}

TEST(ErrorStats, single_value_has_zero_std_dev_and_empty_is_all_zero) {
  const auto one = sdpslam::eval::summarize({3.0});
  DOUBLES_EQUAL(3.0, one.mean, 0.0);
  DOUBLES_EQUAL(0.0, one.std_dev, 0.0);
  const auto none = sdpslam::eval::summarize({});
  LONGS_EQUAL(0, none.count);
  DOUBLES_EQUAL(0.0, none.mean, 0.0);
}
