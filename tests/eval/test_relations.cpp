// Relations metric on synthetic trajectories where the answer is known in closed form.
#include <CppUTest/TestHarness.h>
#include <unistd.h>

#include <cmath>
#include <string>
#include <vector>

#include "sdpslam/eval/relations.h"
#include "sdpslam/io/atomic_file.h"
#include "shared_data.h"

using sdpslam::Pose2;
using sdpslam::eval::Relation;
using sdpslam::io::StampedPose;

namespace {
constexpr double kPi = 3.14159265358979323846;

// A curvy ground-truth path sampled every 100 ms.
std::vector<StampedPose> truth(std::size_t n) {
  std::vector<StampedPose> p;
  Pose2 pose{1.0, -2.0, 0.3};
  for (std::size_t i = 0; i < n; ++i) {
    p.push_back({976052905167303LL + static_cast<std::int64_t>(i) * 100000, pose});
    pose = pose.compose(Pose2{0.1, 0.0, 0.05 * std::sin(0.2 * static_cast<double>(i))});
  }
  return p;
}

std::vector<Relation> relations_of(const std::vector<StampedPose>& gt, std::size_t step) {
  std::vector<Relation> r;
  for (std::size_t i = 0; i + step < gt.size(); i += step) {
    r.push_back(Relation{gt[i].stamp_us, gt[i + step].stamp_us, sdpslam::between(gt[i].pose, gt[i + step].pose),
                         static_cast<std::int64_t>(r.size() + 1)});
  }
  return r;
}
}  // namespace

TEST_GROUP(Relations){};

TEST(Relations, perfect_estimate_has_zero_error) {
  const auto gt = truth(50);
  const auto res = sdpslam::eval::evaluate_relations(relations_of(gt, 3), gt);
  LONGS_EQUAL(16, res.relation_count);
  LONGS_EQUAL(16, res.used_count);
  LONGS_EQUAL(16, res.exact_match_count);
  LONGS_EQUAL(0, res.unmatched_count);
  DOUBLES_EQUAL(0.0, res.translation_m.mean, 1e-12);
  DOUBLES_EQUAL(0.0, res.rotation_deg.mean, 1e-9);
}

TEST(Relations, estimate_in_another_global_frame_has_zero_error) {
  // The metric only compares relative displacements: a rigid change of frame is free.
  const auto gt = truth(40);
  std::vector<StampedPose> est = gt;
  const Pose2 frame{100.0, -30.0, 2.0};
  for (auto& p : est) p.pose = frame.compose(p.pose);
  const auto res = sdpslam::eval::evaluate_relations(relations_of(gt, 1), est);
  DOUBLES_EQUAL(0.0, res.translation_m.max, 1e-9);
  DOUBLES_EQUAL(0.0, res.rotation_deg.max, 1e-7);
}

