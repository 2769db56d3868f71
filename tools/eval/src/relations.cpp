// Relations metric (see relations.h).
#include "sdpslam/eval/relations.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "sdpslam/io/text_table.h"

namespace sdpslam::eval {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

bool parse_finite(const std::string& token, double* value) {
  const char* begin = token.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (token.empty() || end != begin + token.size() || errno == ERANGE || !std::isfinite(v)) return false;
  *value = v;
  return true;
}

}  // namespace

bool read_relations(const std::string& path, std::vector<Relation>* relations, std::string* error) {
  relations->clear();
  std::ifstream in;
  return io::open_for_reading(path, &in, error) && read_relations(in, path, relations, error);
}

bool read_relations(std::istream& in, const std::string& path, std::vector<Relation>* relations, std::string* error) {
  relations->clear();
  static const char* const kColumns[] = {"t1", "t2", "x", "y", "z", "roll", "pitch", "yaw"};
  return io::read_table(
      in, path,
      [relations](const std::vector<std::string>& tokens, std::int64_t line) -> std::string {
        if (tokens.size() != 8) {
          return "expected 8 columns (t1 t2 x y z roll pitch yaw), found " + std::to_string(tokens.size());
        }
        Relation r;
        r.line = line;
        if (!io::parse_stamp_us(tokens[0], &r.t1_us)) return "bad timestamp t1 '" + tokens[0] + "'";
        if (!io::parse_stamp_us(tokens[1], &r.t2_us)) return "bad timestamp t2 '" + tokens[1] + "'";
        double v[6] = {};
        for (std::size_t k = 2; k < 8; ++k) {
          if (!parse_finite(tokens[k], &v[k - 2])) {
            return std::string("column ") + kColumns[k] + " '" + tokens[k] + "' is not a finite number";
          }
        }
        r.expected = Pose2{v[0], v[1], normalize_angle_rad(v[5])};
        relations->push_back(r);
        return std::string();
      },
      error);
}

bool fill_with_odometry(const std::vector<io::StampedPose>& estimate, const std::vector<io::StampedPose>& scan_odometry,
                        std::int64_t tolerance_us, std::vector<io::StampedPose>* per_scan, FillReport* report,
                        std::string* error) {
  FillReport rep;
  rep.scan_count = scan_odometry.size();
  std::size_t bad = 0;
  if (!stamps_strictly_increasing(scan_odometry, &bad)) {
    if (error != nullptr) {
      *error = "scan stamps are not strictly increasing at scan " + std::to_string(bad) + " (" +
               io::format_stamp_us(scan_odometry[bad].stamp_us) + " after " +
               io::format_stamp_us(scan_odometry[bad - 1].stamp_us) + ")";
    }
    if (report != nullptr) *report = rep;
    return false;
  }
  std::vector<io::StampedPose> out(scan_odometry.size());
  std::vector<bool> has(scan_odometry.size(), false);
  for (const io::StampedPose& e : estimate) {
    std::size_t k = 0;
    if (find_stamp(scan_odometry, e.stamp_us, tolerance_us, &k) == StampMatch::kNone) {
      ++rep.unmatched_estimate_count;
      continue;
    }
    if (has[k]) ++rep.duplicate_estimate_count;
    has[k] = true;
    out[k] = io::StampedPose{scan_odometry[k].stamp_us, e.pose};
  }
  std::size_t first = scan_odometry.size();
  for (std::size_t k = 0; k < has.size(); ++k) {
    if (has[k]) {
      ++rep.estimated_count;
      if (first == scan_odometry.size()) first = k;
    }
  }
  if (first == scan_odometry.size()) {
    if (error != nullptr) {
      *error = "none of the " + std::to_string(estimate.size()) + " estimated poses matches any of the " +
               std::to_string(scan_odometry.size()) + " laser scan stamps";
    }
    if (report != nullptr) *report = rep;
    return false;
  }
  // Backwards from the first estimate, then forwards from the last one seen.
  for (std::size_t k = 0; k < first; ++k) {
    out[k] = io::StampedPose{scan_odometry[k].stamp_us,
                             out[first].pose.compose(between(scan_odometry[first].pose, scan_odometry[k].pose))};
    ++rep.filled_count;
  }
  std::size_t last = first;
  for (std::size_t k = first + 1; k < has.size(); ++k) {
    if (has[k]) {
      last = k;
      continue;
    }
    out[k] = io::StampedPose{scan_odometry[k].stamp_us,
                             out[last].pose.compose(between(scan_odometry[last].pose, scan_odometry[k].pose))};
    ++rep.filled_count;
  }
  *per_scan = std::move(out);
  if (report != nullptr) *report = rep;
  return true;
}

