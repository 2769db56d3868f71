#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdint>

#include "sdpslam/drivers/diff_drive_odometry.h"

using namespace sdpslam;
using namespace sdpslam::drivers;

namespace {
constexpr double kPi = 3.14159265358979323846;

// MinesRover (protocols.md §4): 2000 ticks/rev, r = 77 mm, half axle 165 mm.
DiffDriveParams mines_rover(std::uint8_t bits = 32) {
  DiffDriveParams p;
  p.ticks_per_rev = 2000.0;
  p.left_radius_m = 0.077;
  p.right_radius_m = 0.077;
  p.wheel_separation_m = 0.330;
  p.counter_bits = bits;
  return p;
}
double wrap_pi(double a) {
  a = std::remainder(a, 2.0 * kPi);
  return a <= -kPi ? a + 2.0 * kPi : a;
}
// a ⊕ b with std trigonometry (independent of the library under test).
Pose2 compose(const Pose2& a, const Pose2& b) {
  const double c = std::cos(a.heading_rad), s = std::sin(a.heading_rad);
  return Pose2{a.x_m + c * b.x_m - s * b.y_m, a.y_m + s * b.x_m + c * b.y_m, wrap_pi(a.heading_rad + b.heading_rad)};
}
constexpr double kMetresPerTick = 2.0 * kPi * 0.077 / 2000.0;

class FakeEncoders final : public hal::WheelEncoderSource {
 public:
  int update() override { return 0; }
  hal::WheelEncoderSample latest() const override { return sample; }
  void push(std::uint32_t left, std::uint32_t right, std::int64_t stamp_us) {
    sample.left.raw_count = left;
    sample.right.raw_count = right;
    sample.left.stamp_us = sample.right.stamp_us = stamp_us;
    sample.left.sequence++;
    sample.right.sequence++;
    sample.left.has_sample = sample.right.has_sample = true;
    sample.left.stale = sample.right.stale = false;
  }
  hal::WheelEncoderSample sample;
};
}  // namespace

TEST_GROUP(DiffDriveOdometry){};

TEST(DiffDriveOdometry, params_validation_names_the_bad_field) {
  DiffDriveParams p = mines_rover();
  CHECK(validate(p) == DiffDriveParamsError::kOk);
  p.wheel_separation_m = 0.0;
  CHECK(validate(p) == DiffDriveParamsError::kWheelSeparation);
  p = mines_rover();
  p.left_sign = 0;
  CHECK(validate(p) == DiffDriveParamsError::kSign);
  p = mines_rover();
  p.counter_bits = 24;
  CHECK(validate(p) == DiffDriveParamsError::kCounterBits);
  p = mines_rover();
  p.ticks_per_rev = NAN;
  CHECK(validate(p) == DiffDriveParamsError::kTicksPerRev);
}

TEST(DiffDriveOdometry, invalid_params_refuse_every_update) {
  DiffDriveParams p = mines_rover();
  p.right_radius_m = -1.0;
  DiffDriveOdometry odo(p);
  CHECK(odo.update(0, 0, 0) == DiffDriveOdometry::Step::kInvalidParams);
  CHECK(odo.update(10, 10, 1) == DiffDriveOdometry::Step::kInvalidParams);
}

TEST(DiffDriveOdometry, first_sample_is_latched_not_integrated) {
  DiffDriveOdometry odo(mines_rover());
  CHECK(odo.update(123456789u, 987654321u, 10) == DiffDriveOdometry::Step::kLatched);
  DOUBLES_EQUAL(0.0, odo.pose().x_m, 0.0);
  DOUBLES_EQUAL(0.0, odo.pose().y_m, 0.0);
  DOUBLES_EQUAL(0.0, odo.pose().heading_rad, 0.0);
  CHECK(odo.update(123456789u, 987654321u, 20) == DiffDriveOdometry::Step::kIntegrated);
  DOUBLES_EQUAL(0.0, odo.pose().x_m, 0.0);
}

TEST(DiffDriveOdometry, straight_line_one_revolution_is_wheel_circumference) {
  DiffDriveOdometry odo(mines_rover());
  odo.update(1000, 5000, 0);
  odo.update(3000, 7000, 1);
  DOUBLES_EQUAL(2.0 * kPi * 0.077, odo.pose().x_m, 1e-12);
  DOUBLES_EQUAL(0.0, odo.pose().y_m, 1e-12);
  DOUBLES_EQUAL(0.0, odo.pose().heading_rad, 1e-12);
}

