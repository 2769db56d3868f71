// Kinematics and the route follower: exact arcs, limits, and driving the paper's loops.
#include <CppUTest/TestHarness.h>

#include <cmath>

#include "sdpslam/sim/diff_drive.h"
#include "sdpslam/sim/simulator.h"
#include "sim_test_util.h"

using namespace sdpslam;
using namespace sdpslam::sim;
using sdpslam::test::RecordingSink;

namespace {
constexpr double kPi = 3.14159265358979323846;

SimulationSummary drive(const Route& route, RecordingSink* sink, SimulationOptions o = test::cheap_laser_options()) {
  SimulationSummary summary;
  std::string error;
  CHECK_TRUE_TEXT(run_simulation(builtin_world(), route, o, sink, &summary, &error), error.c_str());
  return summary;
}

Route sub_route(std::size_t first, std::size_t last) {
  const Route all = builtin_route();
  Route r;
  r.waypoints.assign(all.waypoints.begin() + static_cast<long>(first), all.waypoints.begin() + static_cast<long>(last) + 1);
  return r;
}
}  // namespace

TEST_GROUP(SimRobot){};

TEST(SimRobot, straight_motion_integrates_exactly) {
  const Pose2 p = integrate_arc(Pose2{1.0, 2.0, 0.0}, 1.5, 0.0);
  DOUBLES_EQUAL(2.5, p.x_m, 0.0);
  DOUBLES_EQUAL(2.0, p.y_m, 0.0);
  DOUBLES_EQUAL(0.0, p.heading_rad, 0.0);
}

TEST(SimRobot, quarter_circle_arc_lands_on_the_circle) {
  // Radius 1 m, turning left from the origin facing +x: ends at (1, 1) facing +y.
  const Pose2 p = integrate_arc(Pose2{}, kPi / 2.0, kPi / 2.0);
  DOUBLES_EQUAL(1.0, p.x_m, 1e-12);
  DOUBLES_EQUAL(1.0, p.y_m, 1e-12);
  DOUBLES_EQUAL(kPi / 2.0, p.heading_rad, 1e-12);
}

TEST(SimRobot, rotation_in_place_does_not_translate) {
  const Pose2 p = integrate_arc(Pose2{3.0, 4.0, 0.5}, 0.0, 0.7);
  DOUBLES_EQUAL(3.0, p.x_m, 0.0);
  DOUBLES_EQUAL(4.0, p.y_m, 0.0);
  DOUBLES_EQUAL(1.2, p.heading_rad, 1e-15);
}

TEST(SimRobot, follower_of_an_empty_route_is_finished_and_commands_nothing) {
  Route r;
  r.waypoints = {{0.0, 0.0}};
  PathFollower f(r, FollowerOptions{}, RobotLimits{});
  CHECK_TRUE(f.finished());
  const Twist t = f.update(Pose2{}, 0.01);
  DOUBLES_EQUAL(0.0, t.v_mps, 0.0);
  DOUBLES_EQUAL(0.0, t.w_radps, 0.0);
}

TEST(SimRobot, full_builtin_route_returns_to_the_start_within_0_2_m) {
  RecordingSink sink;
  const SimulationSummary s = drive(builtin_route(), &sink);
  CHECK_TRUE(s.reached_goal);
  const Point2 start = builtin_route().waypoints.front();
  CHECK(std::hypot(s.final_true.x_m - start.x_m, s.final_true.y_m - start.y_m) < 0.2);
  // The log ends with a scan of the robot at rest on the goal.
  DOUBLES_EQUAL(s.final_true.x_m, sink.truth.back().x_m, 0.0);
  DOUBLES_EQUAL(s.final_true.y_m, sink.truth.back().y_m, 0.0);
}

TEST(SimRobot, driven_inner_loop_is_28_m_within_3_percent) {
  RecordingSink sink;
  const SimulationSummary s = drive(sub_route(0, kBuiltinInnerLoopEndWaypoint), &sink);
  CHECK_TRUE(s.reached_goal);
  DOUBLES_EQUAL(28.0, s.distance_m, 0.03 * 28.0);
}

TEST(SimRobot, driven_outer_loop_is_80_m_within_3_percent) {
  RecordingSink sink;
  const SimulationSummary s = drive(sub_route(kBuiltinInnerLoopEndWaypoint, builtin_route().waypoints.size() - 1), &sink);
  CHECK_TRUE(s.reached_goal);
  DOUBLES_EQUAL(80.0, s.distance_m, 0.03 * 80.0);
}

TEST(SimRobot, robot_keeps_clear_of_the_walls_on_the_builtin_route) {
  RecordingSink sink;
  const SimulationSummary s = drive(builtin_route(), &sink);
  CHECK(s.min_wall_clearance_m > 0.5);
}

TEST(SimRobot, speed_and_acceleration_stay_within_limits) {
  SimulationOptions o = test::cheap_laser_options();
  o.robot.max_speed_mps = 0.8;
  o.robot.max_accel_mps2 = 0.4;
  RecordingSink sink;
  const SimulationSummary s = drive(builtin_route(), &sink, o);
  CHECK_TRUE(s.reached_goal);
  double top = 0.0;
  const double dt = 1.0 / o.odom_rate_hz;
  for (std::size_t i = 0; i < sink.odoms.size(); ++i) {
    const io::OdomRecord& r = sink.odoms[i];
    CHECK(r.tv_mps >= 0.0 && r.tv_mps <= 0.8 + 1e-12);
    CHECK(std::fabs(r.rv_radps) <= o.robot.max_angular_speed_radps + 1e-12);
    if (i > 0) CHECK(std::fabs(r.tv_mps - sink.odoms[i - 1].tv_mps) <= 0.4 * dt + 1e-9);
    top = std::fmax(top, r.tv_mps);
  }
  DOUBLES_EQUAL(0.8, top, 1e-9);  // the straights are long enough to reach full speed
}

TEST(SimRobot, default_run_takes_about_route_length_over_speed) {
  RecordingSink sink;
  const SimulationSummary s = drive(builtin_route(), &sink);
  CHECK(s.duration_s > 108.0 / 0.5);
  CHECK(s.duration_s < 1.3 * 108.0 / 0.5);
  // 10 Hz laser, 20 Hz odometry, both including t = 0.
  LONGS_EQUAL(static_cast<long>(s.steps / 10U + 1U), static_cast<long>(s.scan_count));
  LONGS_EQUAL(static_cast<long>(s.steps / 5U + 1U), static_cast<long>(s.odom_count));
}

TEST(SimRobot, run_out_of_time_is_reported_as_not_reaching_the_goal) {
  SimulationOptions o = test::cheap_laser_options();
  o.max_duration_s = 5.0;
  RecordingSink sink;
  const SimulationSummary s = drive(builtin_route(), &sink, o);
  CHECK_FALSE(s.reached_goal);
  DOUBLES_EQUAL(5.0, s.duration_s, 1e-9);
}

TEST(SimRobot, stamps_start_at_the_fixed_epoch_and_step_by_exactly_100_ms) {
  RecordingSink sink;
  SimulationOptions o = test::cheap_laser_options();
  o.max_duration_s = 1.0;
  drive(builtin_route(), &sink, o);
  CHECK(sink.scan_stamps_us.size() >= 10U);
  CHECK_EQUAL(1000000000LL * 1000000LL, sink.scan_stamps_us[0]);
  for (std::size_t i = 1; i < sink.scan_stamps_us.size(); ++i)
    CHECK_EQUAL(100000LL, sink.scan_stamps_us[i] - sink.scan_stamps_us[i - 1]);
}