TEST(Relations, known_errors_give_expected_figures) {
  // Three relations: the first exact; in the second the end pose is displaced 0.3 m along
  // its own x axis, so E = δ ⊕ (0.3, 0, 0) ⊕ δ⁻¹ has ‖t‖ = 0.3 and θ = 0; the third is a
  // turn on the spot (t(δ) = 0) over-estimated by 2°, so E = (0, 0, 2°).
  std::vector<StampedPose> gt{{0, {0, 0, 0}},       {1, {1, 0, kPi / 2}}, {2, {1, 1, kPi / 2}},
                              {3, {5, 5, 0.5}},     {4, {5, 5, 1.5}}};
  std::vector<Relation> rel{{0, 1, sdpslam::between(gt[0].pose, gt[1].pose), 1},
                            {1, 2, sdpslam::between(gt[1].pose, gt[2].pose), 2},
                            {3, 4, sdpslam::between(gt[3].pose, gt[4].pose), 3}};
  auto est = gt;
  est[2].pose = gt[2].pose.compose(Pose2{0.3, 0.0, 0.0});
  est[4].pose.heading_rad += 2.0 * kPi / 180.0;
  const auto res = sdpslam::eval::evaluate_relations(rel, est);
  LONGS_EQUAL(3, res.used_count);
  DOUBLES_EQUAL(0.0, res.per_relation[0].translation_error_m, 1e-12);
  DOUBLES_EQUAL(0.3, res.per_relation[1].translation_error_m, 1e-12);
  DOUBLES_EQUAL(0.0, res.per_relation[1].rotation_error_rad, 1e-12);
  DOUBLES_EQUAL(0.0, res.per_relation[2].translation_error_m, 1e-12);
  DOUBLES_EQUAL(2.0 * kPi / 180.0, res.per_relation[2].rotation_error_rad, 1e-12);
  DOUBLES_EQUAL(0.1, res.translation_m.mean, 1e-12);
  DOUBLES_EQUAL(std::sqrt(0.03), res.translation_m.std_dev, 1e-12);  // sample std (n - 1)
  DOUBLES_EQUAL(0.03, res.translation_m2.mean, 1e-12);               // (0 + 0.09 + 0) / 3
  DOUBLES_EQUAL(2.0 / 3.0, res.rotation_deg.mean, 1e-9);
  DOUBLES_EQUAL(4.0 / 3.0, res.rotation_deg2.mean, 1e-9);            // (0 + 0 + 4) / 3
  DOUBLES_EQUAL(0.3, res.translation_m.max, 1e-12);
}

TEST(Relations, rotational_error_wraps_around_pi) {
  std::vector<StampedPose> est{{0, {0, 0, 0}}, {1, {0, 0, kPi - 0.01}}};
  std::vector<Relation> rel{{0, 1, Pose2{0, 0, -kPi + 0.01}, 1}};
  const auto res = sdpslam::eval::evaluate_relations(rel, est);
  DOUBLES_EQUAL(0.02, res.per_relation[0].rotation_error_rad, 1e-9);
}

TEST(Relations, unmatched_relations_are_counted_and_listed_not_dropped_silently) {
  const auto gt = truth(10);
  auto rel = relations_of(gt, 1);
  rel.push_back(Relation{gt[0].stamp_us, gt[9].stamp_us + 5000, Pose2{}, 77});  // 5 ms off: beyond 1 ms
  const auto res = sdpslam::eval::evaluate_relations(rel, gt);
  LONGS_EQUAL(10, res.relation_count);
  LONGS_EQUAL(9, res.used_count);
  LONGS_EQUAL(1, res.unmatched_count);
  LONGS_EQUAL(1, res.unmatched.size());
  LONGS_EQUAL(77, res.unmatched[0].line);
}

TEST(Relations, stamps_off_by_microseconds_match_within_tolerance_but_not_exactly) {
  const auto gt = truth(10);
  auto rel = relations_of(gt, 1);
  rel[0].t1_us += 1;  // e.g. a file printed through floating point
  const auto res = sdpslam::eval::evaluate_relations(rel, gt);
  LONGS_EQUAL(9, res.used_count);
  LONGS_EQUAL(8, res.exact_match_count);
  const auto strict = sdpslam::eval::evaluate_relations(rel, gt, 0);
  LONGS_EQUAL(1, strict.unmatched_count);
}

TEST(Relations, unmatched_list_is_bounded) {
  const auto gt = truth(5);
  std::vector<Relation> rel(100, Relation{1, 2, Pose2{}, 1});
  const auto res = sdpslam::eval::evaluate_relations(rel, gt);
  LONGS_EQUAL(100, res.unmatched_count);
  LONGS_EQUAL(sdpslam::eval::RelationsResult::kMaxUnmatchedKept, res.unmatched.size());
  LONGS_EQUAL(0, res.used_count);
  LONGS_EQUAL(0, res.translation_m.count);
}

