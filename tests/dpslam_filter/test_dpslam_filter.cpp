// DpSlamFilter through its public API: options validation, arena sizing, the
// no-motion rule, accuracy on a synthetic loop, determinism, and exhaustion.
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "filter_harness.h"

using namespace sdpslam;
using sdpslam::test::FilterRig;

TEST_GROUP(DpSlamOptions){};

TEST(DpSlamOptions, defaults_are_valid) {
  char why[160];
  CHECK_TRUE(DpSlamOptions{}.validate(why, sizeof why));
  STRCMP_EQUAL("", why);
}

TEST(DpSlamOptions, too_many_particles_are_refused_naming_the_field_and_range) {
  DpSlamOptions o;
  o.particle_count = capacity::kMaxBottomParticles + 1U;
  char why[160];
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "filter.particles") != nullptr);
  CHECK(std::strstr(why, "out of range") != nullptr);
}

TEST(DpSlamOptions, zero_particles_and_nan_sigma_are_refused) {
  DpSlamOptions o;
  o.particle_count = 0;
  CHECK_FALSE(o.validate(nullptr, 0));
  o = DpSlamOptions{};
  o.beam.sigma_hit_m = std::nan("");
  char why[160];
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "observation.sigma_hit_m") != nullptr);
}

TEST(DpSlamOptions, window_narrower_than_a_cell_is_refused) {
  DpSlamOptions o;
  o.beam.window_m = 0.01;
  char why[160];
  CHECK_FALSE(o.validate(why, sizeof why));
  CHECK(std::strstr(why, "observation.window_m") != nullptr);
}

TEST_GROUP(DpSlamFilter){};

TEST(DpSlamFilter, invalid_options_give_zero_arena_bytes_and_init_fails_with_reason) {
  DpSlamOptions o;
  o.particle_count = 0;
  LONGS_EQUAL(0, DpSlamFilter::required_arena_bytes(o));
  FilterRig rig;
  unsigned char tiny[64];
  rig.arena.reset(tiny, sizeof tiny);
  CHECK_FALSE(rig.filter->init(o, rig.arena, 1));
  CHECK(std::strstr(rig.filter->why(), "filter.particles") != nullptr);
}

TEST(DpSlamFilter, too_small_arena_is_refused_with_the_sizes) {
  const DpSlamOptions o = test::sim_options(4);
  FilterRig rig;
  rig.buffer.assign(DpSlamFilter::required_arena_bytes(o) / 2U, 0);
  rig.arena.reset(rig.buffer.data(), rig.buffer.size());
  CHECK_FALSE(rig.filter->init(o, rig.arena, 1));
  CHECK(std::strstr(rig.filter->why(), "arena too small") != nullptr);
}

TEST(DpSlamFilter, process_before_init_reports_not_initialised) {
  FilterRig rig;
  OdometrySample od;
  CHECK(rig.filter->process(od, *rig.scan).status == StepResult::Status::kNotInitialised);
}

TEST(DpSlamFilter, small_motion_is_not_processed_and_gets_the_odometry_pose) {
  FilterRig rig;
  CHECK_TRUE(rig.init(test::sim_options(4), 3));
  const auto world = test::room_world();
  test::make_scan(world, Pose2{}, 0, rig.scan.get());
  OdometrySample od;
  od.pose = Pose2{10.0, 5.0, 1.0};  // arbitrary odometry frame
  CHECK(rig.filter->process(od, *rig.scan).status == StepResult::Status::kProcessed);
  od.pose = od.pose.compose(Pose2{0.05, 0.01, 0.02});
  const StepResult r = rig.filter->process(od, *rig.scan);
  CHECK(r.status == StepResult::Status::kSkippedNoMotion);
  DOUBLES_EQUAL(0.05, r.pose.x_m, 1e-12);
  DOUBLES_EQUAL(0.01, r.pose.y_m, 1e-12);
  DOUBLES_EQUAL(0.02, r.pose.heading_rad, 1e-12);
  LONGS_EQUAL(1, rig.filter->stats().processed);
  LONGS_EQUAL(2, rig.filter->stats().scans);
}

