#pragma once
// Localization on a saved map: Monte Carlo localization (Thrun, Burgard & Fox,
// "Probabilistic Robotics" 2005, ch. 8) with
//   - the likelihood-field sensor model (§6.4, Table 6.3): the map's distance to the
//     nearest occupied cell is computed once at init (exact Euclidean distance transform,
//     Felzenszwalb & Huttenlocher 2012) and kept as log p(z_k | x, m) per cell, so a beam
//     costs one lookup;
//   - KLD-sampling (Fox 2003; Table 8.4): after each update as many particles are drawn
//     as make the Kullback-Leibler distance between the sample and the belief below
//     kld_error with probability kld_quantile, between min_particles and max_particles
//     (few when the pose is known, many while it is not);
//   - augmented MCL (Table 8.3): a short- and a long-term average of how well the belief
//     explains the scans; when the short one falls below half the long one (the robot is
//     lost, or was carried), a share of the new particles, 1 − 2·short/long, is drawn at
//     random free cells. (Thrun's rule, 1 − short/long, also fires on the ordinary swing
//     of the fit from place to place, and the random particles it keeps adding make a
//     tracked robot jump to look-alike places.)
// The estimate is the heaviest mode of the weighed particles, not their mean.
// The odometry motion model is the bottom level's (motion_model.h, Table 5.6).
//
// Memory: everything is carved from the arena at init (required_arena_bytes): one byte
// per map cell (the likelihood in 128 steps and whether the cell is free), the particles
// and the KLD bins for max_particles. update() never allocates. Deterministic given the
// seed (det_math).
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/bottom/motion_model.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/range_scan.h"
#include "sdpslam/core/rng.h"

namespace sdpslam {

struct LocalizerOptions {
  std::uint32_t min_particles = 200U;    // KLD floor, >= 10
  std::uint32_t max_particles = 20000U;  // KLD ceiling and memory, min_particles .. 1,000,000
  double kld_error = 0.05;               // ε, (0, 1)
  double kld_quantile_z = 2.326;         // z_(1-δ): 2.326 for δ = 0.01, (0, 10]
  double kld_bin_xy_m = 0.5;             // histogram bins of the KLD bound, (0, 10]
  double kld_bin_theta_rad = 0.1745;     // 10°, (0, π]
  double sigma_hit_m = 0.1;              // likelihood field: spread of a hit around a wall, (0, 5]
  double z_hit = 0.9;                    // share of hits; the rest is z_rand / range_max, (0, 1)
  double max_distance_m = 2.0;           // distances are clamped here (the field's reach), (0, 20]
  std::uint32_t beams = 60U;             // beams weighed per update, evenly spread, 1 .. kMaxBeams
  // The beams of one scan are not independent (the map's cells, the field's smoothing,
  // one pose error moves them all): a scan's log-likelihood is scaled to count as this
  // many independent beams (weight = exp(Σ log p · independent_beams / beams used)), so
  // that one scan does not collapse the set onto one particle. 1 .. beams.
  std::uint32_t independent_beams = 8U;
  double update_min_travel_m = 0.2;      // a filter update after this travel ...
  double update_min_turn_rad = 0.2;      // ... or this turn, [0, 10]
  double recovery_alpha_slow = 0.001;    // augmented MCL's averages, 0 <= slow < fast <= 1
  double recovery_alpha_fast = 0.1;      // (slow = fast = 0: no random particles)
  MotionModelOptions motion{};

