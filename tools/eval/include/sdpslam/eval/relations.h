#pragma once
// The relations metric of Kümmerle, Steder, Dornhege, Ruhnke, Grisetti, Stachniss and
// Kleiner, "On measuring the accuracy of SLAM algorithms", Autonomous Robots 27(4), 2009,
// §III (Eq. 2-3) as used with the Freiburg benchmark `.relations` files:
//
//   for each relation (t1, t2, expected):  E = (p1⁻¹ ⊕ p2) ⊕ expected⁻¹
//   translational error ‖t(E)‖ (m), rotational error |θ(E)| (rad, reported in degrees)
//
// reported as mean ± sample standard deviation of the absolute and of the squared errors.
// p1, p2 are the estimated poses of the laser scans carrying stamps t1, t2.
#include <cstdint>
#include <istream>
#include <string>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/eval/error_stats.h"
#include "sdpslam/eval/stamp_match.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::eval {

struct Relation {
  std::int64_t t1_us = 0;
  std::int64_t t2_us = 0;
  Pose2 expected;        // true pose at t2 in the frame of the true pose at t1
  std::int64_t line = 0; // 1-based line in the .relations file
};

// Reads `t1 t2 x y z roll pitch yaw` lines (stamps exact to the µs; z, roll, pitch must
// be numbers and are ignored: the benchmark is planar). Blank lines and '#' comments are
// skipped. False iff the file cannot be read or a line is malformed; `error` then says
// "file:line: reason" and `*relations` holds the relations read before that line.
bool read_relations(const std::string& path, std::vector<Relation>* relations, std::string* error);
// The same from a stream read to its end; `name` stands for the file in messages.
bool read_relations(std::istream& in, const std::string& name, std::vector<Relation>* relations, std::string* error);

// Completes a possibly sparse estimate into one pose per laser scan, as the benchmark
// prescribes ("fill missing scans with the last estimate composed with odometry"):
// for scan k without an estimate, with j the last scan at or before k that has one,
//   pose_k = estimate_j ⊕ between(odom_j, odom_k).
// Scans before the first estimate are filled backwards from the first estimate by the
// same formula. Estimate stamps are matched to scan stamps with `tolerance_us`
// (stamp_match.h); `scan_odometry` holds the log's odometry pose at every laser scan,
// ascending by stamp. The output has the scan stamps.
struct FillReport {
  std::size_t scan_count = 0;
  std::size_t estimated_count = 0;  // scans that received an estimate
  std::size_t filled_count = 0;     // scans completed from odometry
  std::size_t unmatched_estimate_count = 0;  // estimates whose stamp matches no scan
  std::size_t duplicate_estimate_count = 0;  // estimates for a scan that already had one (later wins)
};
// False iff `scan_odometry` is not strictly increasing or no estimate matches any scan
// (`error` says which).
bool fill_with_odometry(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& scan_odometry,
                        std::int64_t tolerance_us, std::vector<io::StampedPose>* per_scan, FillReport* report,
                        std::string* error);

struct RelationResult {
  Relation relation;
  Pose2 error;  // E
  double translation_error_m = 0.0;
  double rotation_error_rad = 0.0;
};

struct RelationsResult {
  std::size_t relation_count = 0;
  std::size_t used_count = 0;            // relations with both stamps matched
  std::size_t exact_match_count = 0;     // ... both matched exactly
  std::size_t unmatched_count = 0;       // relations left out: a stamp matched no pose
  std::vector<Relation> unmatched;       // the first kMaxUnmatchedKept of them
  static constexpr std::size_t kMaxUnmatchedKept = 20;

  ErrorStats translation_m;    // |t(E)|
  ErrorStats translation_m2;   // |t(E)|²
  ErrorStats rotation_deg;     // |θ(E)|
  ErrorStats rotation_deg2;    // |θ(E)|²
  std::vector<RelationResult> per_relation;  // in file order, used relations only
};

// Evaluates `relations` against `per_scan` (ascending by stamp; one pose per laser scan,
// e.g. from fill_with_odometry). Relations whose stamps match no pose are counted and
// listed, never silently dropped.
RelationsResult evaluate_relations(const std::vector<Relation>& relations, const std::vector<io::StampedPose>& per_scan,
                                   std::int64_t tolerance_us = kDefaultStampToleranceUs);

// Where a trajectory went wrong: the used relations with the largest translational
// errors, worst first, at most `count`, one per event. A relation is left out when both
// its stamps lie within `apart_us` of the stamps of one already chosen: the relations
// between one stretch and one revisit of it err alike, and would hide the next event.
// Indices into result.per_relation; ties keep file order.
std::vector<std::size_t> worst_relations(const RelationsResult& result, std::size_t count, std::int64_t apart_us);

// Local error or revisits: the used relations split by their span |t2 − t1|. A log's
// relations mix pairs of nearby scans (what the odometry and the scan matching get
// right or wrong step by step) with pairs of a place and its revisit (what the loops get
// right or wrong); the overall mean hides which of the two a run loses. Class k holds
// the spans in [edges_us[k − 1], edges_us[k]) (edges ascending; class 0 from 0, the last
// to no end): edges.size() + 1 classes, each with its translational error and its share
// of the sum of all used relations' translational errors (0 when that sum is 0).
// Each class also says whether the estimate's displacements come out shorter or longer
// than the true ones: the along-track scale error, the least-squares fit of the
// estimated displacement's error onto the true displacement, Σ (t_est − t_true)·t_true /
// Σ |t_true|² over the class (−0.01: 1 % short; weighted by length², so relations that
// barely move, whose direction says little, count little). A map whose steps come out
// short everywhere shows it in the local class even when its loops hold the whole in
// place. 0 with scale_measured false when no relation of the class moves.
struct SpanClass {
  std::int64_t from_us = 0;
  std::int64_t to_us = -1;  // -1: no upper end
  ErrorStats translation_m;
  double share = 0.0;
  double scale_error = 0.0;
  bool scale_measured = false;
};
std::vector<SpanClass> relations_by_span(const RelationsResult& result, const std::vector<std::int64_t>& edges_us);

}  // namespace sdpslam::eval
