#include "sdpslam/daemon/slam_engine.h"

#include <cmath>

#include "sdpslam/core/bottom/dpslam_filter.h"
#include "sdpslam/core/sdp_slam.h"
#include "sdpslam/io/snapshot_file.h"
#include "sdpslam/slam/dpslam_session.h"
#include "sdpslam/slam/localize_session.h"
#include "sdpslam/slam/run_localize.h"
#include "sdpslam/slam/sdp_session.h"
#include "sdpslam/slam/session_continuation.h"
#include "sdpslam/slam/slam_outputs.h"

namespace sdpslam::daemon {
namespace {

// PoseSpread of n particle poses pose_at(i), turned by `turn_rad` into the map frame.
template <class PoseAt>
PoseSpread spread_of(std::uint32_t n, PoseAt&& pose_at, double turn_rad) {
  PoseSpread s;
  if (n < 2U) return s;
  double mx = 0.0, my = 0.0, sc = 0.0, ss = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Pose2 p = pose_at(i);
    mx += p.x_m;
    my += p.y_m;
    sc += std::cos(p.heading_rad);
    ss += std::sin(p.heading_rad);
  }
  const double inv = 1.0 / static_cast<double>(n);
  mx *= inv;
  my *= inv;
  const double mh = std::atan2(ss, sc);
  double xx = 0.0, xy = 0.0, yy = 0.0, hh = 0.0;
  for (std::uint32_t i = 0; i < n; ++i) {
    const Pose2 p = pose_at(i);
    const double dx = p.x_m - mx;
    const double dy = p.y_m - my;
    const double dh = std::remainder(p.heading_rad - mh, 2.0 * M_PI);
    xx += dx * dx;
    xy += dx * dy;
    yy += dy * dy;
    hh += dh * dh;
  }
  const double c = std::cos(turn_rad);
  const double sn = std::sin(turn_rad);
  // R C Rᵀ for the position block, R the rotation by turn_rad.
  s.var_x = (c * c * xx - 2.0 * c * sn * xy + sn * sn * yy) * inv;
  s.cov_xy = (c * sn * (xx - yy) + (c * c - sn * sn) * xy) * inv;
  s.var_y = (sn * sn * xx + 2.0 * c * sn * xy + c * c * yy) * inv;
  s.var_heading = hh * inv;
  return s;
}

// The bottom-level DP-SLAM filter alone: the session of `sdpslam run --mode dpslam`
// (runtime/slam dpslam_session.h), fed one scan at a time.
class DpSlamEngine final : public SlamEngine {
 public:
  bool init(const DaemonConfig& c, std::string* error) {
    if (!session_.create(c.slam.filter, c.seed, error)) return false;
    session_.reserve_records(c.max_trajectory_scans);
    return true;
  }

  const char* name() const override { return "dpslam"; }

  EngineStep process(const OdometrySample& odom, const RangeScan& scan) override {
    const StepResult r = session_.feed(odom, scan);
    EngineStep s;
    s.processed = r.status == StepResult::Status::kProcessed;
    s.pose = r.pose;
    return s;
  }

  PoseSpread spread() const override {
    const DpSlamFilter& filter = session_.filter();
    return spread_of(filter.particle_count(), [&filter](std::uint32_t i) { return filter.particle_pose(i); }, 0.0);
  }

  std::vector<io::StampedPose> trajectory() const override { return session_.trajectory(nullptr); }

  std::uint32_t map_image(io::OccupancyImage* image) const override { return session_.map_image(image); }

  io::Json status_json() const override {
    const DpSlamFilter& filter = session_.filter();
    const DpSlamStats& st = filter.stats();
    const AncestryTree& tree = filter.tree();
    const DpMap& map = filter.map();
    return {{"particles", filter.particle_count()},
            {"processed", st.processed},
            {"resamplings", st.resamplings},
            {"map_updates_dropped", st.map_updates_dropped},
            {"node_fallbacks", st.node_fallback_count},
            {"ancestry_nodes_peak", tree.peak_used()},
            {"ancestry_nodes_capacity", tree.capacity()},
            {"path_entries_exhausted", tree.path_oom_count()},
            {"observations_peak", map.observations_peak()},
            {"observations_capacity", map.observation_capacity()},
            {"arena_bytes", session_.arena_bytes()},
            {"committed_poses_dropped", session_.committed_dropped()},
            {"unrecorded_scans", session_.unrecorded()}};
  }

  std::uint64_t unrecorded_scans() const override { return session_.unrecorded(); }