// A move odometry did not see (the robot carried while the program was off, then found
// in the map): every particle moves rigidly by it, the next scan is processed although
// the odometry shows no motion, and the lineage holds the step.
TEST(DpSlamFilter, a_displacement_moves_every_particle_rigidly_and_the_next_scan_is_processed) {
  FilterRig rig;
  CHECK_TRUE(rig.init(test::sim_options(4), 3));
  const auto world = test::room_world();
  const Pose2 delta{0.8, -0.3, 0.4};
  CHECK_FALSE(rig.filter->displace(delta));  // nothing processed yet
  test::make_scan(world, Pose2{}, 0, rig.scan.get());
  OdometrySample od;
  CHECK(rig.filter->process(od, *rig.scan).status == StepResult::Status::kProcessed);
  od.pose = Pose2{0.3, 0.0, 0.0};
  od.stamp_us = 100000;
  test::make_scan(world, od.pose, od.stamp_us, rig.scan.get());
  CHECK(rig.filter->process(od, *rig.scan).status == StepResult::Status::kProcessed);
  std::vector<Pose2> before;
  for (std::uint32_t i = 0; i < rig.filter->particle_count(); ++i) before.push_back(rig.filter->particle_pose(i));
  CHECK_FALSE(rig.filter->displace(Pose2{std::nan(""), 0.0, 0.0}));
  CHECK_TRUE(rig.filter->displace(delta));
  for (std::uint32_t i = 0; i < rig.filter->particle_count(); ++i) {
    const Pose2 want = before[i].compose(delta);
    const Pose2 got = rig.filter->particle_pose(i);
    CHECK(want.x_m == got.x_m && want.y_m == got.y_m && want.heading_rad == got.heading_rad);
  }
  // The same odometry again (no motion): processed, at the displaced place (the truth
  // there), not skipped.
  const Pose2 truth = od.pose.compose(delta);
  od.stamp_us = 200000;
  test::make_scan(world, truth, od.stamp_us, rig.scan.get());
  const StepResult r = rig.filter->process(od, *rig.scan);
  CHECK(r.status == StepResult::Status::kProcessed);
  CHECK(std::hypot(r.pose.x_m - truth.x_m, r.pose.y_m - truth.y_m) < 0.1);
  LONGS_EQUAL(3, rig.filter->stats().processed);
  // And only that one: the scan after it, still without motion, is skipped again.
  od.stamp_us = 300000;
  CHECK(rig.filter->process(od, *rig.scan).status == StepResult::Status::kSkippedNoMotion);
}

namespace {
std::vector<Pose2> run_loop(std::uint32_t particles, std::uint64_t seed, const test::SimRun& run,
                            DpSlamStats* stats = nullptr, DpSlamOptions* opts = nullptr) {
  const auto world = test::room_world();
  FilterRig rig;
  const DpSlamOptions o = opts != nullptr ? *opts : test::sim_options(particles);
  CHECK_TRUE(rig.init(o, seed));
  std::vector<Pose2> est;
  for (std::size_t i = 0; i < run.truth.size(); ++i) est.push_back(rig.step(run, world, i).pose);
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(rig.filter->map().invariants_hold());
  if (stats != nullptr) *stats = rig.filter->stats();
  return est;
}
}  // namespace

TEST(DpSlamFilter, recovers_the_true_loop_far_better_than_odometry) {
  const test::SimRun run = test::make_loop();
  std::vector<Pose2> odom_in_start;
  for (const Pose2& p : run.odom) odom_in_start.push_back(between(run.odom[0], p));
  const double odom_err = test::mean_error(odom_in_start, run.truth);
  DpSlamStats stats;
  const double slam_err = test::mean_error(run_loop(30, 1, run, &stats), run.truth);
  std::printf("\n  loop: odometry mean error %.3f m, filter %.3f m\n", odom_err, slam_err);
  CHECK(odom_err > 0.3);  // the odometry really is bad
  CHECK(slam_err < 0.15);
  CHECK(slam_err < odom_err / 4.0);
  CHECK(stats.processed > 50U);
  LONGS_EQUAL(0, stats.map_updates_dropped);
}

