// Loop constraints checked against a ground truth (tools/eval/.../loops.h): a constraint
// built from the true frames has no error, one moved by a known amount has that error
// and lands in its bin, frames whose origin is not the robot's pose are handled, an
// unknown origin is counted apart, and a malformed line is named with file:line.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/eval/loops.h"

using namespace sdpslam;
using namespace sdpslam::eval;

namespace {

// The robot drives around: poses at 1 s steps.
std::vector<io::StampedPose> truth() {
  std::vector<io::StampedPose> v;
  for (int k = 0; k < 10; ++k) {
    v.push_back(io::StampedPose{1000000LL * k, Pose2{2.0 * k, 0.5 * k, 0.1 * k}});
  }
  return v;
}

// The loop between the levels that started at seconds a and b, each in a frame where
// the robot's start pose was `ia` / `ib`, moved by (dx, dy) in the older frame.
LoopLine loop(int a, int b, const Pose2& ia, const Pose2& ib, double dx, double dy, bool searched, bool used) {
  const std::vector<io::StampedPose> gt = truth();
  LoopLine l;
  l.older_level = static_cast<std::uint32_t>(a);
  l.newer_level = static_cast<std::uint32_t>(b);
  l.searched = searched;
  l.used = used;
  l.older_known = l.newer_known = true;
  l.older_stamp_us = gt[static_cast<std::size_t>(a)].stamp_us;
  l.newer_stamp_us = gt[static_cast<std::size_t>(b)].stamp_us;
  l.older_initial = ia;
  l.newer_initial = ib;
  const Pose2 fa = gt[static_cast<std::size_t>(a)].pose.compose(ia.inverse());
  const Pose2 fb = gt[static_cast<std::size_t>(b)].pose.compose(ib.inverse());
  l.z = between(fa, fb);
  l.z.x_m += dx;
  l.z.y_m += dy;
  return l;
}

}  // namespace

TEST_GROUP(Loops){};

TEST(Loops, errors_are_measured_between_the_true_frames_and_binned) {
  const Pose2 far_origin{35.0, -12.0, 0.7};  // a grid frame: the robot far from its origin
  std::vector<LoopLine> lines = {
      loop(1, 7, Pose2{}, Pose2{}, 0.0, 0.0, true, true),
      loop(2, 8, far_origin, Pose2{3.0, 4.0, -1.0}, 0.3, 0.4, false, true),   // 0.5 m: between
      loop(3, 9, Pose2{1.0, 1.0, 0.2}, far_origin, 6.0, 0.0, true, false),   // one door along
      loop(0, 5, Pose2{}, Pose2{}, 0.0, 0.2, false, false),
  };
  lines.push_back(lines[0]);
  lines.back().newer_known = false;
  const LoopsResult r = check_loops(lines, truth(), 1000);
  UNSIGNED_LONGS_EQUAL(5U, r.count);
  UNSIGNED_LONGS_EQUAL(1U, r.unmatched);
  DOUBLES_EQUAL(0.0, r.checks[0].error_m, 1e-9);
  DOUBLES_EQUAL(0.5, r.checks[1].error_m, 1e-9);
  DOUBLES_EQUAL(6.0, r.checks[2].error_m, 1e-9);
  DOUBLES_EQUAL(0.2, r.checks[3].error_m, 1e-9);
  CHECK_FALSE(r.checks[4].matched);
  UNSIGNED_LONGS_EQUAL(2U, r.search.count);
  UNSIGNED_LONGS_EQUAL(1U, r.search.right);
  UNSIGNED_LONGS_EQUAL(1U, r.search.wrong);
  DOUBLES_EQUAL(6.0, r.search.max_m, 1e-9);
  UNSIGNED_LONGS_EQUAL(2U, r.icp.count);
  UNSIGNED_LONGS_EQUAL(1U, r.icp.right);
  UNSIGNED_LONGS_EQUAL(1U, r.icp.between);
  UNSIGNED_LONGS_EQUAL(2U, r.used.count);
  UNSIGNED_LONGS_EQUAL(1U, r.used.right);
  UNSIGNED_LONGS_EQUAL(1U, r.used.between);
  UNSIGNED_LONGS_EQUAL(0U, r.used.wrong);
  // A heading error alone.
  std::vector<LoopLine> turned = {loop(1, 7, Pose2{}, Pose2{}, 0.0, 0.0, true, true)};
  turned[0].z.heading_rad += 0.05;
  DOUBLES_EQUAL(0.05, check_loops(turned, truth(), 1000).checks[0].heading_error_rad, 1e-9);
}