// The worst relations name where a run went wrong: worst first, one per event (a
// stretch and its revisit err alike over many relations), at most as many as asked.
TEST(Relations, worst_relations_name_one_relation_per_event_worst_first) {
  const auto gt = truth(400);  // 40 s
  // Relations from three stretches to three later ones (events A, B, C), several each.
  std::vector<Relation> rel;
  const auto add = [&](std::size_t i, std::size_t j) {
    rel.push_back(Relation{gt[i].stamp_us, gt[j].stamp_us, sdpslam::between(gt[i].pose, gt[j].pose),
                           static_cast<std::int64_t>(rel.size() + 1)});
  };
  for (std::size_t k = 0; k < 3; ++k) add(10 + k, 300 + k);  // A
  for (std::size_t k = 0; k < 3; ++k) add(100 + k, 350 + k);  // B
  for (std::size_t k = 0; k < 3; ++k) add(200 + k, 390 + k);  // C
  // The estimate: the truth with the revisits of B shifted 3 m and those of A 1 m.
  std::vector<StampedPose> est = gt;
  const auto shift = [&](std::size_t first, double dx_m) {
    for (std::size_t i = first; i < first + 3; ++i) est[i].pose.x_m += dx_m;
  };
  shift(300, 1.0);
  shift(350, 3.0);
  const auto res = sdpslam::eval::evaluate_relations(rel, est);
  LONGS_EQUAL(9, res.used_count);
  // Events apart by more than 2 s: B (3 m), then A (1 m), then C (0 m).
  const auto worst = sdpslam::eval::worst_relations(res, 5, 2000000);
  LONGS_EQUAL(3, worst.size());
  // Each event's relations err alike (to rounding): which of them stands for it is open.
  const auto in_event = [&](std::size_t w, std::size_t first) {
    const std::int64_t t1 = res.per_relation[w].relation.t1_us;
    return t1 >= gt[first].stamp_us && t1 <= gt[first + 2].stamp_us;
  };
  CHECK_TRUE(in_event(worst[0], 100));
  DOUBLES_EQUAL(3.0, res.per_relation[worst[0]].translation_error_m, 1e-9);
  CHECK_TRUE(in_event(worst[1], 10));
  DOUBLES_EQUAL(1.0, res.per_relation[worst[1]].translation_error_m, 1e-9);
  CHECK_TRUE(in_event(worst[2], 200));
  // At most as many as asked; with events taken as 0.1 s apart, every relation is one.
  LONGS_EQUAL(2, sdpslam::eval::worst_relations(res, 2, 2000000).size());
  LONGS_EQUAL(9, sdpslam::eval::worst_relations(res, 20, 0).size());
}

