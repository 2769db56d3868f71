// libFuzzer: the Kümmerle relations reader (eval::read_relations) over arbitrary file
// contents, then the metric over what was read.
// Checks beyond the sanitizers: every relation kept is finite with its heading in
// (-pi, pi] and a line number of the input, in file order; a refusal names
// "fuzz.relations:N: reason", keeps exactly the relations before line N, and is the first
// problem (the first N - 1 lines are accepted, giving the same relations); the metric
// accounts for every relation.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "sdpslam/eval/relations.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;
using sdpslam::test::fuzz::error_line;
using sdpslam::test::fuzz::first_lines;
using sdpslam::test::fuzz::line_count;

const char* const kName = "fuzz.relations";
constexpr double kPi = 3.14159265358979323846;

bool same(const std::vector<sdpslam::eval::Relation>& a, const std::vector<sdpslam::eval::Relation>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].t1_us != b[i].t1_us || a[i].t2_us != b[i].t2_us || a[i].line != b[i].line ||
        a[i].expected.x_m != b[i].expected.x_m || a[i].expected.y_m != b[i].expected.y_m ||
        a[i].expected.heading_rad != b[i].expected.heading_rad) {
      return false;
    }
  }
  return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  std::istringstream in(text);
  std::vector<sdpslam::eval::Relation> relations;
  std::string error;
  const bool ok = sdpslam::eval::read_relations(in, kName, &relations, &error);
  const auto lines = static_cast<std::int64_t>(line_count(text));
  std::int64_t previous_line = 0;
  for (const sdpslam::eval::Relation& r : relations) {
    check(r.line > previous_line && r.line <= lines);
    previous_line = r.line;
    check(std::isfinite(r.expected.x_m) && std::isfinite(r.expected.y_m));
    check(r.expected.heading_rad > -kPi && r.expected.heading_rad <= kPi);
  }
  if (!ok) {
    const std::size_t n = error_line(error, kName);
    check(n >= 1U && static_cast<std::int64_t>(n) <= lines);
    check(relations.empty() || relations.back().line < static_cast<std::int64_t>(n));
    std::istringstream before(first_lines(text, n - 1U));
    std::vector<sdpslam::eval::Relation> kept;
    std::string again;
    check(sdpslam::eval::read_relations(before, kName, &kept, &again));
    check(same(kept, relations));
  }

  // The metric against poses at every stamp read (identity poses, strictly increasing).
  std::vector<sdpslam::io::StampedPose> per_scan;
  for (const sdpslam::eval::Relation& r : relations) {
    for (const std::int64_t t : {r.t1_us, r.t2_us}) per_scan.push_back(sdpslam::io::StampedPose{t, {}});
  }
  std::sort(per_scan.begin(), per_scan.end(),
            [](const sdpslam::io::StampedPose& a, const sdpslam::io::StampedPose& b) { return a.stamp_us < b.stamp_us; });
  per_scan.erase(std::unique(per_scan.begin(), per_scan.end(),
                             [](const sdpslam::io::StampedPose& a, const sdpslam::io::StampedPose& b) {
                               return a.stamp_us == b.stamp_us;
                             }),
                 per_scan.end());
  const sdpslam::eval::RelationsResult res = sdpslam::eval::evaluate_relations(relations, per_scan);
  check(res.relation_count == relations.size());
  check(res.used_count + res.unmatched_count == relations.size());
  check(res.unmatched_count == 0U);
  check(res.exact_match_count == res.used_count);
  return 0;
}
