// Rigid fit of a run's segment frames to the relations (see frame_fit.h).
#include "sdpslam/eval/frame_fit.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>

#include "sdpslam/eval/stamp_match.h"
#include "sdpslam/io/text_table.h"

namespace sdpslam::eval {
namespace {

constexpr double kConvergedM = 1.0e-10;   // a step that lowers the mean by less ends the fit
constexpr double kWeightFloorM = 1.0e-3;  // IRLS: errors below 1 mm weigh as 1 mm
constexpr std::uint32_t kMaxSteps = 1000U;
constexpr double kDerivativeStep = 1.0e-6;  // central differences, m and rad

struct Point2D {
  double x = 0.0;
  double y = 0.0;
};

// One relation between two scans, with the segments they lie in.
struct Link {
  std::size_t i1 = 0;
  std::size_t i2 = 0;
  std::size_t s1 = 0;
  std::size_t s2 = 0;
  Pose2 expected_inverse;
};

// A segment's correction: turn by dtheta about `pivot`, then shift by (dx, dy).
Pose2 corrected(const Pose2& p, const double* c, const Point2D& pivot) {
  const double cs = std::cos(c[2]);
  const double sn = std::sin(c[2]);
  const double x = p.x_m - pivot.x;
  const double y = p.y_m - pivot.y;
  return Pose2{pivot.x + cs * x - sn * y + c[0], pivot.y + sn * x + cs * y + c[1], p.heading_rad + c[2]};
}

// Solves A x = b for symmetric positive definite A (n × n, row-major), in place by
// Cholesky; false when A is not positive definite.
bool cholesky_solve(std::vector<double>& a, std::vector<double>& b, std::size_t n) {
  for (std::size_t j = 0; j < n; ++j) {
    double d = a[j * n + j];
    for (std::size_t k = 0; k < j; ++k) d -= a[j * n + k] * a[j * n + k];
    if (!(d > 0.0)) return false;
    const double l = std::sqrt(d);
    a[j * n + j] = l;
    for (std::size_t i = j + 1; i < n; ++i) {
      double s = a[i * n + j];
      for (std::size_t k = 0; k < j; ++k) s -= a[i * n + k] * a[j * n + k];
      a[i * n + j] = s / l;
    }
  }
  for (std::size_t i = 0; i < n; ++i) {
    double s = b[i];
    for (std::size_t k = 0; k < i; ++k) s -= a[i * n + k] * b[k];
    b[i] = s / a[i * n + i];
  }
  for (std::size_t i = n; i-- > 0;) {
    double s = b[i];
    for (std::size_t k = i + 1; k < n; ++k) s -= a[k * n + i] * b[k];
    b[i] = s / a[i * n + i];
  }
  return true;
}

}  // namespace

bool read_segments(const std::string& path, std::vector<SegmentStart>* segments, std::string* error) {
  segments->clear();
  std::ifstream in;
  return io::open_for_reading(path, &in, error) && read_segments(in, path, segments, error);
}

bool read_segments(std::istream& in, const std::string& name, std::vector<SegmentStart>* segments,
                   std::string* error) {
  segments->clear();
  return io::read_table(
      in, name,
      [segments](const std::vector<std::string>& tokens, std::int64_t) -> std::string {
        if (tokens.size() != 2) return "expected 2 columns (level start_stamp), found " + std::to_string(tokens.size());
        char* end = nullptr;
        errno = 0;
        const unsigned long long level = std::strtoull(tokens[0].c_str(), &end, 10);
        if (tokens[0].empty() || tokens[0][0] == '-' || *end != '\0' || errno == ERANGE ||
            level > std::numeric_limits<std::uint32_t>::max()) {
          return "bad level '" + tokens[0] + "'";
        }
        SegmentStart s;
        s.level = static_cast<std::uint32_t>(level);
        if (!io::parse_stamp_us(tokens[1], &s.start_us)) return "bad start stamp '" + tokens[1] + "'";
        if (!segments->empty() && !(s.start_us > segments->back().start_us && s.level > segments->back().level)) {
          return "level and start stamp must increase from line to line";
        }
        segments->push_back(s);
        return std::string();
      },
      error);
}

std::size_t segment_of(const std::vector<SegmentStart>& segments, std::int64_t stamp_us) {
  // The last segment whose (exclusive) start lies before the stamp.
  const auto it = std::lower_bound(segments.begin(), segments.end(), stamp_us,
                                   [](const SegmentStart& s, std::int64_t t) { return s.start_us < t; });
  const auto k = static_cast<std::size_t>(it - segments.begin());
  return k == 0U ? 0U : k - 1U;
}

FrameFitResult fit_segment_frames(const std::vector<Relation>& relations, const std::vector<io::StampedPose>& per_scan,
                                  const std::vector<SegmentStart>& segments, std::int64_t tolerance_us) {
  FrameFitResult res;
  if (segments.empty() || per_scan.empty()) return res;
  std::vector<Link> links;
  for (const Relation& r : relations) {
    Link l;
    if (find_stamp(per_scan, r.t1_us, tolerance_us, &l.i1) == StampMatch::kNone ||
        find_stamp(per_scan, r.t2_us, tolerance_us, &l.i2) == StampMatch::kNone) {
      continue;
    }
    l.s1 = segment_of(segments, per_scan[l.i1].stamp_us);
    l.s2 = segment_of(segments, per_scan[l.i2].stamp_us);
    l.expected_inverse = r.expected.inverse();
    links.push_back(l);
  }
  // Unknowns: 3 per segment joined to another by a relation, less the gauge (the first).
  constexpr std::size_t kFixed = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> slot(segments.size(), kFixed);
  std::vector<bool> joined(segments.size(), false);
  for (const Link& l : links) {
    if (l.s1 != l.s2) joined[l.s1] = joined[l.s2] = true;
  }
  std::size_t unknowns = 0;
  bool gauge = false;
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (!joined[s]) continue;
    if (!gauge) {
      gauge = true;
      continue;
    }
    slot[s] = unknowns;
    unknowns += 3U;
  }
  res.segments_moved = unknowns / 3U;
  // Pivots: each segment's mean scan position.
  std::vector<Point2D> pivot(segments.size());
  std::vector<std::size_t> scans_in(segments.size(), 0U);
  for (const io::StampedPose& p : per_scan) {
    const std::size_t s = segment_of(segments, p.stamp_us);
    pivot[s].x += p.pose.x_m;
    pivot[s].y += p.pose.y_m;
    ++scans_in[s];
  }
  for (std::size_t s = 0; s < segments.size(); ++s) {
    if (scans_in[s] > 0U) {
      pivot[s].x /= static_cast<double>(scans_in[s]);
      pivot[s].y /= static_cast<double>(scans_in[s]);
    }
  }