TEST(Loops, a_stamp_without_ground_truth_is_unmatched_not_guessed) {
  std::vector<LoopLine> lines = {loop(1, 7, Pose2{}, Pose2{}, 0.0, 0.0, true, true)};
  lines[0].older_stamp_us += 500000;  // half-way between two ground-truth poses
  const LoopsResult r = check_loops(lines, truth(), 1000);
  UNSIGNED_LONGS_EQUAL(1U, r.unmatched);
  UNSIGNED_LONGS_EQUAL(0U, r.search.count);
  lines[0].older_stamp_us -= 499999;  // 1 µs off: the same scan
  UNSIGNED_LONGS_EQUAL(0U, check_loops(lines, truth(), 1000).unmatched);
}

TEST(Loops, reads_what_the_runner_writes_and_names_a_bad_line) {
  std::istringstream good(
      "# sdpslam loop constraints: ...\n"
      "0 3 icp 1 0.043562 0.047548 0.023402 0.002015701 999999999.999999 0.000000 0.000000 0.000000000 "
      "1000000049.900000 -3.319087 -0.039924 0.066222902\n"
      "2 11 search 0 0.040743 0.185872 -0.124176 -0.002032312 - 0 0 0 1000000179.400000 -4.327973 14.430537 "
      "-1.539741341\n");
  std::vector<LoopLine> lines;
  std::string error;
  CHECK_TRUE(read_loops(good, "loops.tsv", &lines, &error));
  UNSIGNED_LONGS_EQUAL(2U, lines.size());
  CHECK_FALSE(lines[0].searched);
  CHECK_TRUE(lines[0].used);
  LONGS_EQUAL(999999999999999LL, lines[0].older_stamp_us);
  DOUBLES_EQUAL(0.066222902, lines[0].newer_initial.heading_rad, 1e-12);
  CHECK_TRUE(lines[1].searched);
  CHECK_FALSE(lines[1].used);
  CHECK_FALSE(lines[1].older_known);
  CHECK_TRUE(lines[1].newer_known);
  const char* bad[] = {
      "0 3 maybe 1 0.04 0 0 0 1.0 0 0 0 2.0 0 0 0\n",         // source
      "0 3 icp 2 0.04 0 0 0 1.0 0 0 0 2.0 0 0 0\n",           // used
      "0 3 icp 1 0.04 0 0 0 1.0 0 0 0 2.0 0 0\n",             // short
      "0 3 icp 1 0.04 0 0 0 1.0 0 0 0 2.0 0 0 0 extra\n",     // long
      "0 3 icp 1 nan 0 0 0 1.0 0 0 0 2.0 0 0 0\n",            // not finite
      "0 3 icp 1 0.04 0 0 0 yesterday 0 0 0 2.0 0 0 0\n",     // stamp
  };
  for (const char* b : bad) {
    std::istringstream in(std::string("# c\n0 3 icp 1 0.04 0 0 0 1.0 0 0 0 2.0 0 0 0\n") + b);
    std::vector<LoopLine> kept;
    CHECK_FALSE_TEXT(read_loops(in, "l.tsv", &kept, &error), b);
    STRCMP_CONTAINS("l.tsv:3: expected", error.c_str());
    UNSIGNED_LONGS_EQUAL(1U, kept.size());
  }
  CHECK_FALSE(read_loops(std::string("/nonexistent/loops.tsv"), &lines, &error));
  STRCMP_CONTAINS("cannot open '/nonexistent/loops.tsv'", error.c_str());
}