 private:
  slam::DpSlamSession session_;
};

// Segmented DP-SLAM: the session the offline runner runs (runtime/slam sdp_session.h),
// fed one scan at a time, with its outputs built by the same functions.
class SdpEngine final : public SlamEngine {
 public:
  bool init(const DaemonConfig& c, std::string* error) {
    if (!session_.create(c.slam.filter, c.sdp, c.seed, false, error)) return false;
    session_.reserve_records(c.max_trajectory_scans);
    output_directory_ = c.output_directory;
    return true;
  }

  const char* name() const override { return "sdp"; }

  EngineStep process(const OdometrySample& odom, const RangeScan& scan) override {
    const slam::ContinuationReport::Place before = session_.continuation().report().place;
    SdpStepResult r;
    const bool fed = session_.feed(odom, scan, &r);
    if (session_.continuation().report().place != before) notice_ = session_.continuation().report().describe();
    EngineStep s;
    if (!fed) {  // held back: a resumed session is looking for the robot
      s.placed = false;
      s.pose = session_.last_pose();
      return s;
    }
    s.processed = r.bottom.status == StepResult::Status::kProcessed;
    s.pose = r.pose;  // global frame, best top-level particle
    return s;
  }

  std::string take_notice() override {
    std::string n;
    n.swap(notice_);
    return n;
  }

  // The bottom-level particles live in the segment's frame: turned into the map frame by
  // the best particle's heading there and the estimate's heading here.
  PoseSpread spread() const override {
    const DpSlamFilter& bottom = session_.slam().bottom();
    return spread_of(bottom.particle_count(), [&bottom](std::uint32_t i) { return bottom.particle_pose(i); },
                     session_.last_pose().heading_rad - bottom.best_pose().heading_rad);
  }

  std::vector<io::StampedPose> trajectory() const override { return session_.trajectory(&path_gaps_); }

  std::uint32_t map_image(io::OccupancyImage* image) const override {
    known_cells_ = session_.map_image(image);
    return known_cells_;
  }

  void finish() override { session_.finish(); }

  io::Json status_json() const override {
    const SdpSlam& slam = session_.slam();
    io::Json js = {{"particles", slam.bottom().particle_count()},
                   {"top_particles", slam.options().top_particles},
                   {"processed", slam.bottom().stats().processed},
                   {"committed_poses_dropped", session_.permanent().dropped()},
                   {"unrecorded_scans", session_.unrecorded()}};
    // The offline runner's stats.json members; trajectory gaps and known cells as of the
    // last trajectory() / map_image().
    js.update(session_.state_json(path_gaps_, known_cells_));
    if (session_.continuation().active()) js["resumed"] = session_.continuation().report().json();
    return js;
  }

  std::uint64_t unrecorded_scans() const override { return session_.unrecorded(); }

  bool has_snapshots() const override { return true; }

  bool save_snapshot(const std::string& path, std::uint64_t fingerprint, std::uint64_t* file_bytes,
                     std::string* error) override {
    io::SnapshotOut out;
    if (!out.open(path, fingerprint, error)) return false;
    out.put_bytes(kSnapshotPart, sizeof kSnapshotPart);
    io::put_vector(out, session_.records());
    out.put_u64(session_.unrecorded());
    out.write(&session_.last_odom(), sizeof(Pose2));
    session_.permanent().write_state(out);
    if (!session_.slam().save_state(out)) {
      *error = path + ": " + session_.slam().why();
      return false;
    }
    if (!out.commit(error)) return false;
    *file_bytes = out.file_bytes();
    return true;
  }

  bool resume_snapshot(const std::string& path, std::uint64_t fingerprint, std::uint64_t* scans,
                       std::string* error) override {
    io::SnapshotInfo info;
    if (!io::check_snapshot(path, fingerprint, &info, error)) return false;
    io::SnapshotIn in;
    if (!in.open(path, error)) return false;
    std::string part;
    if (!in.get_bytes(&part, 64U) || part != std::string(kSnapshotPart, sizeof kSnapshotPart)) {
      *error = path + ": not a snapshot of sdpslamd in mode sdp";
      return false;
    }
    // The records keep the room reserved at create time: a longer one is refused.
    std::vector<slam::ScanRecord>& records = session_.records();
    std::uint64_t unrecorded = 0U;
    Pose2 last_odom;
    if (!io::get_vector(in, &records, records.capacity()) || !in.get_u64(&unrecorded) ||
        !in.read(&last_odom, sizeof last_odom) || !session_.permanent().read_state(in)) {
      *error = path + ": the snapshot's records are damaged or longer than [output] max_trajectory_scans";
      return false;
    }
    session_.set_unrecorded(unrecorded);
    session_.set_last_odom(last_odom);
    if (!session_.slam().load_state(in)) {
      *error = path + ": " + session_.slam().why();
      return false;
    }
    if (!in.at_end()) {
      *error = path + ": the snapshot holds more than this program reads";
      return false;
    }
    *scans = records.size() + unrecorded;
    // The trajectory written every [output] period_s holds where the robot went after
    // the snapshot (minutes apart): its last pose, if later, is where to look first.
    const std::int64_t last_stamp_us = records.empty() ? 0 : records.back().stamp_us;
    std::vector<io::StampedPose> written;
    std::string ignored;
    const bool later = !output_directory_.empty() &&
                       io::read_trajectory(output_directory_ + "/trajectory.txt", &written, &ignored) &&
                       !written.empty() && written.back().stamp_us > last_stamp_us;
    session_.continuation().begin(last_odom, last_stamp_us, later ? &written.back().pose : nullptr);
    return true;
  }

