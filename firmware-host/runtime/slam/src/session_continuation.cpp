#include "sdpslam/slam/session_continuation.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <utility>
#include <vector>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/localization/monte_carlo_localizer.h"
#include "sdpslam/core/loops/correlative_matcher.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/slam/run_localize.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::slam {

namespace {

// The search's grid: the loop search's cell size is the map's; here a coarser one keeps
// a ±10 m, all-headings search of one scan to about a second at start-up, and the
// bottom filter's scan matcher takes the last centimetres.
constexpr double kGridM = 0.1;
constexpr std::uint32_t kCoarseCells = 4U;
// Scan points used: beams up to this range (the heading step is one cell at the
// farthest point, and at most CorrelativeOptions::kMaxHeadings), evenly thinned to
// kMaxScanPoints.
constexpr double kScanReachM = 20.0;
constexpr std::uint32_t kMaxScanPoints = 360U;
// "Near" a pose: this window around it. Where the session left the robot, the first
// scan is matched within it; a place found by global localization is taken when the
// scan pins the pose within it (one unambiguous peak above the matcher's score, near the
// localizer's estimate: a corridor's view, which fits anywhere along it, waits for a
// view that does not).
constexpr double kNearM = 1.0;
constexpr double kNearRad = 0.35;
// Walls to match against: the rendered map's cells at or above this occupancy, the
// confident ones (map_server's default occupied_thresh). The written map.yaml's lower
// threshold also keeps cells that a grazing beam hit once, which make every place fit
// a little.
constexpr double kWallOccupancy = 0.65;
// Fewest points either set must have for a match to mean anything.
constexpr std::uint32_t kMinPoints = 20U;

CorrelativeOptions scan_match_options(const SdpOptions& so, double window_m, double window_rad) {
  CorrelativeOptions co;
  co.resolution_m = kGridM;
  co.coarse_cells = kCoarseCells;
  co.kernel_sigma_m = 1.5 * kGridM;
  co.window_xy_m = window_m;
  co.window_theta_rad = window_rad;
  co.min_score = so.loop_search_min_score;
  co.min_overlap_points = kMinPoints;
  co.max_ambiguity = so.loop_search_max_ambiguity;
  return co;
}

bool matched(const CorrelativeResult& c) {
  return c.status == CorrelativeResult::Status::kFound || c.status == CorrelativeResult::Status::kWeak ||
         c.status == CorrelativeResult::Status::kAmbiguous;
}

// The scan's fit to the map's walls at the best pose within ±window_m, ±window_rad of
// `guess` (exhaustive, correlative_matcher.h); status kTooFewPoints when either set is
// too small to mean anything.
CorrelativeResult match_scan(const io::OccupancyImage& image, const RangeScan& scan, const Pose2& guess,
                             double window_m, double window_rad, const SdpOptions& so) {
  CorrelativeResult none;
  none.status = CorrelativeResult::Status::kTooFewPoints;
  // The scan's points in the robot's frame, evenly thinned.
  std::vector<Point2> source;
  for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
    if (scan.classify(i) != RangeScan::Beam::kReturn) continue;
    const double r = scan.ranges_m[i];
    if (r > kScanReachM) continue;
    const double a = scan.beam_angle_rad(i);
    Point2 p;
    scan.geometry.laser_in_base.transform_point(r * det::cos(a), r * det::sin(a), p.x_m, p.y_m);
    source.push_back(p);
  }
  if (source.size() > kMaxScanPoints) {
    std::vector<Point2> thinned;
    thinned.reserve(kMaxScanPoints);
    for (std::uint32_t k = 0; k < kMaxScanPoints; ++k) thinned.push_back(source[k * source.size() / kMaxScanPoints]);
    source.swap(thinned);
  }
  // The walls a scan from anywhere in the window can see.
  const double reach = window_m + kScanReachM + 1.0;
  std::vector<Point2> target;
  for (std::uint32_t row = 0; row < image.height; ++row) {
    for (std::uint32_t col = 0; col < image.width; ++col) {
      if (!(image.occupancy[static_cast<std::size_t>(row) * image.width + col] >= kWallOccupancy)) continue;
      const Point2 p{image.origin_x_m + (col + 0.5) * image.resolution_m,
                     image.origin_y_m + (row + 0.5) * image.resolution_m};
      if (std::fabs(p.x_m - guess.x_m) <= reach && std::fabs(p.y_m - guess.y_m) <= reach) target.push_back(p);
    }
  }
  if (source.size() < kMinPoints || target.size() < kMinPoints) return none;
  const CorrelativeOptions co = scan_match_options(so, window_m, window_rad);
  const std::uint32_t side = static_cast<std::uint32_t>((2.0 * reach + 6.0 * co.kernel_sigma_m) / kGridM) + 8U;
  const std::uint32_t steps = CorrelativeMatcher::steps_for(window_m, kGridM, kCoarseCells);
  const auto n = static_cast<std::uint32_t>(source.size());
  const std::size_t bytes = CorrelativeMatcher::required_bytes(side, n, steps);
  std::unique_ptr<unsigned char[]> buffer(new unsigned char[bytes]);
  Arena arena(buffer.get(), bytes);
  auto matcher = std::make_unique<CorrelativeMatcher>();
  if (!matcher->init(side, n, steps, arena)) return none;
  return matcher->match(target.data(), static_cast<std::uint32_t>(target.size()), source.data(), n, guess, co);
}

}  // namespace