TEST(DiffDriveOdometry, straight_line_follows_current_heading) {
  DiffDriveOdometry odo(mines_rover(), Pose2{1.0, 2.0, kPi / 2});
  odo.update(0, 0, 0);
  odo.update(2000, 2000, 1);
  DOUBLES_EQUAL(1.0, odo.pose().x_m, 1e-12);
  DOUBLES_EQUAL(2.0 + 2.0 * kPi * 0.077, odo.pose().y_m, 1e-12);
}

TEST(DiffDriveOdometry, pure_rotation_keeps_position) {
  DiffDriveOdometry odo(mines_rover());
  odo.update(0, 0, 0);
  odo.update(static_cast<std::uint32_t>(-500), 500, 1);
  const double expected = 2.0 * 500 * kMetresPerTick / 0.330;
  DOUBLES_EQUAL(0.0, odo.pose().x_m, 1e-12);
  DOUBLES_EQUAL(0.0, odo.pose().y_m, 1e-12);
  DOUBLES_EQUAL(expected, odo.pose().heading_rad, 1e-12);
}

TEST(DiffDriveOdometry, arc_lands_on_the_circle) {
  DiffDriveOdometry odo(mines_rover());
  odo.update(0, 0, 0);
  odo.update(1000, 2000, 1);
  const double l = 1000 * kMetresPerTick, r = 2000 * kMetresPerTick;
  const double ds = (l + r) / 2, dth = (r - l) / 0.330, radius = ds / dth;
  DOUBLES_EQUAL(radius * std::sin(dth), odo.pose().x_m, 1e-12);
  DOUBLES_EQUAL(radius * (1.0 - std::cos(dth)), odo.pose().y_m, 1e-12);
  DOUBLES_EQUAL(dth, odo.pose().heading_rad, 1e-12);
}

TEST(DiffDriveOdometry, arc_integration_is_exact_when_split_in_steps) {
  DiffDriveOdometry one(mines_rover()), many(mines_rover());
  one.update(0, 0, 0);
  one.update(3000, 6000, 1);
  many.update(0, 0, 0);
  for (std::uint32_t k = 1; k <= 100; ++k) many.update(30 * k, 60 * k, k);
  DOUBLES_EQUAL(one.pose().x_m, many.pose().x_m, 1e-9);
  DOUBLES_EQUAL(one.pose().y_m, many.pose().y_m, 1e-9);
  DOUBLES_EQUAL(one.pose().heading_rad, many.pose().heading_rad, 1e-9);
}

TEST(DiffDriveOdometry, direction_sign_and_gear_ratio_apply) {
  DiffDriveParams p = mines_rover();
  p.left_sign = -1;   // left encoder mounted mirrored
  p.gear_ratio = 0.5; // two encoder revolutions per wheel revolution
  DiffDriveOdometry odo(p);
  odo.update(0, 0, 0);
  odo.update(static_cast<std::uint32_t>(-4000), 4000, 1);
  DOUBLES_EQUAL(2.0 * kPi * 0.077, odo.pose().x_m, 1e-12);
  DOUBLES_EQUAL(0.0, odo.pose().heading_rad, 1e-12);
}

TEST(DiffDriveOdometry, wrap_delta_sixteen_bit_both_directions) {
  LONGS_EQUAL(10, wrap_delta(4, 65530, 16));
  LONGS_EQUAL(-10, wrap_delta(65530, 4, 16));
  LONGS_EQUAL(-32768, wrap_delta(0x8000, 0, 16));
  LONGS_EQUAL(32767, wrap_delta(0x7FFF, 0, 16));
}

TEST(DiffDriveOdometry, wrap_delta_thirty_two_bit_both_directions) {
  LONGS_EQUAL(10, wrap_delta(4, 0xFFFFFFFAu, 32));
  LONGS_EQUAL(-10, wrap_delta(0xFFFFFFFAu, 4, 32));
}

TEST(DiffDriveOdometry, sixteen_bit_counter_forward_across_wrap) {
  DiffDriveOdometry odo(mines_rover(16));
  odo.update(65000, 65000, 0);
  odo.update(1464, 1464, 1);  // +2000 through 2^16
  DOUBLES_EQUAL(2.0 * kPi * 0.077, odo.pose().x_m, 1e-12);
}