TEST(Relations, relations_by_span_split_the_error_into_local_steps_and_revisits) {
  const auto gt = truth(1000);  // 100 s, a pose every 0.1 s
  std::vector<Relation> rel;
  const auto add = [&](std::size_t i, std::size_t j) {
    rel.push_back(Relation{gt[i].stamp_us, gt[j].stamp_us, sdpslam::between(gt[i].pose, gt[j].pose),
                           static_cast<std::int64_t>(rel.size() + 1)});
  };
  // Spans 1 s (4 relations), exactly 2 s (1: the edge belongs to the next class),
  // 10 s (1), exactly 60 s (1) and 90 s (2).
  for (std::size_t k = 0; k < 4; ++k) add(100 + k, 110 + k);
  add(200, 220);
  add(300, 400);
  add(0, 600);
  add(5, 905);
  add(6, 906);
  // The estimate: the truth with poses 906 and after 1 m off, so only the last 90 s
  // relation errs (1 m), and pose 110 0.2 m off, so one 1 s relation errs (0.2 m).
  std::vector<StampedPose> est = gt;
  for (std::size_t i = 906; i < est.size(); ++i) est[i].pose.y_m += 1.0;
  est[110].pose.y_m += 0.2;
  const auto res = sdpslam::eval::evaluate_relations(rel, est);
  LONGS_EQUAL(9, res.used_count);
  const auto c = sdpslam::eval::relations_by_span(res, {2000000, 60000000});
  LONGS_EQUAL(3, c.size());
  LONGS_EQUAL(0, c[0].from_us);
  LONGS_EQUAL(2000000, c[0].to_us);
  LONGS_EQUAL(4, c[0].translation_m.count);
  DOUBLES_EQUAL(0.05, c[0].translation_m.mean, 1e-9);
  DOUBLES_EQUAL(0.2, c[0].translation_m.max, 1e-9);
  LONGS_EQUAL(2000000, c[1].from_us);
  LONGS_EQUAL(60000000, c[1].to_us);
  LONGS_EQUAL(2, c[1].translation_m.count);
  DOUBLES_EQUAL(0.0, c[1].translation_m.mean, 1e-9);
  LONGS_EQUAL(60000000, c[2].from_us);
  LONGS_EQUAL(-1, c[2].to_us);
  LONGS_EQUAL(3, c[2].translation_m.count);
  DOUBLES_EQUAL(1.0 / 3.0, c[2].translation_m.mean, 1e-9);
  // Shares of the 1.2 m of error in all.
  DOUBLES_EQUAL(0.2 / 1.2, c[0].share, 1e-9);
  DOUBLES_EQUAL(0.0, c[1].share, 1e-9);
  DOUBLES_EQUAL(1.0 / 1.2, c[2].share, 1e-9);
  // No edges: one class with everything; no relations: empty classes, no shares.
  const auto one = sdpslam::eval::relations_by_span(res, {});
  LONGS_EQUAL(1, one.size());
  LONGS_EQUAL(9, one[0].translation_m.count);
  DOUBLES_EQUAL(1.0, one[0].share, 1e-9);
  const auto none = sdpslam::eval::relations_by_span(sdpslam::eval::RelationsResult{}, {2000000});
  LONGS_EQUAL(2, none.size());
  LONGS_EQUAL(0, none[0].translation_m.count + none[1].translation_m.count);
  DOUBLES_EQUAL(0.0, none[0].share + none[1].share, 0.0);
  CHECK_FALSE(none[0].scale_measured);
  DOUBLES_EQUAL(0.0, none[0].scale_error, 0.0);
}

TEST(Relations, relations_by_span_measure_steps_that_come_out_short_whatever_the_loops_hold) {
  // The truth winds (truth()); the estimate's steps are 2 % short (each step scaled by
  // 0.98 in its own frame), except that it is put back on the truth every 10 s, as loop
  // closures would. Local relations (1 s) see the shrink exactly; relations of 10 s
  // between the poses put back see none; a relation without motion says nothing.
  const auto gt = truth(301);
  // Every step 2 % short; with `reset`, every 100th pose put back on the truth.
  const auto shortened = [&gt](bool reset) {
    std::vector<StampedPose> p = gt;
    for (std::size_t i = 1; i < gt.size(); ++i) {
      const Pose2 step = sdpslam::between(gt[i - 1].pose, gt[i].pose);
      p[i].pose = reset && i % 100 == 0
                      ? gt[i].pose
                      : p[i - 1].pose.compose(Pose2{0.98 * step.x_m, 0.98 * step.y_m, step.heading_rad});
    }
    return p;
  };
  const std::vector<StampedPose> est = shortened(true);
  std::vector<Relation> rel;
  const auto add = [&](std::size_t i, std::size_t j) {
    rel.push_back(Relation{gt[i].stamp_us, gt[j].stamp_us, sdpslam::between(gt[i].pose, gt[j].pose),
                           static_cast<std::int64_t>(rel.size() + 1)});
  };
  for (std::size_t k = 0; k < 290; k += 7) {
    if (k % 100U + 10U < 100U) add(k, k + 10);  // 1 s, within one stretch between resets
  }
  add(0, 100);
  add(100, 200);
  add(0, 300);
  rel.push_back(Relation{gt[5].stamp_us, gt[5].stamp_us, Pose2{}, static_cast<std::int64_t>(rel.size() + 1)});
  const auto res = sdpslam::eval::evaluate_relations(rel, est);
  const auto c = sdpslam::eval::relations_by_span(res, {2000000});
  LONGS_EQUAL(2, c.size());
  CHECK_TRUE(c[0].scale_measured);
  CHECK_TRUE(c[1].scale_measured);
  DOUBLES_EQUAL(-0.02, c[0].scale_error, 1e-9);
  DOUBLES_EQUAL(0.0, c[1].scale_error, 1e-12);
  // Without the resets every class is 2 % short.
  const auto all =
      sdpslam::eval::relations_by_span(sdpslam::eval::evaluate_relations(rel, shortened(false)), {2000000});
  DOUBLES_EQUAL(-0.02, all[0].scale_error, 1e-9);
  DOUBLES_EQUAL(-0.02, all[1].scale_error, 1e-9);
  // Only a relation without motion: nothing measured.
  const std::vector<Relation> still{rel.back()};
  const auto s = sdpslam::eval::relations_by_span(sdpslam::eval::evaluate_relations(still, est), {2000000});
  CHECK_FALSE(s[0].scale_measured);
}

