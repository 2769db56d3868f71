#include "sdpslam/eval/loops.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "sdpslam/eval/stamp_match.h"

namespace sdpslam::eval {
namespace {

bool parse_origin(std::istringstream& in, bool* known, std::int64_t* stamp_us, Pose2* p) {
  std::string stamp;
  if (!(in >> stamp >> p->x_m >> p->y_m >> p->heading_rad)) return false;
  *known = stamp != "-";
  if (!*known) return true;
  return io::parse_stamp_us(stamp, stamp_us) && std::isfinite(p->x_m) && std::isfinite(p->y_m) &&
         std::isfinite(p->heading_rad);
}

}  // namespace

void LoopBins::add(double error_m) {
  ++count;
  if (error_m < kLoopRightM) {
    ++right;
  } else if (error_m >= kLoopWrongM) {
    ++wrong;
  } else {
    ++between;
  }
  max_m = std::max(max_m, error_m);
}

bool read_loops(std::istream& in, const std::string& name, std::vector<LoopLine>* lines, std::string* error) {
  std::string text;
  std::size_t number = 0;
  while (std::getline(in, text)) {
    ++number;
    if (text.empty() || text[0] == '#') continue;
    std::istringstream fields(text);
    LoopLine l;
    std::string source;
    int used = 0;
    const bool ok = static_cast<bool>(fields >> l.older_level >> l.newer_level >> source >> used >> l.residual_m >>
                                      l.z.x_m >> l.z.y_m >> l.z.heading_rad) &&
                    (source == "search" || source == "icp") && (used == 0 || used == 1) &&
                    std::isfinite(l.residual_m) && std::isfinite(l.z.x_m) && std::isfinite(l.z.y_m) &&
                    std::isfinite(l.z.heading_rad) &&
                    parse_origin(fields, &l.older_known, &l.older_stamp_us, &l.older_initial) &&
                    parse_origin(fields, &l.newer_known, &l.newer_stamp_us, &l.newer_initial);
    std::string extra;
    if (!ok || (fields >> extra)) {
      *error = name + ":" + std::to_string(number) +
               ": expected 'older newer search|icp 0|1 error_m z_x z_y z_theta' and two origins 'stamp x y theta'";
      return false;
    }
    l.searched = source == "search";
    l.used = used == 1;
    lines->push_back(l);
  }
  return true;
}

bool read_loops(const std::string& path, std::vector<LoopLine>* lines, std::string* error) {
  std::ifstream in(path);
  if (!in) {
    *error = "cannot open '" + path + "'";
    return false;
  }
  return read_loops(in, path, lines, error);
}

LoopsResult check_loops(const std::vector<LoopLine>& lines, const std::vector<io::StampedPose>& ground_truth,
                        std::int64_t tolerance_us) {
  const std::vector<io::StampedPose> sorted = sorted_by_stamp(ground_truth);
  LoopsResult r;
  r.count = lines.size();
  for (const LoopLine& l : lines) {
    LoopCheck c;
    std::size_t at_older = 0;
    std::size_t at_newer = 0;
    if (l.older_known && l.newer_known &&
        find_stamp(sorted, l.older_stamp_us, tolerance_us, &at_older) != StampMatch::kNone &&
        find_stamp(sorted, l.newer_stamp_us, tolerance_us, &at_newer) != StampMatch::kNone) {
      const Pose2 f_older = sorted[at_older].pose.compose(l.older_initial.inverse());
      const Pose2 f_newer = sorted[at_newer].pose.compose(l.newer_initial.inverse());
      const Pose2 d = between(between(f_older, f_newer), l.z);
      c.matched = true;
      c.error_m = std::hypot(d.x_m, d.y_m);
      c.heading_error_rad = std::fabs(normalize_angle_rad(d.heading_rad));
      (l.searched ? r.search : r.icp).add(c.error_m);
      if (l.used) r.used.add(c.error_m);
    } else {
      ++r.unmatched;
    }
    r.checks.push_back(c);
  }
  return r;
}

}  // namespace sdpslam::eval
