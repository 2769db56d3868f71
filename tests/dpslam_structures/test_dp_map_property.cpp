// The DP-Mapping property: for every current particle, its view of the shared map (own
// observations, then nearest ancestor's) equals a naive private copy of its map that is
// duplicated at every resampling, as a plain RBPF would (paper §II-A). Same for the
// trajectory: committed poses followed by the tree's remaining ones equal a naive
// per-particle path list.
#include <CppUTest/TestHarness.h>

#include <cstdint>
#include <map>
#include <vector>

#include "dp_fixture.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "test_rng.h"

using sdpslam::CellObservation;
using sdpslam::DpMap;
using sdpslam::kNoNode;
using sdpslam::NodeId;
using sdpslam::Pose2;
using sdpslam::test::DpFixture;
using sdpslam::test::small_options;
using sdpslam::test::SplitMix64;

namespace {

struct NaivePose {
  std::int64_t stamp_us;
  double x_m;
};

struct NaiveParticle {
  std::vector<std::uint8_t> known;
  std::vector<CellObservation> value;
  std::vector<NaivePose> path;
};

struct Committed final : sdpslam::PoseSink {
  std::vector<NaivePose> poses;
  void on_committed(std::int64_t stamp_us, const Pose2& p) override { poses.push_back({stamp_us, p.x_m}); }
};

struct Scenario {
  std::uint32_t particles;
  std::uint32_t generations;
  std::uint32_t updates_per_particle;
  std::uint32_t tile_capacity;
  std::uint32_t observation_capacity;
  std::uint64_t seed;
  bool owner_cell_index = true;
  bool views = false;  // each particle's updates and reads in a begin_view() .. end_view() run
};

DpMap::Options scenario_options(const Scenario& s) {
  DpMap::Options o = small_options(s.tile_capacity, s.observation_capacity);
  o.owner_cell_index = s.owner_cell_index;
  return o;
}

class PropertyRun {
 public:
  explicit PropertyRun(const Scenario& s)
      : s_(s), f_(3U * s.particles, 4096U, scenario_options(s)), rng_(s.seed) {
    w_ = f_.map.width_cells();
    h_ = f_.map.height_cells();
    cells_ = static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_);
  }

  void run() {
    const NodeId root = f_.tree.create_root();
    NaiveParticle& n0 = naive_[root];
    n0.known.assign(cells_, 0U);
    n0.value.assign(cells_, CellObservation{});
    current_.push_back(root);
    for (std::uint32_t g = 0; g < s_.generations; ++g) generation(g);
    check_everything();
  }

  std::uint32_t refused() const { return refused_; }
  const DpFixture& fixture() const { return f_; }

 private:
  void check_invariants() {
    CHECK_TRUE(f_.tree.invariants_hold());
    CHECK_TRUE(f_.map.invariants_hold());
  }

  // A random cell in a window that drifts across the map, so tiles fill, empty and
  // are reused, like a robot driving through an area.
  void random_cell(std::uint32_t g, std::int32_t* ix, std::int32_t* iy) {
    const std::int32_t cx = static_cast<std::int32_t>((g / 3U) % static_cast<std::uint32_t>(w_));
    const std::int32_t cy = static_cast<std::int32_t>((g / 7U) % static_cast<std::uint32_t>(h_));
    *ix = (cx + static_cast<std::int32_t>(rng_.below(12U)) - 6 + w_) % w_;
    *iy = (cy + static_cast<std::int32_t>(rng_.below(12U)) - 6 + h_) % h_;
  }