TEST(DpSlamFilter, same_seed_gives_bit_identical_trajectories) {
  const test::SimRun run = test::make_loop();
  const std::vector<Pose2> a = run_loop(10, 77, run);
  const std::vector<Pose2> b = run_loop(10, 77, run);
  LONGS_EQUAL(a.size(), b.size());
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(Pose2)) == 0);
}

TEST(DpSlamFilter, different_seed_gives_a_different_trajectory) {
  const test::SimRun run = test::make_loop();
  const std::vector<Pose2> a = run_loop(10, 77, run);
  const std::vector<Pose2> b = run_loop(10, 78, run);
  CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(Pose2)) != 0);
}

TEST(DpSlamFilter, tiny_capacities_degrade_counted_without_crash_or_corruption) {
  const test::SimRun run = test::make_loop();
  DpSlamOptions o = test::sim_options(12);
  o.ancestry_nodes_per_particle = 1;     // far below the 3 the tree needs
  o.path_entries_per_particle = 1;
  o.map_observations_base = 500;
  o.map_observations_per_particle = 100; // a fraction of one scan
  o.map_tile_capacity = 3;
  const auto world = test::room_world();
  FilterRig rig;
  CHECK_TRUE(rig.init(o, 5));
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    const StepResult r = rig.step(run, world, i);
    CHECK(std::isfinite(r.pose.x_m) && std::isfinite(r.pose.y_m) && std::isfinite(r.pose.heading_rad));
    if (i % 40 == 0) {
      CHECK_TRUE(rig.filter->tree().invariants_hold());
      CHECK_TRUE(rig.filter->map().invariants_hold());
    }
  }
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(rig.filter->map().invariants_hold());
  const DpSlamStats& s = rig.filter->stats();
  CHECK(s.processed > 50U);
  CHECK(s.map_updates_dropped > 0U);
  CHECK(s.node_fallback_count > 0U);
  CHECK(rig.filter->map().observation_oom_count() + rig.filter->map().tile_oom_count() > 0U);
  CHECK(rig.filter->tree().path_oom_count() > 0U);
  CHECK(rig.filter->map().observations_used() <= rig.filter->map().observation_capacity());
}

namespace {
// Records what the filter asks; frees nothing (a filter alone holds no anchored nodes).
class RecordingRoom final : public MapRoom {
 public:
  explicit RecordingRoom(const DpMap& map) : map_(map) {}
  void make_room(std::uint64_t observations) override {
    ++asked;
    need = observations;
    free_then = map_.observation_capacity() - map_.observations_used();
  }
  std::uint32_t asked = 0U;
  std::uint64_t need = 0U;
  std::uint64_t free_then = 0U;

 private:
  const DpMap& map_;
};
}  // namespace