TEST_GROUP(FillWithOdometry){};

TEST(FillWithOdometry, missing_scans_are_last_estimate_composed_with_odometry) {
  // Odometry drifts from the truth; the estimate is the truth at scans 0 and 5 only.
  const auto gt = truth(8);
  std::vector<StampedPose> odom = gt;
  for (std::size_t i = 0; i < odom.size(); ++i) {
    odom[i].pose = Pose2{3.0, 4.0, 1.0}.compose(gt[i].pose).compose(Pose2{0.01 * static_cast<double>(i), 0, 0});
  }
  std::vector<StampedPose> est{gt[0], gt[5]};
  std::vector<StampedPose> full;
  sdpslam::eval::FillReport rep;
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::eval::fill_with_odometry(est, odom, 1000, &full, &rep, &error), error.c_str());
  LONGS_EQUAL(8, full.size());
  LONGS_EQUAL(2, rep.estimated_count);
  LONGS_EQUAL(6, rep.filled_count);
  for (std::size_t k : {0U, 5U}) {
    DOUBLES_EQUAL(gt[k].pose.x_m, full[k].pose.x_m, 0.0);
  }
  for (std::size_t k : {1U, 2U, 3U, 4U}) {
    const Pose2 want = gt[0].pose.compose(sdpslam::between(odom[0].pose, odom[k].pose));
    DOUBLES_EQUAL(want.x_m, full[k].pose.x_m, 1e-12);
    DOUBLES_EQUAL(want.y_m, full[k].pose.y_m, 1e-12);
    DOUBLES_EQUAL(want.heading_rad, full[k].pose.heading_rad, 1e-12);
    CHECK_EQUAL(odom[k].stamp_us, full[k].stamp_us);
  }
  const Pose2 want7 = gt[5].pose.compose(sdpslam::between(odom[5].pose, odom[7].pose));
  DOUBLES_EQUAL(want7.x_m, full[7].pose.x_m, 1e-12);
}

TEST(FillWithOdometry, scans_before_first_estimate_are_filled_backwards) {
  const auto gt = truth(6);
  std::vector<StampedPose> est{gt[3]};
  std::vector<StampedPose> full;
  std::string error;
  CHECK_TRUE(sdpslam::eval::fill_with_odometry(est, gt, 1000, &full, nullptr, &error));
  // Odometry equal to the truth: filling reproduces the truth everywhere.
  for (std::size_t k = 0; k < gt.size(); ++k) {
    DOUBLES_EQUAL(gt[k].pose.x_m, full[k].pose.x_m, 1e-9);
    DOUBLES_EQUAL(gt[k].pose.y_m, full[k].pose.y_m, 1e-9);
  }
}

TEST(FillWithOdometry, estimates_matching_no_scan_are_counted) {
  const auto gt = truth(4);
  std::vector<StampedPose> est{gt[0], {gt[1].stamp_us + 50000, {}}, gt[2], gt[2]};
  std::vector<StampedPose> full;
  sdpslam::eval::FillReport rep;
  std::string error;
  CHECK_TRUE(sdpslam::eval::fill_with_odometry(est, gt, 1000, &full, &rep, &error));
  LONGS_EQUAL(1, rep.unmatched_estimate_count);
  LONGS_EQUAL(1, rep.duplicate_estimate_count);
  LONGS_EQUAL(2, rep.estimated_count);
}