  void random_update(std::uint32_t g, NodeId p) {
    std::int32_t ix = 0;
    std::int32_t iy = 0;
    random_cell(g, &ix, &iy);
    NaiveParticle& n = naive_[p];
    const std::size_t i = static_cast<std::size_t>(iy) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(ix);
    if (rng_.below(2U) == 0U) {
      const CellObservation v{static_cast<std::uint16_t>(rng_.below(6U)), static_cast<std::uint16_t>(rng_.below(6U))};
      if (f_.map.update(p, ix, iy, v)) {
        n.known[i] = 1U;
        n.value[i] = v;
      } else {
        ++refused_;
      }
    } else {
      const std::uint16_t dh = static_cast<std::uint16_t>(rng_.below(3U) == 0U ? 40000U : rng_.below(3U));
      const std::uint16_t dm = static_cast<std::uint16_t>(rng_.below(3U));
      const CellObservation base = n.known[i] != 0U ? n.value[i] : CellObservation{};
      if (f_.map.add(p, ix, iy, dh, dm)) {
        n.known[i] = 1U;
        n.value[i] = sdpslam::accumulate(base, dh, dm);
      } else {
        ++refused_;
      }
    }
  }

  void generation(std::uint32_t g) {
    // Resampling with a skewed draw: some particles get several children, some none.
    std::vector<NodeId> next;
    const std::uint32_t favourites = 1U + rng_.below(static_cast<std::uint32_t>(current_.size()));
    const bool early_updates = rng_.below(3U) == 0U;
    for (std::uint32_t k = 0; k < s_.particles; ++k) {
      const std::uint32_t pick = rng_.below(4U) == 0U ? rng_.below(static_cast<std::uint32_t>(current_.size()))
                                                      : rng_.below(favourites);
      const NodeId parent = current_[pick];
      const NodeId c = f_.tree.add_child(parent);
      CHECK(c != kNoNode);
      naive_[c] = naive_[parent];  // the copy a plain RBPF would make
      next.push_back(c);
      if (early_updates) {  // children write before the prune
        begin_view(c);
        random_update(g, c);
        end_view();
      }
      check_invariants();
    }
    if (early_updates) compare_views(next);  // provisional labels answer correctly too
    for (NodeId p : current_) {
      f_.tree.set_active(p, false);
      naive_.erase(p);
    }
    f_.tree.prune(&f_.map);
    check_invariants();
    current_.swap(next);
    for (std::size_t k = 0; k < current_.size(); ++k) {
      const NodeId p = current_[k];
      const double x_m = static_cast<double>(g) + 0.001 * static_cast<double>(k);
      const std::int64_t stamp_us = static_cast<std::int64_t>(g) * 100000;
      CHECK_TRUE(f_.tree.append_pose(p, stamp_us, Pose2{x_m, 0.0, 0.0}));
      naive_[p].path.push_back({stamp_us, x_m});
      begin_view(p);
      for (std::uint32_t u = 0; u < s_.updates_per_particle; ++u) random_update(g, p);
      end_view();
    }
    check_invariants();
    f_.tree.drain_committed(committed_);
    check_invariants();
    CHECK(f_.tree.size() <= 2U * s_.particles - 1U);
    compare_views(current_);
    compare_paths();
  }

  void begin_view(NodeId p) {
    if (s_.views) f_.map.begin_view(p);
  }
  void end_view() {
    if (s_.views) f_.map.end_view();
  }

  void compare_views(const std::vector<NodeId>& particles) {
    for (NodeId p : particles) {
      const NaiveParticle& n = naive_[p];
      std::size_t i = 0U;
      begin_view(p);
      for (std::int32_t iy = 0; iy < h_; ++iy) {
        for (std::int32_t ix = 0; ix < w_; ++ix, ++i) {
          CellObservation v;
          const bool known = f_.map.lookup(p, ix, iy, &v);
          CHECK_EQUAL(n.known[i] != 0U, known);
          if (known && n.known[i] != 0U) CHECK_TRUE(v == n.value[i]);
        }
      }
      end_view();
    }
  }

  void compare_paths() {
    for (NodeId p : current_) {
      std::vector<NaivePose> got = committed_.poses;
      f_.tree.for_each_pose_from_root(p, [&](std::int64_t stamp_us, const Pose2& pose) {
        got.push_back({stamp_us, pose.x_m});
      });
      const std::vector<NaivePose>& want = naive_[p].path;
      LONGS_EQUAL(want.size(), got.size());
      for (std::size_t k = 0; k < want.size() && k < got.size(); ++k) {
        CHECK_EQUAL(want[k].stamp_us, got[k].stamp_us);
        CHECK_EQUAL(want[k].x_m, got[k].x_m);
      }
    }
  }

