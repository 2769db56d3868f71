// PairedWheelEncoders: the odometry steps on complete wheel pairs only, so frames read one
// at a time never produce a half-updated (spuriously turned) pose.
#include <CppUTest/TestHarness.h>

#include "sdpslam/daemon/paired_wheel_encoders.h"
#include "sdpslam/drivers/diff_drive_odometry.h"

using namespace sdpslam;
using namespace sdpslam::daemon;

namespace {

// One wheel at a time, as a CAN bus read frame by frame delivers them.
class OneWheelAtATime final : public hal::WheelEncoderSource {
 public:
  void wheel(hal::WheelTicks& w, std::uint32_t count, std::int64_t stamp_us) {
    w.raw_count = count;
    w.stamp_us = stamp_us;
    ++w.sequence;
    w.has_sample = true;
    w.stale = false;
  }
  int update() override { return 0; }
  hal::WheelEncoderSample latest() const override { return s; }
  hal::WheelEncoderSample s;
};

// A bus that only says whether frames are waiting.
class PendingBus final : public hal::CanBus {
 public:
  int send(const hal::CanFrame&) override { return 1; }
  int receive(hal::CanFrame&) override { return 0; }
  int wait_readable(std::int64_t) override { return pending ? 1 : 0; }
  hal::CanBusState state() const override { return hal::CanBusState::kActive; }
  const hal::CanBusStats& stats() const override { return st; }
  bool pending = false;
  hal::CanBusStats st;
};

}  // namespace

TEST_GROUP(SdpslamdPairedWheelEncoders){};

TEST(SdpslamdPairedWheelEncoders, one_wheel_sample_is_held_back_until_the_other_wheel_has_one) {
  OneWheelAtATime in;
  PairedWheelEncoders p(in, nullptr, 500000);
  in.wheel(in.s.left, 10, 100);
  p.update();
  CHECK_FALSE(p.latest().left.has_sample);
  in.wheel(in.s.right, 20, 100);
  p.update();
  LONGS_EQUAL(10, p.latest().left.raw_count);
  LONGS_EQUAL(20, p.latest().right.raw_count);
  in.wheel(in.s.left, 11, 200);
  p.update();
  LONGS_EQUAL(10, p.latest().left.raw_count);  // right not new yet: the old pair stays
  in.wheel(in.s.right, 21, 200);
  p.update();
  LONGS_EQUAL(11, p.latest().left.raw_count);
  LONGS_EQUAL(2, p.pairs_published());
}

TEST(SdpslamdPairedWheelEncoders, lost_frame_only_delays_the_next_pair_to_the_newest_counts) {
  OneWheelAtATime in;
  PairedWheelEncoders p(in, nullptr, 500000);
  in.wheel(in.s.left, 10, 100);
  in.wheel(in.s.right, 20, 100);
  p.update();
  in.wheel(in.s.left, 11, 200);  // its right partner is lost
  p.update();
  in.wheel(in.s.left, 12, 300);
  in.wheel(in.s.right, 22, 300);
  p.update();
  LONGS_EQUAL(12, p.latest().left.raw_count);
  LONGS_EQUAL(22, p.latest().right.raw_count);
  LONGS_EQUAL(300, p.latest().left.stamp_us);
}

TEST(SdpslamdPairedWheelEncoders, staleness_is_passed_through_at_once) {
  OneWheelAtATime in;
  PairedWheelEncoders p(in, nullptr, 500000);
  in.wheel(in.s.left, 10, 100);
  in.wheel(in.s.right, 20, 100);
  p.update();
  CHECK_TRUE(p.latest().both_fresh());
  in.s.right.stale = true;
  p.update();
  CHECK_FALSE(p.latest().both_fresh());
}

TEST(SdpslamdPairedWheelEncoders, straight_motion_read_frame_by_frame_never_turns_the_odometry) {
  OneWheelAtATime in;
  PairedWheelEncoders p(in, nullptr, 500000);
  drivers::EncoderOdometrySource odom(p, drivers::DiffDriveParams{});
  for (std::uint32_t k = 0; k < 5; ++k) {
    const std::int64_t t = 1000 + 100 * static_cast<std::int64_t>(k);
    in.wheel(in.s.left, 1000U * k, t);
    odom.update();
    DOUBLES_EQUAL(0.0, odom.latest().pose.heading_rad, 0.0);  // after the left frame alone
    in.wheel(in.s.right, 1000U * k, t);
    odom.update();
    DOUBLES_EQUAL(0.0, odom.latest().pose.heading_rad, 0.0);
  }
  DOUBLES_EQUAL(4.0 * 0.077 * 3.14159265358979323846, odom.latest().pose.x_m, 1e-9);
}

TEST(SdpslamdPairedWheelEncoders, wheel_called_stale_by_read_time_stays_fresh_while_its_frame_waits_in_the_backlog) {
  OneWheelAtATime in;
  PendingBus bus;
  PairedWheelEncoders p(in, &bus, 500000);
  in.wheel(in.s.left, 10, 1000000);
  in.wheel(in.s.right, 20, 1000000);
  p.update();
  // The loop was busy; the next pair arrived 200 ms later and is read frame by frame:
  // the driver, judging by read time, calls the right wheel stale after the left frame.
  in.wheel(in.s.left, 11, 1200000);
  in.s.right.stale = true;
  bus.pending = true;  // the right frame is still waiting
  p.update();
  CHECK_TRUE(p.latest().both_fresh());
  LONGS_EQUAL(1, p.drain_stale_overrides());
}

TEST(SdpslamdPairedWheelEncoders, outage_inside_a_backlog_is_still_stale) {
  OneWheelAtATime in;
  PendingBus bus;
  PairedWheelEncoders p(in, &bus, 500000);
  in.wheel(in.s.left, 10, 1000000);
  in.wheel(in.s.right, 20, 1000000);
  p.update();
  in.wheel(in.s.left, 11, 2000000);  // 1 s after the right wheel's last sample
  in.s.right.stale = true;
  bus.pending = true;
  p.update();
  CHECK_FALSE(p.latest().both_fresh());
}

TEST(SdpslamdPairedWheelEncoders, with_nothing_waiting_the_drivers_staleness_stands) {
  OneWheelAtATime in;
  PendingBus bus;
  PairedWheelEncoders p(in, &bus, 500000);
  in.wheel(in.s.left, 10, 1000000);
  in.wheel(in.s.right, 20, 1000000);
  p.update();
  in.s.left.stale = in.s.right.stale = true;
  p.update();
  CHECK_FALSE(p.latest().both_fresh());
  LONGS_EQUAL(0, p.drain_stale_overrides());
}