RelationsResult evaluate_relations(const std::vector<Relation>& relations, const std::vector<io::StampedPose>& per_scan,
                                   std::int64_t tolerance_us) {
  RelationsResult res;
  res.relation_count = relations.size();
  std::vector<double> t_abs, t_sq, r_abs, r_sq;
  for (const Relation& rel : relations) {
    std::size_t i1 = 0;
    std::size_t i2 = 0;
    const StampMatch m1 = find_stamp(per_scan, rel.t1_us, tolerance_us, &i1);
    const StampMatch m2 = find_stamp(per_scan, rel.t2_us, tolerance_us, &i2);
    if (m1 == StampMatch::kNone || m2 == StampMatch::kNone) {
      ++res.unmatched_count;
      if (res.unmatched.size() < RelationsResult::kMaxUnmatchedKept) res.unmatched.push_back(rel);
      continue;
    }
    if (m1 == StampMatch::kExact && m2 == StampMatch::kExact) ++res.exact_match_count;
    RelationResult rr;
    rr.relation = rel;
    // Eq. (2): δ_est = p1⁻¹ ⊕ p2, E = δ_est ⊖ δ_true = δ_est ⊕ δ_true⁻¹.
    rr.error = between(per_scan[i1].pose, per_scan[i2].pose).compose(rel.expected.inverse());
    rr.translation_error_m = std::hypot(rr.error.x_m, rr.error.y_m);
    rr.rotation_error_rad = std::fabs(normalize_angle_rad(rr.error.heading_rad));
    const double deg = rr.rotation_error_rad * kRadToDeg;
    t_abs.push_back(rr.translation_error_m);
    t_sq.push_back(rr.translation_error_m * rr.translation_error_m);
    r_abs.push_back(deg);
    r_sq.push_back(deg * deg);
    res.per_relation.push_back(rr);
  }
  res.used_count = res.per_relation.size();
  res.translation_m = summarize(t_abs);
  res.translation_m2 = summarize(t_sq);
  res.rotation_deg = summarize(r_abs);
  res.rotation_deg2 = summarize(r_sq);
  return res;
}

std::vector<std::size_t> worst_relations(const RelationsResult& result, std::size_t count, std::int64_t apart_us) {
  std::vector<std::size_t> order(result.per_relation.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&result](std::size_t a, std::size_t b) {
    return result.per_relation[a].translation_error_m > result.per_relation[b].translation_error_m;
  });
  const auto near = [apart_us](std::int64_t a, std::int64_t b) { return (a > b ? a - b : b - a) <= apart_us; };
  std::vector<std::size_t> chosen;
  for (std::size_t i : order) {
    if (chosen.size() >= count) break;
    const Relation& r = result.per_relation[i].relation;
    bool same_event = false;
    for (std::size_t j : chosen) {
      const Relation& q = result.per_relation[j].relation;
      same_event = same_event || (near(r.t1_us, q.t1_us) && near(r.t2_us, q.t2_us));
    }
    if (!same_event) chosen.push_back(i);
  }
  return chosen;
}

std::vector<SpanClass> relations_by_span(const RelationsResult& result, const std::vector<std::int64_t>& edges_us) {
  std::vector<std::vector<double>> errors(edges_us.size() + 1U);
  std::vector<double> along(errors.size(), 0.0);   // Σ (t_est − t_true)·t_true
  std::vector<double> length2(errors.size(), 0.0);  // Σ |t_true|²
  double total = 0.0;
  for (const RelationResult& r : result.per_relation) {
    const std::int64_t span = r.relation.t2_us > r.relation.t1_us ? r.relation.t2_us - r.relation.t1_us
                                                                   : r.relation.t1_us - r.relation.t2_us;
    std::size_t k = 0;
    while (k < edges_us.size() && span >= edges_us[k]) ++k;
    errors[k].push_back(r.translation_error_m);
    total += r.translation_error_m;
    // E = δ_est ⊕ δ_true⁻¹ (Eq. 2), so δ_est = E ⊕ δ_true.
    const Pose2& truth = r.relation.expected;
    const Pose2 estimate = r.error.compose(truth);
    along[k] += (estimate.x_m - truth.x_m) * truth.x_m + (estimate.y_m - truth.y_m) * truth.y_m;
    length2[k] += truth.x_m * truth.x_m + truth.y_m * truth.y_m;
  }
  std::vector<SpanClass> out(errors.size());
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].from_us = k == 0 ? 0 : edges_us[k - 1];
    out[k].to_us = k < edges_us.size() ? edges_us[k] : -1;
    out[k].translation_m = summarize(errors[k]);
    double sum = 0.0;
    for (double e : errors[k]) sum += e;
    out[k].share = total > 0.0 ? sum / total : 0.0;
    out[k].scale_measured = length2[k] > 0.0;
    out[k].scale_error = out[k].scale_measured ? along[k] / length2[k] : 0.0;
  }
  return out;
}

}  // namespace sdpslam::eval