double ContinuationReport::moved_m() const { return std::hypot(found.x_m - expected.x_m, found.y_m - expected.y_m); }

double ContinuationReport::turned_rad() const { return normalize_angle_rad(found.heading_rad - expected.heading_rad); }

const char* ContinuationReport::place_name() const {
  switch (place) {
    case Place::kNotChecked: return "not checked";
    case Place::kSearching: return "searching";
    case Place::kInPlace: return "in place";
    case Place::kMoved: return "moved";
    case Place::kNoMap: return "no map";
  }
  return "?";
}

std::string ContinuationReport::describe() const {
  char text[400];
  switch (place) {
    case Place::kNotChecked:
      return "the place was not checked against the saved map";
    case Place::kSearching:
      std::snprintf(text, sizeof text,
                    "the first scan does not fit where the robot was expected (score %.2f%s): looking for it in the "
                    "saved map; %llu scans held back from mapping so far",
                    score_here, score_here >= score_best ? "" : ", better elsewhere",
                    static_cast<unsigned long long>(scans_held));
      return text;
    case Place::kInPlace:
      std::snprintf(text, sizeof text,
                    "the first scan fits the saved map where the session left the robot (score %.2f, %.2f m and %.1f "
                    "deg from it): continued there",
                    score_here, moved_m(), turned_rad() * 57.29577951308232);
      return text;
    case Place::kMoved:
      std::snprintf(text, sizeof text,
                    "the robot was moved while off: the first scan did not fit where the session left it (score %.2f); "
                    "found by global localization in the saved map after %llu scans, %.2f m and %.1f deg from there "
                    "(where mapping went on, after the robot's own motion); those scans are not mapped",
                    score_here, static_cast<unsigned long long>(scans_held), moved_m(),
                    turned_rad() * 57.29577951308232);
      return text;
    case Place::kNoMap:
      return "the saved map or the first scan holds too few points to match: continued where the session left the "
             "robot";
  }
  return "?";
}

io::Json ContinuationReport::json() const {
  io::Json js = {{"place", place_name()}, {"stamp_shift_us", stamp_shift_us}};
  if (place != Place::kNotChecked && place != Place::kNoMap) {
    js["score_here"] = score_here;
    js["score_best"] = score_best;
    js["scans_held"] = scans_held;
    js["expected"] = {expected.x_m, expected.y_m, expected.heading_rad};
    js["near"] = {near.x_m, near.y_m, near.heading_rad};
  }
  if (place == Place::kMoved || place == Place::kInPlace) {
    js["found"] = {found.x_m, found.y_m, found.heading_rad};
    js["moved_m"] = moved_m();
    js["turned_rad"] = turned_rad();
  }
  return js;
}

