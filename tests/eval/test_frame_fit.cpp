// Rigid fit of segment frames to relations (eval/frame_fit.h) on synthetic runs whose
// frames were displaced by known amounts.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "rectangle_run.h"
#include "sdpslam/eval/frame_fit.h"
#include "sdpslam/eval/relations.h"

using sdpslam::Pose2;
using sdpslam::eval::FrameFitResult;
using sdpslam::eval::Relation;
using sdpslam::eval::SegmentStart;
using sdpslam::io::StampedPose;

namespace {

constexpr std::size_t kPerSegment = 47U;

// A robot driving three times round a 6 m × 4 m rectangle, one scan every 10 cm.
std::vector<StampedPose> truth() { return sdpslam::test::rectangle_run(3); }

// Consecutive scans, and each scan with the same place one and two laps later.
std::vector<Relation> relations_of(const std::vector<StampedPose>& gt) {
  std::vector<Relation> r;
  const std::size_t lap = gt.size() / 3U;
  auto add = [&](std::size_t i, std::size_t j) {
    r.push_back(Relation{gt[i].stamp_us, gt[j].stamp_us, sdpslam::between(gt[i].pose, gt[j].pose),
                         static_cast<std::int64_t>(r.size() + 1U)});
  };
  for (std::size_t i = 0; i + 1U < gt.size(); ++i) add(i, i + 1U);
  for (std::size_t i = 0; i < lap; i += 3U) {
    add(i, i + lap);
    add(i, i + 2U * lap);
  }
  return r;
}

std::vector<SegmentStart> segments_of(const std::vector<StampedPose>& gt) {
  return sdpslam::test::segments_every(gt, kPerSegment);
}

// Each segment's scans moved rigidly: turned about the segment's first scan and shifted,
// by amounts that differ from segment to segment; plus, optionally, a deterministic
// wobble of every scan (errors within the segments, which no frame can take away).
std::vector<StampedPose> displaced(const std::vector<StampedPose>& gt, double wobble_m, double frame_scale = 1.0) {
  std::vector<StampedPose> out = gt;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    const std::size_t seg = i / kPerSegment;
    const double k = static_cast<double>(seg);
    const Pose2 frame{frame_scale * 0.05 * std::sin(1.3 * k), frame_scale * 0.04 * std::cos(0.7 * k),
                      frame_scale * 0.01 * std::sin(2.1 * k + 0.5)};
    const Pose2 anchor = gt[seg * kPerSegment].pose;
    out[i].pose = anchor.compose(frame).compose(anchor.inverse().compose(gt[i].pose));
    out[i].pose.x_m += wobble_m * std::sin(0.9 * static_cast<double>(i));
    out[i].pose.y_m += wobble_m * std::cos(1.7 * static_cast<double>(i));
  }
  return out;
}

}  // namespace

TEST_GROUP(FrameFit){};

// Frames displaced rigidly, nothing else wrong: the fit puts them back, and the error
// across segments vanishes while the relations within segments had none to begin with.
TEST(FrameFit, rigidly_displaced_frames_are_put_back) {
  const std::vector<StampedPose> gt = truth();
  const std::vector<Relation> rel = relations_of(gt);
  const std::vector<SegmentStart> seg = segments_of(gt);
  const FrameFitResult f = sdpslam::eval::fit_segment_frames(rel, displaced(gt, 0.0), seg);
  LONGS_EQUAL(rel.size(), f.all.count);
  LONGS_EQUAL(f.all.count, f.within.count + f.across.count);
  CHECK_TRUE(f.across.count > 100U);
  LONGS_EQUAL(seg.size() - 1U, f.segments_moved);
  CHECK_TRUE(f.across.mean_m > 0.02);
  CHECK_TRUE(f.across.fitted_mean_m < 1.0e-4);
  DOUBLES_EQUAL(0.0, f.within.mean_m, 1.0e-9);
  DOUBLES_EQUAL(0.0, f.within.fitted_mean_m, 1.0e-9);
  CHECK_TRUE(f.converged);
}