  void check_everything() {
    compare_views(current_);
    compare_paths();
    // for_each_known_cell reports exactly the known cells, with their values.
    for (NodeId p : current_) {
      const NaiveParticle& n = naive_[p];
      std::size_t known = 0U;
      for (std::uint8_t k : n.known) known += k;
      std::size_t seen = 0U;
      f_.map.for_each_known_cell(p, [&](std::int32_t ix, std::int32_t iy, const CellObservation& v) {
        const std::size_t i = static_cast<std::size_t>(iy) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(ix);
        CHECK_TRUE(n.known[i] != 0U && v == n.value[i]);
        ++seen;
      });
      LONGS_EQUAL(known, seen);
    }
    LONGS_EQUAL(0, f_.tree.node_oom_count());
    LONGS_EQUAL(0, f_.tree.path_oom_count());
    CHECK(f_.tree.committed_count() > 0U);
  }

  Scenario s_;
  DpFixture f_;
  SplitMix64 rng_;
  std::int32_t w_ = 0;
  std::int32_t h_ = 0;
  std::size_t cells_ = 0U;
  std::map<NodeId, NaiveParticle> naive_;
  std::vector<NodeId> current_;
  Committed committed_;
  std::uint32_t refused_ = 0U;
};

}  // namespace

TEST_GROUP(DpMapProperty){};

TEST(DpMapProperty, every_particle_view_equals_its_naive_map_copy_and_path) {
  PropertyRun run(Scenario{12U, 180U, 6U, 32U, 60000U, 11U});
  run.run();
  LONGS_EQUAL(0, run.refused());
  LONGS_EQUAL(0, run.fixture().map.observation_oom_count());
  LONGS_EQUAL(0, run.fixture().map.tile_oom_count());
  CHECK(run.fixture().map.tiles_peak() >= 2U);
}

// Without the (owner, cell) index every search is the cell-list scan: same views.
TEST(DpMapProperty, views_equal_the_naive_copies_without_the_owner_cell_index) {
  PropertyRun run(Scenario{12U, 180U, 6U, 32U, 60000U, 11U, false});
  run.run();
  LONGS_EQUAL(0, run.refused());
  CHECK(run.fixture().map.tiles_peak() >= 2U);
}

// A particle's updates and reads in a begin_view() run (what BeamModel::update_map and
// the scan-matching proposal do) walk the cell lists on per-owner marks: the same
// views, the first record of a particle too.
TEST(DpMapProperty, views_equal_the_naive_copies_when_updates_run_in_a_view) {
  Scenario s{12U, 180U, 6U, 32U, 60000U, 11U, false};  // without the index: views are used then
  s.views = true;
  PropertyRun run(s);
  run.run();
  LONGS_EQUAL(0, run.refused());
  CHECK(run.fixture().map.tiles_peak() >= 2U);
}

TEST(DpMapProperty, two_particles_long_run) {
  PropertyRun run(Scenario{2U, 800U, 3U, 32U, 60000U, 12U});
  run.run();
  LONGS_EQUAL(0, run.refused());
}

// Degraded path under random operations: with too few observations and tiles, updates
// are refused (the naive model skips exactly those), and every view still matches.
TEST(DpMapProperty, views_stay_exact_when_pools_run_out) {
  PropertyRun run(Scenario{10U, 150U, 8U, 2U, 150U, 13U});
  run.run();
  CHECK(run.refused() > 0U);
  CHECK(run.fixture().map.observation_oom_count() > 0U);
  CHECK(run.fixture().map.tile_oom_count() > 0U);
  LONGS_EQUAL(run.refused(), run.fixture().map.observation_oom_count() + run.fixture().map.tile_oom_count());
}