TEST(FillWithOdometry, no_matching_estimate_is_an_error) {
  const auto gt = truth(4);
  std::vector<StampedPose> est{{1, {}}};
  std::vector<StampedPose> full;
  std::string error;
  CHECK_FALSE(sdpslam::eval::fill_with_odometry(est, gt, 1000, &full, nullptr, &error));
  STRCMP_CONTAINS("none of the 1 estimated poses", error.c_str());
  CHECK_FALSE(sdpslam::eval::fill_with_odometry({}, gt, 1000, &full, nullptr, &error));
}

TEST(FillWithOdometry, unordered_scan_odometry_is_refused) {
  auto gt = truth(4);
  std::swap(gt[1], gt[2]);
  std::vector<StampedPose> full;
  std::string error;
  CHECK_FALSE(sdpslam::eval::fill_with_odometry(gt, gt, 1000, &full, nullptr, &error));
  STRCMP_CONTAINS("scan 2", error.c_str());
}

TEST_GROUP(RelationsFile) {
  std::string dir;
  std::string path;
  void setup() override {
    dir = sdpslam::test::make_temp_dir("rel");
    path = dir + "/r.relations";
  }
  void teardown() override {
    ::unlink(path.c_str());
    ::rmdir(dir.c_str());
  }
  void write(const std::string& text) {
    std::string error;
    CHECK_TRUE(sdpslam::io::write_file_atomic(path, text, &error));
  }
};

TEST(RelationsFile, reads_stamps_exactly_and_yaw_as_heading) {
  write("# comment\n976052905.167303 976052911.885496 -0.056990 -0.128430 0.000000 0.000000 0.000000 -1.682210\n\n");
  std::vector<Relation> rel;
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::eval::read_relations(path, &rel, &error), error.c_str());
  LONGS_EQUAL(1, rel.size());
  CHECK_EQUAL(976052905167303LL, rel[0].t1_us);
  CHECK_EQUAL(976052911885496LL, rel[0].t2_us);
  DOUBLES_EQUAL(-0.05699, rel[0].expected.x_m, 0.0);
  DOUBLES_EQUAL(-1.68221, rel[0].expected.heading_rad, 0.0);
  LONGS_EQUAL(2, rel[0].line);
}

TEST(RelationsFile, malformed_line_is_reported_with_file_and_line_and_earlier_kept) {
  write("1 2 0 0 0 0 0 0\n2 3 0 0 0 0 zero 0\n3 4 0 0 0 0 0 0\n");
  std::vector<Relation> rel;
  std::string error;
  CHECK_FALSE(sdpslam::eval::read_relations(path, &rel, &error));
  STRCMP_CONTAINS((path + ":2:").c_str(), error.c_str());
  STRCMP_CONTAINS("pitch", error.c_str());
  LONGS_EQUAL(1, rel.size());
}

TEST(RelationsFile, wrong_column_count_and_bad_stamp_are_errors) {
  std::vector<Relation> rel;
  std::string error;
  write("1 2 0 0 0 0 0\n");
  CHECK_FALSE(sdpslam::eval::read_relations(path, &rel, &error));
  STRCMP_CONTAINS("found 7", error.c_str());
  write("1 2e3 0 0 0 0 0 0\n");
  CHECK_FALSE(sdpslam::eval::read_relations(path, &rel, &error));
  STRCMP_CONTAINS("t2", error.c_str());
}

TEST(RelationsFile, missing_file_is_named) {
  std::vector<Relation> rel;
  std::string error;
  CHECK_FALSE(sdpslam::eval::read_relations(dir + "/nope", &rel, &error));
  STRCMP_CONTAINS("nope", error.c_str());
}