// Errors within the segments stay: the fit leaves the relations within one segment as
// they were; across segments it does at least as well as the true frames.
TEST(FrameFit, errors_within_segments_stay) {
  const std::vector<StampedPose> gt = truth();
  const std::vector<Relation> rel = relations_of(gt);
  const std::vector<SegmentStart> seg = segments_of(gt);
  const FrameFitResult f = sdpslam::eval::fit_segment_frames(rel, displaced(gt, 0.01), seg);
  // The same wobble with every frame where it belongs: what the true placement scores.
  const FrameFitResult placed = sdpslam::eval::fit_segment_frames(rel, displaced(gt, 0.01, 0.0), seg);
  CHECK_TRUE(f.within.mean_m > 0.005);
  DOUBLES_EQUAL(f.within.mean_m, f.within.fitted_mean_m, 1.0e-12);
  CHECK_TRUE(f.across.fitted_mean_m > 0.005);
  CHECK_TRUE(f.across.fitted_mean_m < f.across.mean_m);
  CHECK_TRUE(f.all.fitted_mean_m < f.all.mean_m);
  // It places the frames at least as well as where they truly belong.
  CHECK_TRUE(f.across.fitted_mean_m <= placed.across.mean_m + 1.0e-9);
  CHECK_TRUE(f.across.mean_m > 2.0 * placed.across.mean_m);
}

// A run with one segment has nothing to place: every relation lies within it.
TEST(FrameFit, one_segment_moves_nothing) {
  const std::vector<StampedPose> gt = truth();
  const std::vector<Relation> rel = relations_of(gt);
  const std::vector<SegmentStart> one{{0U, gt.front().stamp_us - 1}};
  const FrameFitResult f = sdpslam::eval::fit_segment_frames(rel, displaced(gt, 0.0), one);
  LONGS_EQUAL(0U, f.segments_moved);
  LONGS_EQUAL(0U, f.across.count);
  LONGS_EQUAL(rel.size(), f.within.count);
  DOUBLES_EQUAL(f.all.mean_m, f.all.fitted_mean_m, 0.0);
}

// A scan belongs to the last segment that started before it; its start stamp is the
// previous segment's last scan.
TEST(FrameFit, a_scan_belongs_to_the_last_segment_started_before_it) {
  const std::vector<SegmentStart> s{{0U, 99}, {1U, 200}, {4U, 300}};
  LONGS_EQUAL(0U, sdpslam::eval::segment_of(s, 50));
  LONGS_EQUAL(0U, sdpslam::eval::segment_of(s, 100));
  LONGS_EQUAL(0U, sdpslam::eval::segment_of(s, 200));
  LONGS_EQUAL(1U, sdpslam::eval::segment_of(s, 201));
  LONGS_EQUAL(1U, sdpslam::eval::segment_of(s, 300));
  LONGS_EQUAL(2U, sdpslam::eval::segment_of(s, 301));
}

TEST(FrameFit, segments_file_is_read_and_bad_lines_are_named) {
  std::vector<SegmentStart> s;
  std::string error;
  std::istringstream good("# comment\n0 10.000000\n\n3 12.500000\n");
  CHECK_TRUE(sdpslam::eval::read_segments(good, "s.tsv", &s, &error));
  LONGS_EQUAL(2U, s.size());
  LONGS_EQUAL(3U, s[1].level);
  LONGS_EQUAL(12500000, s[1].start_us);

  std::istringstream columns("0 10.0\n1 11.0 2\n");
  CHECK_FALSE(sdpslam::eval::read_segments(columns, "s.tsv", &s, &error));
  STRCMP_CONTAINS("s.tsv:2: expected 2 columns", error.c_str());
  LONGS_EQUAL(1U, s.size());

  std::istringstream level("x 10.0\n");
  CHECK_FALSE(sdpslam::eval::read_segments(level, "s.tsv", &s, &error));
  STRCMP_CONTAINS("s.tsv:1: bad level 'x'", error.c_str());

  std::istringstream stamp("0 ten\n");
  CHECK_FALSE(sdpslam::eval::read_segments(stamp, "s.tsv", &s, &error));
  STRCMP_CONTAINS("s.tsv:1: bad start stamp 'ten'", error.c_str());

  std::istringstream order("0 10.0\n1 9.0\n");
  CHECK_FALSE(sdpslam::eval::read_segments(order, "s.tsv", &s, &error));
  STRCMP_CONTAINS("s.tsv:2: level and start stamp must increase", error.c_str());

  CHECK_FALSE(sdpslam::eval::read_segments(std::string("/nonexistent/segments.tsv"), &s, &error));
  STRCMP_CONTAINS("cannot open '/nonexistent/segments.tsv'", error.c_str());
}