  const double zero[3] = {0.0, 0.0, 0.0};
  auto param = [&](const std::vector<double>& x, std::size_t s) { return slot[s] == kFixed ? zero : &x[slot[s]]; };
  // t(E) of link l with the corrections c1, c2 of its two segments.
  auto error_of = [&](const Link& l, const double* c1, const double* c2) {
    const Pose2 p1 = corrected(per_scan[l.i1].pose, c1, pivot[l.s1]);
    const Pose2 p2 = corrected(per_scan[l.i2].pose, c2, pivot[l.s2]);
    const Pose2 e = between(p1, p2).compose(l.expected_inverse);
    return Point2D{e.x_m, e.y_m};
  };
  auto mean_error = [&](const std::vector<double>& x) {
    double sum = 0.0;
    for (const Link& l : links) {
      const Point2D e = error_of(l, param(x, l.s1), param(x, l.s2));
      sum += std::hypot(e.x, e.y);
    }
    return links.empty() ? 0.0 : sum / static_cast<double>(links.size());
  };

  std::vector<double> x(unknowns, 0.0);
  double current = mean_error(x);
  double lambda = 1.0e-3;
  const std::size_t n = unknowns;
  bool converged = n == 0U;
  for (std::uint32_t step = 0; !converged && step < kMaxSteps; ++step) {
    ++res.steps;
    // Normal equations of Σ w |t(E)|² at x, w = 1 / max(|t(E)|, floor) (IRLS for Σ |t(E)|).
    std::vector<double> h(n * n, 0.0);
    std::vector<double> g(n, 0.0);
    for (const Link& l : links) {
      if (l.s1 == l.s2) continue;  // a rigid move of one segment leaves it as it is
      double c1[3], c2[3];
      std::copy(param(x, l.s1), param(x, l.s1) + 3, c1);
      std::copy(param(x, l.s2), param(x, l.s2) + 3, c2);
      const Point2D e = error_of(l, c1, c2);
      const double w = 1.0 / std::max(std::hypot(e.x, e.y), kWeightFloorM);
      // Jacobian columns (2 × 6): the three unknowns of each of the two segments.
      double jx[6] = {}, jy[6] = {};
      std::size_t col[6];
      bool free_col[6];
      for (std::size_t k = 0; k < 6; ++k) {
        const std::size_t s = k < 3 ? l.s1 : l.s2;
        free_col[k] = slot[s] != kFixed;
        col[k] = free_col[k] ? slot[s] + k % 3U : 0U;
        if (!free_col[k]) continue;
        double* c = k < 3 ? c1 : c2;
        const double keep = c[k % 3U];
        c[k % 3U] = keep + kDerivativeStep;
        const Point2D ep = error_of(l, c1, c2);
        c[k % 3U] = keep - kDerivativeStep;
        const Point2D em = error_of(l, c1, c2);
        c[k % 3U] = keep;
        jx[k] = (ep.x - em.x) / (2.0 * kDerivativeStep);
        jy[k] = (ep.y - em.y) / (2.0 * kDerivativeStep);
      }
      for (std::size_t a = 0; a < 6; ++a) {
        if (!free_col[a]) continue;
        g[col[a]] += w * (jx[a] * e.x + jy[a] * e.y);
        for (std::size_t b = 0; b < 6; ++b) {
          if (free_col[b]) h[col[a] * n + col[b]] += w * (jx[a] * jx[b] + jy[a] * jy[b]);
        }
      }
    }
    // Levenberg–Marquardt: damped step, kept only if the mean error falls.
    bool kept = false;
    for (int tries = 0; tries < 12 && !kept; ++tries) {
      std::vector<double> a = h;
      std::vector<double> d(n);
      for (std::size_t i = 0; i < n; ++i) {
        a[i * n + i] += lambda * (h[i * n + i] + 1.0e-9);
        d[i] = -g[i];
      }
      if (!cholesky_solve(a, d, n)) {
        lambda *= 10.0;
        continue;
      }
      std::vector<double> trial = x;
      for (std::size_t i = 0; i < n; ++i) trial[i] += d[i];
      const double m = mean_error(trial);
      if (m < current) {
        kept = true;
        const double gain = current - m;
        x = trial;
        current = m;
        lambda = std::max(lambda * 0.3, 1.0e-9);
        converged = gain < kConvergedM;
      } else {
        lambda *= 10.0;
      }
    }
    if (!kept) converged = true;  // no step lowers the mean: a minimum
  }

  auto part_add = [](FrameFitPart* p, double before, double after) {
    ++p->count;
    p->mean_m += before;
    p->fitted_mean_m += after;
  };
  const std::vector<double> none(unknowns, 0.0);
  for (const Link& l : links) {
    const Point2D b = error_of(l, param(none, l.s1), param(none, l.s2));
    const Point2D f = error_of(l, param(x, l.s1), param(x, l.s2));
    const double before = std::hypot(b.x, b.y);
    const double after = std::hypot(f.x, f.y);
    part_add(&res.all, before, after);
    part_add(l.s1 == l.s2 ? &res.within : &res.across, before, after);
  }
  for (FrameFitPart* p : {&res.all, &res.within, &res.across}) {
    if (p->count == 0U) continue;
    p->mean_m /= static_cast<double>(p->count);
    p->fitted_mean_m /= static_cast<double>(p->count);
  }
  res.converged = converged;
  return res;
}

}  // namespace sdpslam::eval