TEST(DiffDriveOdometry, sixteen_bit_counter_backward_across_wrap) {
  DiffDriveOdometry odo(mines_rover(16));
  odo.update(500, 500, 0);
  odo.update(64036, 64036, 1);  // −2000 through 0
  DOUBLES_EQUAL(-2.0 * kPi * 0.077, odo.pose().x_m, 1e-12);
}

TEST(DiffDriveOdometry, thirty_two_bit_counter_forward_and_backward_across_wrap) {
  DiffDriveOdometry odo(mines_rover(32));
  odo.update(0xFFFFFC18u, 0xFFFFFC18u, 0);  // −1000
  odo.update(1000, 1000, 1);                // +2000 through 2^32
  DOUBLES_EQUAL(2.0 * kPi * 0.077, odo.pose().x_m, 1e-12);
  odo.update(0xFFFFFC18u, 0xFFFFFC18u, 2);  // back −2000 through 0
  DOUBLES_EQUAL(0.0, odo.pose().x_m, 1e-12);
  LONGS_EQUAL(0, odo.left_ticks_total());
}

TEST(DiffDriveOdometry, inverse_of_straight_line_is_equal_ticks) {
  const Pose2 poses[] = {{0, 0, 0}, {2.0 * kPi * 0.077, 0, 0}};
  std::int64_t l[2], r[2];
  CHECK_TRUE(poses_to_ticks(mines_rover(), poses, 2, l, r));
  LONGS_EQUAL(0, l[0]);
  LONGS_EQUAL(2000, l[1]);
  LONGS_EQUAL(2000, r[1]);
}

TEST(DiffDriveOdometry, inverse_refuses_empty_input_and_bad_params) {
  std::int64_t l[1], r[1];
  const Pose2 p{};
  CHECK_FALSE(poses_to_ticks(mines_rover(), &p, 0, l, r));
  DiffDriveParams bad = mines_rover();
  bad.gear_ratio = 0.0;
  CHECK_FALSE(poses_to_ticks(bad, &p, 1, l, r));
}

// Forward from integer ticks gives exact arc poses; inverting them must give the same
// ticks back within one tick, over straight runs, arcs, spins, reversing and both wraps.
TEST(DiffDriveOdometry, forward_then_inverse_returns_the_ticks_within_one) {
  constexpr int kN = 400;
  std::uint32_t state = 12345u;
  auto next = [&state]() {  // xorshift32: deterministic test motion
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return state;
  };
  DiffDriveOdometry odo(mines_rover(16));
  Pose2 poses[kN];
  std::int64_t left[kN], right[kN];
  std::int64_t lt = 65000, rt = 10;  // start near the 16-bit wrap
  odo.update(static_cast<std::uint16_t>(lt), static_cast<std::uint16_t>(rt), 0);
  poses[0] = odo.pose();
  left[0] = right[0] = 0;
  for (int i = 1; i < kN; ++i) {
    const int dl = static_cast<int>(next() % 401) - 200;
    const int dr = (i % 50 < 10) ? -dl : static_cast<int>(next() % 401) - 200;
    lt += dl;
    rt += dr;
    odo.update(static_cast<std::uint16_t>(lt), static_cast<std::uint16_t>(rt), i);
    poses[i] = odo.pose();
    left[i] = left[i - 1] + dl;
    right[i] = right[i - 1] + dr;
  }
  std::int64_t il[kN], ir[kN];
  CHECK_TRUE(poses_to_ticks(mines_rover(16), poses, kN, il, ir));
  for (int i = 0; i < kN; ++i) {
    CHECK_TRUE(std::llabs(il[i] - left[i]) <= 1);
    CHECK_TRUE(std::llabs(ir[i] - right[i]) <= 1);
  }
}