  // Empty when valid; otherwise "key: why" of the first bad option (to fill `why`, n bytes).
  bool check(char* why, std::size_t n) const;
};

// The saved map as the localizer reads it: cells row-major from row 0 (lowest y), cell
// (col, row) covering x in [origin_x_m + col·res, +res), y likewise.
struct LocalizerMap {
  std::uint32_t width = 0U;
  std::uint32_t height = 0U;
  double resolution_m = 0.05;
  double origin_x_m = 0.0;
  double origin_y_m = 0.0;
  enum Cell : std::uint8_t { kFree = 0U, kOccupied = 1U, kUnknown = 2U };
  const std::uint8_t* cells = nullptr;  // width × height of Cell; read during init only
};

struct LocalizerStats {
  std::uint64_t scans = 0U;              // update() calls
  std::uint64_t filter_updates = 0U;     // scans that moved the filter (weighed and resampled)
  std::uint64_t beams_weighed = 0U;
  std::uint64_t random_particles = 0U;   // drawn at random free cells (global start, recovery)
  std::uint64_t kld_capped = 0U;         // resamplings that wanted more than max_particles
  std::uint64_t degenerate_weights = 0U; // updates where no particle explained the scan
  std::uint32_t free_cells = 0U;
  std::uint32_t occupied_cells = 0U;
};

class MonteCarloLocalizer {
 public:
  // Arena bytes init() needs for this map; 0 if the options or the map are invalid.
  static std::size_t required_arena_bytes(const LocalizerOptions& options, const LocalizerMap& map);
  // Builds the likelihood field; false (with `why`) on bad options or map, a map without
  // free cells, or a short arena. The filter has no particles until start_*().
  bool init(const LocalizerOptions& options, const LocalizerMap& map, Arena& arena, std::uint64_t seed, char* why,
            std::size_t n);

  // Tracking: min_particles drawn around `pose` (map frame) with these deviations.
  void start_at(const Pose2& pose, double sigma_xy_m, double sigma_theta_rad);
  // Global localization: max_particles at random free cells and headings.
  void start_global();

  struct Step {
    bool updated = false;  // the filter weighed and resampled on this scan
    Pose2 pose;            // the estimate at the scan's time (map frame)
    double spread_m = 0.0; // √(var x + var y) of the particles at the last update
  };
  // One scan with the odometry pose at its stamp. Before the first update of a start, or
  // after enough motion, the particles move by the odometry since the last update, are
  // weighed by the scan, and are resampled; otherwise the last estimate moves with the
  // odometry.
  Step update(const OdometrySample& odom, const RangeScan& scan);

  std::uint32_t particle_count() const { return count_; }
  const Pose2* particles() const { return pose_; }
  Pose2 estimate() const { return estimate_; }
  double spread_m() const { return spread_m_; }
  const LocalizerStats& stats() const { return stats_; }
  // log p of one beam ending at (x, y): the likelihood field (tests, pictures).
  double log_field(double x_m, double y_m) const;

 private:
  Pose2 random_free_pose();
  void weigh(const RangeScan& scan);
  void resample();
  void summarise();

  LocalizerOptions options_{};
  MotionModel motion_{};
  Rng rng_{};
  std::uint32_t width_ = 0U, height_ = 0U;
  double res_m_ = 0.05, origin_x_m_ = 0.0, origin_y_m_ = 0.0;
  // Per cell: log p as one of kLevels steps of log_step_ above log_floor_ (a beam ending
  // off the map, or beyond the field's reach, gets the floor), and kFreeBit for a free cell.
  static constexpr std::uint32_t kLevels = 128U;
  static constexpr std::uint8_t kFreeBit = 0x80U;
  static constexpr std::int64_t kReachCells = 250;  // fits the column pass's byte
  std::uint8_t* field_ = nullptr;
  double log_floor_ = 0.0;
  double log_step_ = 0.0;
  Pose2* pose_ = nullptr;            // particles
  Pose2* next_ = nullptr;
  double* log_w_ = nullptr;
  double* cumulative_ = nullptr;
  std::uint64_t* bins_ = nullptr;    // open addressing, bin_capacity_ slots (0 = empty)
  std::uint32_t bin_capacity_ = 0U;
  std::uint32_t count_ = 0U;
  bool initialised_ = false;
  bool have_update_ = false;
  Pose2 odom_at_update_{};
  Pose2 estimate_{};
  double spread_m_ = 0.0;
  double w_slow_ = 0.0, w_fast_ = 0.0;
  LocalizerStats stats_{};
};

}  // namespace sdpslam