// Global localization on the session's rendered map (step 2).
struct SessionContinuation::Search {
  LocalizationMap map;
  std::unique_ptr<unsigned char[]> buffer;
  std::unique_ptr<Arena> arena;
  MonteCarloLocalizer localizer;
  std::uint32_t updates = 0U;
  std::uint32_t settled = 0U;  // updates in a row with the particles gathered and the scan fitting there
};

SessionContinuation::SessionContinuation(double window_m, bool stayed_likely)
    : window_m_(window_m), stayed_likely_(stayed_likely) {}
SessionContinuation::~SessionContinuation() = default;

void SessionContinuation::begin(const Pose2& last_odom, std::int64_t last_stamp_us, const Pose2* hint) {
  has_hint_ = hint != nullptr;
  if (hint != nullptr) hint_ = *hint;
  active_ = true;
  first_input_ = true;
  rebased_ = false;
  last_odom_ = last_odom;
  last_stamp_us_ = last_stamp_us;
  report_ = ContinuationReport{};
  search_.reset();
}

void SessionContinuation::rebase_at(const Pose2& odom_in) {
  odom_offset_ = last_odom_.compose(odom_in.inverse());
  rebased_ = true;
}

bool SessionContinuation::carry(OdometrySample* odom, RangeScan* scan, SdpSlam& slam) {
  if (!active_) return true;
  using Place = ContinuationReport::Place;
  if (first_input_) {
    first_input_ = false;
    if (odom->stamp_us <= last_stamp_us_) report_.stamp_shift_us = last_stamp_us_ + 1000000 - odom->stamp_us;
  }
  odom->stamp_us += report_.stamp_shift_us;
  scan->stamp_us += report_.stamp_shift_us;
  if (report_.place == Place::kNotChecked && !rebased_) {
    io::OccupancyImage image;
    if (window_m_ > 0.0) check_first(*scan, slam, &image);
    if (report_.place == Place::kSearching && !start_search(std::move(image))) report_.place = Place::kNoMap;
    if (report_.place != Place::kSearching) rebase_at(odom->pose);
  }
  if (report_.place == Place::kSearching) {
    const MonteCarloLocalizer::Step st = search_->localizer.update(*odom, *scan);
    if (st.updated) {
      ++search_->updates;
      // Gathered particles, and the scan of each update pinning the pose where they
      // are: kSettledUpdates in a row, each after motion, so that one look-alike view
      // cannot decide.
      const bool settled = st.spread_m < kConvergedSpreadM && search_->updates >= kMinSearchUpdates;
      search_->settled = settled && fits_at(*scan, st.pose, slam) ? search_->settled + 1U : 0U;
    }
    if (st.updated && search_->settled >= kSettledUpdates) {
      // Found: the session's last pose steps to this scan's place, and mapping goes on
      // from here with this scan's odometry taken as the session's last.
      report_.found = st.pose;
      const Pose2 delta = report_.expected.inverse().compose(st.pose);
      report_.place = slam.relocate(delta) ? Place::kMoved : Place::kNoMap;
      search_.reset();
      rebase_at(odom->pose);
    } else {
      // Not found (yet): nothing is mapped at a guessed place, however long it takes;
      // what the session holds stays as it is.
      ++report_.scans_held;
      return false;
    }
  }
  odom->pose = odom_offset_.compose(odom->pose);
  return true;
}