TEST(DiffDriveOdometry, inverse_then_forward_reproduces_poses_within_a_tick) {
  // A square-ish path: straight 1 m, quarter arcs of radius 0.5 m, sampled every 5 cm.
  constexpr int kN = 4 * (20 + 16) + 1;
  Pose2 poses[kN];
  int n = 0;
  Pose2 p{};
  poses[n++] = p;
  for (int side = 0; side < 4; ++side) {
    for (int k = 0; k < 20; ++k) poses[n++] = p = compose(p, Pose2{0.05, 0.0, 0.0});
    const double step = (kPi / 2) / 16;
    for (int k = 0; k < 16; ++k) {
      const double rr = 0.5;
      poses[n++] = p = compose(p, Pose2{rr * std::sin(step), rr * (1 - std::cos(step)), step});
    }
  }
  LONGS_EQUAL(kN, n);
  std::int64_t l[kN], r[kN];
  CHECK_TRUE(poses_to_ticks(mines_rover(), poses, kN, l, r));
  DiffDriveOdometry odo(mines_rover());
  odo.update(0, 0, 0);
  const double tick_angle = 2.0 * kMetresPerTick / 0.330;
  for (int i = 1; i < kN; ++i) {
    odo.update(static_cast<std::uint32_t>(l[i]), static_cast<std::uint32_t>(r[i]), i);
    DOUBLES_EQUAL(0.0, wrap_pi(odo.pose().heading_rad - poses[i].heading_rad), tick_angle);
  }
  // Back at the start after a full loop: within a tick of travel per coordinate, with
  // heading rounding (≤ one tick angle) spread over the path.
  const double path_m = 4.0 * (1.0 + 0.5 * kPi / 2);
  DOUBLES_EQUAL(poses[kN - 1].x_m, odo.pose().x_m, kMetresPerTick + path_m * tick_angle);
  DOUBLES_EQUAL(poses[kN - 1].y_m, odo.pose().y_m, kMetresPerTick + path_m * tick_angle);
}

TEST_GROUP(EncoderOdometrySource){};

TEST(EncoderOdometrySource, reports_no_data_before_any_sample) {
  FakeEncoders enc;
  EncoderOdometrySource src(enc, mines_rover());
  LONGS_EQUAL(0, src.update());
  CHECK(src.latest().status == hal::OdometryStatus::kNoData);
}

TEST(EncoderOdometrySource, first_pair_latches_then_integrates) {
  FakeEncoders enc;
  EncoderOdometrySource src(enc, mines_rover());
  enc.push(100, 100, 10);
  LONGS_EQUAL(0, src.update());
  CHECK(src.latest().status == hal::OdometryStatus::kLatching);
  enc.push(2100, 2100, 20);
  LONGS_EQUAL(1, src.update());
  CHECK_TRUE(src.latest().valid());
  LONGS_EQUAL(20, src.latest().stamp_us);
  DOUBLES_EQUAL(2.0 * kPi * 0.077, src.latest().pose.x_m, 1e-12);
}

TEST(EncoderOdometrySource, same_sample_is_not_integrated_twice) {
  FakeEncoders enc;
  EncoderOdometrySource src(enc, mines_rover());
  enc.push(0, 0, 10);
  src.update();
  enc.push(100, 100, 20);
  LONGS_EQUAL(1, src.update());
  LONGS_EQUAL(0, src.update());
  DOUBLES_EQUAL(100 * kMetresPerTick, src.latest().pose.x_m, 1e-12);
}

TEST(EncoderOdometrySource, stale_wheel_reports_stale_and_does_not_move) {
  FakeEncoders enc;
  EncoderOdometrySource src(enc, mines_rover());
  enc.push(0, 0, 10);
  src.update();
  enc.push(100, 100, 20);
  src.update();
  enc.push(5000, 5000, 30);
  enc.sample.right.stale = true;  // right wheel stopped reporting
  LONGS_EQUAL(0, src.update());
  CHECK(src.latest().status == hal::OdometryStatus::kStale);
  CHECK_FALSE(src.latest().valid());
  DOUBLES_EQUAL(100 * kMetresPerTick, src.latest().pose.x_m, 1e-12);
  LONGS_EQUAL(20, src.latest().stamp_us);
  LONGS_EQUAL(1, src.stale_count());
}

TEST(EncoderOdometrySource, recovery_after_stale_relatches_without_inventing_motion) {
  FakeEncoders enc;
  EncoderOdometrySource src(enc, mines_rover());
  enc.push(0, 0, 10);
  src.update();
  enc.sample.left.stale = true;
  src.update();
  enc.push(9000, 9000, 40);  // both fresh again, far away
  LONGS_EQUAL(0, src.update());
  CHECK(src.latest().status == hal::OdometryStatus::kLatching);
  DOUBLES_EQUAL(0.0, src.latest().pose.x_m, 0.0);
  LONGS_EQUAL(1, src.relatch_count());
  enc.push(9100, 9100, 50);
  LONGS_EQUAL(1, src.update());
  DOUBLES_EQUAL(100 * kMetresPerTick, src.latest().pose.x_m, 1e-12);
}
