#pragma once
// Differential-drive wheel odometry, forward (ticks -> pose) and inverse (poses -> ticks).
// Pure logic, no I/O, no heap: portable to the core if ever needed.
//
// Model (protocols.md §4): wheel angle = ticks · 2π / ticks_per_rev · gear_ratio;
//   per step  ds = (dL·rL + dR·rR)/2,  dθ = (dR·rR − dL·rL)/wheel_separation,
//   along the arc: if |dθ| < 1e-6 a straight line along θ, else
//   x += ds/dθ·(sin(θ+dθ) − sin θ),  y −= ds/dθ·(cos(θ+dθ) − cos θ).
// Counter deltas are taken modulo 2^counter_bits as signed values (protocols.md §3), so a
// 16- or 32-bit counter wraps in either direction as long as a wheel moves less than half
// the counter range between two samples.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/pose2.h"
#include "sdpslam/hal/odometry_source.h"
#include "sdpslam/hal/wheel_encoder_source.h"

namespace sdpslam::drivers {

struct DiffDriveParams {
  double ticks_per_rev = 2000.0;     // encoder counts per encoder-shaft revolution
  double gear_ratio = 1.0;           // wheel revolutions per encoder revolution
  double left_radius_m = 0.077;
  double right_radius_m = 0.077;
  double wheel_separation_m = 0.330; // distance between the wheel contact points
  int left_sign = 1;                 // +1 or -1: counts increase when the wheel drives forward
  int right_sign = 1;
  std::uint8_t counter_bits = 32;    // 16 or 32
};

enum class DiffDriveParamsError : std::uint8_t {
  kOk,
  kTicksPerRev,     // must be finite and > 0
  kGearRatio,       // must be finite and > 0
  kRadius,          // both radii finite and > 0
  kWheelSeparation, // finite and > 0
  kSign,            // each sign exactly +1 or -1
  kCounterBits,     // 16 or 32
};
DiffDriveParamsError validate(const DiffDriveParams& p);
const char* to_string(DiffDriveParamsError e);

// Signed difference cur − last modulo 2^bits (bits = 16 or 32).
std::int32_t wrap_delta(std::uint32_t cur, std::uint32_t last, std::uint8_t bits);

// Integrates wheel counters into a pose. Construct only with validated params (an invalid
// set is refused: every update() then returns kInvalidParams).
class DiffDriveOdometry {
 public:
  enum class Step : std::uint8_t { kLatched, kIntegrated, kInvalidParams };

  explicit DiffDriveOdometry(const DiffDriveParams& params, const Pose2& start = Pose2{});

  // Feeds one pair of raw counter readings taken together. The first pair after
  // construction or reset() is latched (the reference for later deltas) and never
  // integrated.
  Step update(std::uint32_t left_raw, std::uint32_t right_raw, std::int64_t stamp_us);
  // Forgets the latch; the next update() latches again. The pose is kept (or set).
  void unlatch() { latched_ = false; }
  void reset(const Pose2& pose) {
    pose_ = pose;
    latched_ = false;
  }

  const Pose2& pose() const { return pose_; }
  bool latched() const { return latched_; }
  std::int64_t stamp_us() const { return stamp_us_; }
  const DiffDriveParams& params() const { return params_; }
  bool params_ok() const { return params_ok_; }
  // Accumulated signed travel of each wheel in ticks since construction (after signs).
  std::int64_t left_ticks_total() const { return left_total_; }
  std::int64_t right_ticks_total() const { return right_total_; }

 private:
  DiffDriveParams params_;
  bool params_ok_;
  Pose2 pose_;
  bool latched_ = false;
  std::uint32_t last_left_ = 0;
  std::uint32_t last_right_ = 0;
  std::int64_t stamp_us_ = 0;
  std::int64_t left_total_ = 0;
  std::int64_t right_total_ = 0;
};

// Inverse model for replay: cumulative signed ticks per wheel that drive the robot
// through `poses` (poses[0] is the start; left/right_ticks[0] = 0).
// Assumptions: between consecutive poses the robot follows one constant-curvature arc
// (the same model the forward integration uses), so the turn is dθ = θ1 − θ0 wrapped to
// (−π, π] and the arc length follows from the chord; any displacement sideways to that
// arc (which a differential drive cannot make) is ignored; reversing is a negative ds.
// Ticks are rounded from the exact cumulative value, so the rounding error never exceeds
// half a tick per wheel and does not accumulate. Apply counter wrap with
// `static_cast<uint32_t>` (or uint16_t) of the result. Returns false iff params are
// invalid or n == 0.
bool poses_to_ticks(const DiffDriveParams& params, const Pose2* poses, std::size_t n,
                    std::int64_t* left_ticks, std::int64_t* right_ticks);

// hal::OdometrySource over a hal::WheelEncoderSource. A step is integrated only when both
// wheels are fresh and at least one has a sample not used yet (pairs by newest stamp);
// when either wheel goes stale the reading says kStale and the pose stays where it was
// (no extrapolation), and the next fresh pair is latched again (motion during the
// outage is not known and not invented; relatch_count says how often that happened).
class EncoderOdometrySource final : public hal::OdometrySource {
 public:
  EncoderOdometrySource(hal::WheelEncoderSource& encoders, const DiffDriveParams& params);
  int update() override;
  hal::OdometryReading latest() const override { return reading_; }
  std::uint32_t relatch_count() const { return relatch_count_; }
  std::uint32_t stale_count() const { return stale_count_; }
  const DiffDriveOdometry& odometry() const { return odom_; }

 private:
  hal::WheelEncoderSource& encoders_;
  DiffDriveOdometry odom_;
  hal::OdometryReading reading_;
  std::uint32_t used_left_seq_ = 0;
  std::uint32_t used_right_seq_ = 0;
  bool was_stale_ = false;
  std::uint32_t relatch_count_ = 0;
  std::uint32_t stale_count_ = 0;
};

}  // namespace sdpslam::drivers
