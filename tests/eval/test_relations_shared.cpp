// The relations metric on the Freiburg benchmark logs reproduces the published
// raw-odometry figures (../shared/datasets/README.md): Intel 7.37 ± 14.46 m,
// ACES 0.56 ± 2.72 m, mean ± sample std of the absolute translational error.
#include <CppUTest/TestHarness.h>

#include <string>
#include <vector>

#include "sdpslam/eval/log_scans.h"
#include "sdpslam/eval/relations.h"
#include "shared_data.h"

using sdpslam::io::StampedPose;

namespace {

struct Benchmark {
  std::vector<StampedPose> scans;
  std::vector<sdpslam::eval::Relation> relations;
  sdpslam::eval::LogScansReport report;
};

Benchmark load(const char* name) {
  Benchmark b;
  const std::string log = sdpslam::test::shared_path(std::string("datasets/") + name + ".clf");
  const std::string rel = sdpslam::test::shared_path(std::string("datasets/") + name + ".relations");
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::eval::read_log_scan_odometry(log, &b.scans, &b.report, &error), error.c_str());
  CHECK_TRUE_TEXT(sdpslam::eval::read_relations(rel, &b.relations, &error), error.c_str());
  return b;
}

}  // namespace

TEST_GROUP(RelationsBenchmark){};

TEST(RelationsBenchmark, intel_raw_odometry_matches_published_7_37_pm_14_46) {
  const Benchmark b = load("intel");
  LONGS_EQUAL(13631, b.scans.size());
  LONGS_EQUAL(0, b.report.malformed_line_count);
  LONGS_EQUAL(631, b.report.out_of_order_count);  // sorted by stamp before matching
  const auto res = sdpslam::eval::evaluate_relations(b.relations, b.scans);
  LONGS_EQUAL(2984, res.relation_count);
  LONGS_EQUAL(2984, res.exact_match_count);  // every relation stamp is a scan stamp, to the µs
  LONGS_EQUAL(0, res.unmatched_count);
  DOUBLES_EQUAL(7.37, res.translation_m.mean, 0.01);
  DOUBLES_EQUAL(14.46, res.translation_m.std_dev, 0.01);
}

TEST(RelationsBenchmark, aces_raw_odometry_matches_published_0_56_pm_2_72) {
  const Benchmark b = load("aces");
  LONGS_EQUAL(7374, b.scans.size());
  const auto res = sdpslam::eval::evaluate_relations(b.relations, b.scans);
  LONGS_EQUAL(1279, res.relation_count);
  LONGS_EQUAL(1279, res.exact_match_count);
  LONGS_EQUAL(0, res.unmatched_count);
  DOUBLES_EQUAL(0.56, res.translation_m.mean, 0.01);
  DOUBLES_EQUAL(2.72, res.translation_m.std_dev, 0.01);
}

// Filling a sparse copy of the odometry with odometry gives the odometry back: the
// figures do not change when only every 10th scan is "estimated".
TEST(RelationsBenchmark, sparse_odometry_filled_with_odometry_scores_like_full_odometry) {
  const Benchmark b = load("aces");
  std::vector<StampedPose> sparse;
  for (std::size_t i = 0; i < b.scans.size(); i += 10) sparse.push_back(b.scans[i]);
  std::vector<StampedPose> filled;
  sdpslam::eval::FillReport rep;
  std::string error;
  CHECK_TRUE_TEXT(sdpslam::eval::fill_with_odometry(sparse, b.scans, sdpslam::eval::kDefaultStampToleranceUs, &filled,
                                                    &rep, &error),
                  error.c_str());
  LONGS_EQUAL(b.scans.size() - sparse.size(), rep.filled_count);
  const auto full = sdpslam::eval::evaluate_relations(b.relations, b.scans);
  const auto res = sdpslam::eval::evaluate_relations(b.relations, filled);
  DOUBLES_EQUAL(full.translation_m.mean, res.translation_m.mean, 1e-9);
  DOUBLES_EQUAL(full.rotation_deg.mean, res.rotation_deg.mean, 1e-7);
}