// Before its map writes the filter asks its MapRoom for room exactly where the pool's
// free room may not hold them, and for no less than they take: a step that does not ask
// has nothing refused or shortened, and a step asks only with less room free than it asks
// for. What the writes take is measured on a twin run with an ample pool, identical step
// for step until the tight pool first shortens a write. With the pool ample it never
// asks. Where the room stays short (this one frees nothing), the step writes with a
// shortened update range, and what it writes fits: nothing is refused. A restart asks
// too, scan by scan.
TEST(DpSlamFilter, a_map_room_is_asked_before_writes_the_pool_may_not_hold_and_for_no_less) {
  const test::SimRun run = test::make_loop();
  const auto world = test::room_world();
  const auto options = [](std::uint32_t capacity) {
    DpSlamOptions o = test::sim_options(6);
    o.map_observations_per_particle = 1000U;
    o.map_observations_base = capacity - 6U * o.map_observations_per_particle;
    return o;
  };
  std::vector<std::uint64_t> takes;  // per step, on the ample pool
  {
    FilterRig rig;
    CHECK_TRUE(rig.init(options(400000U), 5));
    RecordingRoom room(rig.filter->map());
    rig.filter->set_map_room(&room);
    for (std::size_t i = 0; i < run.truth.size(); ++i) {
      const std::uint64_t before = rig.filter->map().observations_requested();
      rig.step(run, world, i);
      takes.push_back(rig.filter->map().observations_requested() - before);
    }
    LONGS_EQUAL(0, room.asked);
    LONGS_EQUAL(0, rig.filter->map().observation_oom_count());
    LONGS_EQUAL(0, rig.filter->stats().map_writes_shortened);
  }
  FilterRig rig;
  CHECK_TRUE(rig.init(options(40000U), 5));
  const DpMap& map = rig.filter->map();
  const DpSlamStats& stats = rig.filter->stats();
  RecordingRoom room(map);
  rig.filter->set_map_room(&room);
  std::uint32_t compared = 0U;
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    const std::uint32_t asked_before = room.asked;
    const std::uint64_t shortened_before = stats.map_writes_shortened;
    const std::uint64_t free_before = map.observation_capacity() - map.observations_used();
    const std::uint64_t requested_before = map.observations_requested();
    rig.step(run, world, i);
    CHECK(map.observations_requested() - requested_before <= free_before);  // the writes fit
    if (room.asked == asked_before) {
      LONGS_EQUAL(shortened_before, stats.map_writes_shortened);
    } else {
      CHECK(room.free_then < room.need);
      LONGS_EQUAL(shortened_before + 1U, stats.map_writes_shortened);  // this room frees nothing
      if (shortened_before == 0U) {
        CHECK(takes[i] <= room.need);
        ++compared;
      }
    }
  }
  CHECK(compared > 0U);
  LONGS_EQUAL(0, map.observation_oom_count());
  LONGS_EQUAL(0, stats.map_updates_dropped);
  LONGS_EQUAL(room.asked, stats.map_room_asked);
  LONGS_EQUAL(room.asked, stats.map_room_short);
  LONGS_EQUAL(room.asked, stats.map_writes_shortened);
  CHECK(stats.shortest_write_reach_m < rig.filter->options().beam.max_update_range_m);
  // A restart writes the last scans into the new root one by one, each asking for
  // itself: at least the newest, at most all of them (the newest and three before it).
  const std::uint32_t asked_before = room.asked;
  CHECK_TRUE(rig.filter->restart_segment(rig.filter->best_pose()));
  CHECK(room.asked > asked_before);
  CHECK(room.asked <= asked_before + 4U);
  LONGS_EQUAL(room.asked, stats.map_writes_shortened);
  LONGS_EQUAL(0, map.observation_oom_count());
  CHECK_TRUE(rig.filter->tree().invariants_hold());
  CHECK_TRUE(map.invariants_hold());
}

TEST(DpSlamFilter, best_path_ends_at_the_best_pose) {
  const test::SimRun run = test::make_loop();
  const auto world = test::room_world();
  FilterRig rig;
  CHECK_TRUE(rig.init(test::sim_options(8), 2));
  StepResult last;
  for (std::size_t i = 0; i < 120; ++i) {
    const StepResult r = rig.step(run, world, i);
    if (r.status == StepResult::Status::kProcessed) last = r;
  }
  Pose2 tail;
  std::int64_t stamp = -1;
  std::size_t count = 0;
  rig.filter->for_each_best_pose([&](std::int64_t s, const Pose2& p) {
    CHECK(s > stamp);
    stamp = s;
    tail = p;
    ++count;
  });
  CHECK(count > 0U);
  DOUBLES_EQUAL(last.pose.x_m, tail.x_m, 0.0);
  DOUBLES_EQUAL(last.pose.y_m, tail.y_m, 0.0);
}