 private:
  static constexpr char kSnapshotPart[] = "sdpslamd sdp 1";
  // A resumed session most likely goes on where the robot stopped (sdpslamd restarted).
  slam::SdpSession session_{slam::SessionContinuation::kDefaultWindowM, true};
  std::string output_directory_;
  std::string notice_;
  mutable std::uint64_t path_gaps_ = 0U;
  mutable std::uint32_t known_cells_ = 0U;
};

// Localization on a saved map ([slam] mode = localize): the Monte Carlo localizer of
// `sdpslam localize` (core/localization, firmware-host/runtime/slam run_localize.h) one scan at a time.
// The map is not changed: the outputs are the path on it and the map as loaded.
class LocalizeEngine final : public SlamEngine {
 public:
  bool init(const DaemonConfig& c, std::string* error) {
    if (!session_.create(c.localize, c.localize_map, c.seed, c.localize_have_start ? &c.localize_start : nullptr,
                         kStartSigmaXyM, kStartSigmaThetaRad, error)) {
      return false;
    }
    session_.reserve_records(c.max_trajectory_scans);
    return true;
  }

  const char* name() const override { return "localize"; }

  EngineStep process(const OdometrySample& odom, const RangeScan& scan) override {
    const MonteCarloLocalizer::Step r = session_.feed(odom, scan);
    return EngineStep{r.updated, r.pose};
  }

  // The estimate at each scan as it was given (localization does not revise the past).
  PoseSpread spread() const override {
    const MonteCarloLocalizer& mcl = session_.localizer();
    const Pose2* particles = mcl.particles();
    return spread_of(mcl.particle_count(), [particles](std::uint32_t i) { return particles[i]; }, 0.0);
  }

  std::vector<io::StampedPose> trajectory() const override { return session_.trajectory(); }

  std::uint32_t map_image(io::OccupancyImage* image) const override {
    *image = session_.map().image;
    return session_.localizer().stats().free_cells + session_.localizer().stats().occupied_cells;
  }

  io::Json status_json() const override {
    const MonteCarloLocalizer& mcl = session_.localizer();
    const LocalizerStats& st = mcl.stats();
    return {{"particles", mcl.particle_count()},
            {"filter_updates", st.filter_updates},
            {"converged_at_scan", session_.converged_at()},
            {"spread_m", io::json_fixed(mcl.spread_m(), 4)},
            {"random_particles", st.random_particles},
            {"kld_capped", st.kld_capped},
            {"arena_bytes", session_.arena_bytes()},
            {"unrecorded_scans", session_.unrecorded()}};
  }

  std::uint64_t unrecorded_scans() const override { return session_.unrecorded(); }

 private:
  // The spread of the first particles around a configured start pose (as `sdpslam
  // localize --start`).
  static constexpr double kStartSigmaXyM = 0.25;
  static constexpr double kStartSigmaThetaRad = 0.15;
  slam::LocalizeSession session_;
};

}  // namespace

std::size_t engine_arena_bytes(const DaemonConfig& config) {
  if (config.mode == SlamMode::kSdp) return SdpSlam::required_arena_bytes(config.slam.filter, config.sdp);
  if (config.mode == SlamMode::kLocalize) {
    slam::LocalizationMap map;
    std::string error;
    if (!slam::load_localization_map(config.localize_map, &map, &error)) return 0U;
    return MonteCarloLocalizer::required_arena_bytes(config.localize, map.map);
  }
  return DpSlamFilter::required_arena_bytes(config.slam.filter);
}

std::unique_ptr<SlamEngine> make_engine(const DaemonConfig& config, std::string* error) {
  if (config.mode == SlamMode::kSdp) {
    auto e = std::make_unique<SdpEngine>();
    if (!e->init(config, error)) return nullptr;
    return e;
  }
  if (config.mode == SlamMode::kLocalize) {
    auto e = std::make_unique<LocalizeEngine>();
    if (!e->init(config, error)) return nullptr;
    return e;
  }
  auto e = std::make_unique<DpSlamEngine>();
  if (!e->init(config, error)) return nullptr;
  return e;
}

}  // namespace sdpslam::daemon
