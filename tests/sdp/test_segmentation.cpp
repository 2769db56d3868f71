// Segmentation decision (Algorithm 1 line 4) and SDP options validation.
#include <CppUTest/TestHarness.h>

#include <cstring>

#include "top/segmentation.h"

using namespace sdpslam;

TEST_GROUP(Segmentation){};

TEST(Segmentation, periodic_by_travel_ends_when_the_distance_is_reached) {
  SdpOptions o;
  o.period_travel_m = 1.0;
  o.min_segment_scans = 2U;
  Segmenter s(o);
  s.start(0, Pose2{});
  SegmentEnd e = SegmentEnd::kNone;
  int scans = 0;
  for (int i = 1; i <= 20 && e == SegmentEnd::kNone; ++i) {
    e = s.on_processed(i * 1000, Pose2{0.25 * i, 0.0, 0.0}, nullptr, 0U);
    scans = i;
  }
  CHECK(e == SegmentEnd::kPeriod);
  LONGS_EQUAL(4, scans);
  DOUBLES_EQUAL(1.0, s.travel_m(), 1e-12);
}

TEST(Segmentation, periodic_by_time_and_by_scan_count) {
  SdpOptions o;
  o.period_travel_m = 0.0;
  o.period_time_s = 2.0;
  o.min_segment_scans = 1U;
  Segmenter s(o);
  s.start(0, Pose2{});
  CHECK(s.on_processed(1000000, Pose2{}, nullptr, 0U) == SegmentEnd::kNone);
  CHECK(s.on_processed(2000000, Pose2{}, nullptr, 0U) == SegmentEnd::kPeriod);
  o.period_time_s = 0.0;
  o.period_scans = 3U;
  s.start(0, Pose2{});
  CHECK(s.on_processed(1, Pose2{}, nullptr, 0U) == SegmentEnd::kNone);
  CHECK(s.on_processed(2, Pose2{}, nullptr, 0U) == SegmentEnd::kNone);
  CHECK(s.on_processed(3, Pose2{}, nullptr, 0U) == SegmentEnd::kPeriod);
}

TEST(Segmentation, dispersion_needs_both_spread_and_minimum_length) {
  SdpOptions o;
  o.segmentation = SegmentationMode::kDispersion;
  o.dispersion_threshold_m = 0.1;
  o.min_segment_scans = 3U;
  Segmenter s(o);
  s.start(0, Pose2{});
  const Pose2 spread[2] = {Pose2{-0.2, 0.0, 0.0}, Pose2{0.2, 0.0, 0.0}};
  const Pose2 tight[2] = {Pose2{-0.01, 0.0, 0.0}, Pose2{0.01, 0.0, 0.0}};
  CHECK(s.on_processed(1, Pose2{}, spread, 2U) == SegmentEnd::kNone);  // too short
  CHECK(s.on_processed(2, Pose2{}, spread, 2U) == SegmentEnd::kNone);
  CHECK(s.on_processed(3, Pose2{}, tight, 2U) == SegmentEnd::kNone);   // not spread
  CHECK(s.on_processed(4, Pose2{}, spread, 2U) == SegmentEnd::kDispersion);
  DOUBLES_EQUAL(0.2, s.last_dispersion_m(), 1e-12);
}

TEST(Segmentation, maximum_length_always_ends_a_segment) {
  SdpOptions o;
  o.segmentation = SegmentationMode::kDispersion;
  o.dispersion_threshold_m = 100.0;
  o.min_segment_scans = 1U;
  o.max_segment_scans = 5U;
  Segmenter s(o);
  s.start(0, Pose2{});
  for (int i = 1; i < 5; ++i) CHECK(s.on_processed(i, Pose2{}, nullptr, 0U) == SegmentEnd::kNone);
  CHECK(s.on_processed(5, Pose2{}, nullptr, 0U) == SegmentEnd::kMaxLength);
}

TEST(Segmentation, dispersion_of_fewer_than_two_poses_is_zero) {
  const Pose2 one{5.0, 5.0, 0.0};
  DOUBLES_EQUAL(0.0, Segmenter::dispersion_m(&one, 1U), 0.0);
  DOUBLES_EQUAL(0.0, Segmenter::dispersion_m(nullptr, 3U), 0.0);
}

TEST(Segmentation, options_reject_out_of_range_values_and_name_them) {
  char why[200];
  SdpOptions o;
  CHECK_TRUE(o.validate(why, sizeof why));
  o.top_particles = 0U;
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "sdp.top_particles") != nullptr);
  o = SdpOptions{};
  o.elite_fraction = 0.7;
  o.worst_fraction = 0.5;
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "elite_fraction + worst_fraction") != nullptr);
  o = SdpOptions{};
  o.period_travel_m = 0.0;
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "periodic") != nullptr);
  o = SdpOptions{};
  o.max_segment_scans = 3U;  // below min_segment_scans
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "max_segment_scans") != nullptr);
}
