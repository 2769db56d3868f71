#pragma once
// Continuing a saved SDP-SLAM session (a snapshot, io/snapshot_file.h) on input that
// does not follow it without a break: sdpslamd after a restart (its encoders count from
// zero again, and after a power loss its monotonic clock starts again) and
// `sdpslam run --extend` (another log of the same building). Three things break there,
// and this carries each across:
//  - odometry: the new input's odometry is carried into the session's odometry frame so
//    that the pose where mapping goes on is the session's last (the bottom filter sees
//    no jump);
//  - stamps: when the new input's first stamp is not after the session's last, every
//    new stamp is shifted to follow it by one second (the session's pose ring and paths
//    are in time order; the real time between the two is unknown). Stamps already after
//    the session's last are kept;
//  - place: the robot may have been moved while nothing watched it.
//     1. The first scan is matched against the saved map (the best combination's global
//        map, rendered once) by exhaustive correlative search (core/loops/
//        correlative_matcher.h), once within ±1 m and ±0.35 rad of where the robot is
//        expected (where the session left it, or a later pose given to begin()) and
//        once over ±window_m and every heading. The robot was not moved far if the
//        scan fits near where it is expected (the matcher's min_score) and, for input
//        that is another recording (not stayed_likely), no place elsewhere fits
//        clearly better (by the matcher's ambiguity ratio, on the whole sums it ranks
//        by). Mapping then goes on at once: from the pose the scan pins near there when
//        the matcher calls it unambiguous and distinct from where the session left the
//        robot (half a metre, a tenth of a radian), otherwise from where it was left,
//        the bottom filter's scan matching taking up the rest as after any scan. A
//        view that fits there and elsewhere too (a corridor) is no reason to look for
//        the robot elsewhere.
//     2. Otherwise the robot was moved. One scan cannot say where in a building of
//        look-alike corridors, so the scans that follow go to global Monte Carlo
//        localization on the saved map (core/localization, unknown start, as
//        `sdpslam localize`) and are held back from mapping until, for kSettledUpdates
//        filter updates in a row after at least kMinSearchUpdates (the robot must move
//        for that), the particles are gathered within kConvergedSpreadM and the update's
//        scan itself pins the pose there: an unambiguous correlative peak within ±1 m
//        and ±0.35 rad of the estimate (a set gathered on a look-alike, or anywhere
//        while the robot is where the map has nothing, tends to fail it; several views
//        in a row, taken as the robot moves, rarely all pass). The session's particles are then
//        moved to the place found (SdpSlam::relocate) and mapping goes on from that
//        scan. Until then nothing is mapped, however long it takes: a robot placed at a
//        guess would write the area twice into the saved map, which stays as it was
//        (the report counts the scans held; a robot taken where the map has nothing is
//        not mapped there).
//     The scans held back are not mapped and not in the trajectory (counted). Limits:
//     one scan decides whether to look, so a robot carried to a place that looks like
//     where it was left is taken not to have moved, and on a rough map a robot that did
//     not move may be looked for (its scans held back until found or the limit).
// Allocates while it checks and searches (the rendered map, the matcher's grids, the
// localizer: the first scans after the break), never once mapping has gone on.
#include <cstdint>
#include <memory>
#include <string>

#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/io/json_text.h"

namespace sdpslam::io {
struct OccupancyImage;
}  // namespace sdpslam::io

namespace sdpslam::slam {

struct ContinuationReport {
  enum class Place : std::uint8_t {
    kNotChecked,  // no scan yet since the break, or the check is off (window 0)
    kSearching,   // moved: global localization in progress (or it never found the robot), scans held back
    kInPlace,     // the first scan fits where the session left the robot
    kMoved,       // found elsewhere by global localization: the session was moved there
    kNoMap,       // the saved map or the first scan holds too few points: continued where left
  };
  Place place = Place::kNotChecked;
  Pose2 expected;                   // global pose where the session left the robot
  Pose2 near;                       // where the first scan was looked for (expected, or a later hint)
  Pose2 found;                      // global pose where mapping went on (kMoved)
  double score_here = 0.0;          // the first scan's fit where the robot was left, [0, 1]
  double score_best = 0.0;          // ... at the best place within the window (another recording only)
  std::uint64_t scans_held = 0U;    // scans given to the search, not mapped
  std::int64_t stamp_shift_us = 0;  // added to every new stamp
  double search_ms = 0.0;           // wall time of the checks (not in json(): not deterministic)
  double moved_m() const;
  double turned_rad() const;
  const char* place_name() const;
  // One line for a log or stderr: what was found and what was done.
  std::string describe() const;
  io::Json json() const;
};

class SessionContinuation {
 public:
  // ±window_m searched around where the session left the robot (every heading) by the
  // first scan's check; 0 = take the robot to stand where it was left (odometry and
  // stamps are still carried across).
  static constexpr double kDefaultWindowM = 10.0;
  // Global localization's filter updates (one per 0.2 m or 0.2 rad of motion) before a
  // place is taken, and those in a row with the particles gathered and the scan fitting.
  static constexpr std::uint32_t kMinSearchUpdates = 25U;
  static constexpr std::uint32_t kSettledUpdates = 5U;

  // stayed_likely: the input follows a stop of the same robot (sdpslamd restarted: it
  // most likely stands where it stopped), so a first scan that fits there is taken to
  // be there even if a place elsewhere fits better (a rough map, a look-alike); the
  // search starts only when it does not fit there. Otherwise (another recording) a
  // place elsewhere that fits clearly better starts the search too.
  explicit SessionContinuation(double window_m = kDefaultWindowM, bool stayed_likely = false);
  ~SessionContinuation();
  SessionContinuation(const SessionContinuation&) = delete;
  SessionContinuation& operator=(const SessionContinuation&) = delete;

  // After the session's state was loaded: its last odometry pose and scan stamp (the
  // session's frames). Until then (a fresh session) carry() passes input through.
  // `hint` (may be null): a later global pose of the robot than the session's last, when
  // one is known (sdpslamd's trajectory.txt, written every few seconds, against a
  // snapshot written every few minutes: the robot drove on in between); the first scan
  // is then looked for near it rather than near the session's last pose.
  void begin(const Pose2& last_odom, std::int64_t last_stamp_us, const Pose2* hint = nullptr);
  bool active() const { return active_; }

  // Every odometry sample and scan of the new input, in order, before SdpSlam::process.
  // Shifts the scan's stamp; returns false while the scan is held back (not to be given
  // to SLAM), true with *odom in the session's frames otherwise. May relocate `slam`.
  bool carry(OdometrySample* odom, RangeScan* scan, SdpSlam& slam);

  const ContinuationReport& report() const { return report_; }

 private:
  struct Search;
  // `image`: the saved map as rendered for the check, kept for the search.
  void check_first(const RangeScan& scan, SdpSlam& slam, io::OccupancyImage* image);
  bool start_search(io::OccupancyImage&& image);
  bool fits_at(const RangeScan& scan, const Pose2& pose, const SdpSlam& slam);
  void rebase_at(const Pose2& odom_in);

  double window_m_;
  bool stayed_likely_;
  bool active_ = false;
  bool first_input_ = false;
  bool rebased_ = false;
  Pose2 last_odom_{};
  std::int64_t last_stamp_us_ = 0;
  Pose2 odom_offset_{};  // session frame = this ⊕ the new input's odometry frame
  bool has_hint_ = false;
  Pose2 hint_{};
  ContinuationReport report_{};
  std::unique_ptr<Search> search_;
};

}  // namespace sdpslam::slam