// The localizer's estimate is taken only where the scan itself fits the saved map (a
// check independent of the particles: a set gathered on a look-alike place, or on any
// place while the robot is where the map has nothing, fails it).
bool SessionContinuation::fits_at(const RangeScan& scan, const Pose2& pose, const SdpSlam& slam) {
  const auto t0 = std::chrono::steady_clock::now();
  const CorrelativeOptions co = scan_match_options(slam.options(), 0.0, 0.0);
  const CorrelativeResult r =
      match_scan(search_->map.image, scan, pose, kNearM, kNearRad, slam.options());
  report_.search_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (r.status != CorrelativeResult::Status::kFound) return false;
  const Pose2 d = pose.inverse().compose(r.transform);
  return !co.distinct(d.x_m, d.y_m, d.heading_rad);
}

bool SessionContinuation::start_search(io::OccupancyImage&& image) {
  const auto t0 = std::chrono::steady_clock::now();
  search_ = std::make_unique<Search>();
  search_->map.image = std::move(image);
  if (search_->map.image.width == 0U) return false;
  localization_map_from_image(io::MapWriteOptions{}, &search_->map);  // kWallOccupancy, as map_server
  const LocalizerOptions options;
  const std::size_t bytes = MonteCarloLocalizer::required_arena_bytes(options, search_->map.map);
  if (bytes == 0U) return false;
  search_->buffer.reset(new unsigned char[bytes]);
  search_->arena = std::make_unique<Arena>(search_->buffer.get(), bytes);
  char why[160];
  if (!search_->localizer.init(options, search_->map.map, *search_->arena, 1U, why, sizeof why)) return false;
  search_->localizer.start_global();
  report_.search_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return true;
}

void SessionContinuation::check_first(const RangeScan& scan, SdpSlam& slam, io::OccupancyImage* image_out) {
  const auto t0 = std::chrono::steady_clock::now();
  report_.place = ContinuationReport::Place::kNoMap;
  const Pose2 expected = slam.current_frame().compose(slam.bottom().best_pose());
  report_.expected = expected;
  report_.found = expected;
  const Pose2 near = has_hint_ ? hint_ : expected;
  report_.near = near;
  io::OccupancyImage& image = *image_out;
  sdp_global_map_image(slam, &image);
  const SdpOptions& so = slam.options();
  const CorrelativeOptions co = scan_match_options(so, 0.0, 0.0);
  // Near where the robot is expected (±kNearM, ±kNearRad) and, for another recording,
  // everywhere in the window.
  const CorrelativeResult here = match_scan(image, scan, near, kNearM, kNearRad, so);
  if (here.status == CorrelativeResult::Status::kTooFewPoints) {
    report_.search_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return;  // kNoMap
  }
  report_.score_here = matched(here) ? here.score : 0.0;
  bool look = report_.score_here < co.min_score;
  if (!look && !stayed_likely_) {
    // Not moved far: the scan fits near where the robot is expected and no place
    // elsewhere in the window fits clearly better (by the matcher's ambiguity ratio, on
    // the whole sums it ranks by). A scan that fits there and also elsewhere (a
    // corridor) is no reason to look for the robot elsewhere.
    const CorrelativeResult best = match_scan(image, scan, near, window_m_, det::kPi, so);
    if (matched(best)) {
      report_.score_best = best.score;
      look = here.score * static_cast<double>(here.overlap_points) <
             co.max_ambiguity * best.score * static_cast<double>(best.overlap_points);
    }
  }
  report_.search_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (look) {
    report_.place = ContinuationReport::Place::kSearching;
    return;
  }
  report_.place = ContinuationReport::Place::kInPlace;
  // Near where it was left, the scan may still pin a move (the robot pushed, or driven
  // on for the scans since the last snapshot): taken when the peak there is unambiguous
  // and a distinct pose by the matcher's own measure; closer ones are left to the
  // bottom filter's scan matching, as after any scan.
  if (here.status != CorrelativeResult::Status::kFound) return;
  const Pose2 d = expected.inverse().compose(here.transform);
  if (co.distinct(d.x_m, d.y_m, d.heading_rad) && slam.relocate(d)) report_.found = here.transform;
}

}  // namespace sdpslam::slam
