// Micro-benchmark of the DP-Mapping hot path: lookups and updates per second for a
// DP-SLAM-sized population (400 particles, paper §IV), with resampling and prune/merge
// between steps as the filter does them. A plain program (not a test); build it in a
// Release directory:
//   cmake -S . -B build/rel -G Ninja -DCMAKE_BUILD_TYPE=Release
//   cmake --build build/rel --target bench_dp_map && build/rel/tests/dpslam_structures/bench_dp_map
// Arguments: [particles=400] [steps=60] [cells_per_particle_per_step=300] [seed=1]
//            [half_window_cells=120] (the area a scan touches around the robot)
#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "sdpslam/core/bottom/ancestry_tree.h"
#include "sdpslam/core/bottom/dp_map.h"
#include "test_rng.h"

namespace {

// Process CPU time, not wall time: the figures stay meaningful on a shared machine.
struct Clock {
  using time_point = std::clock_t;
  static time_point now() { return std::clock(); }
};

double seconds_since(Clock::time_point t0) {
  return static_cast<double>(std::clock() - t0) / static_cast<double>(CLOCKS_PER_SEC);
}

struct NullSink final : sdpslam::PoseSink {
  std::uint64_t count = 0U;
  void on_committed(std::int64_t, const sdpslam::Pose2&) override { ++count; }
};

}  // namespace

int main(int argc, char** argv) {
  const std::uint32_t n = argc > 1 ? static_cast<std::uint32_t>(std::strtoul(argv[1], nullptr, 10)) : 400U;
  const std::uint32_t steps = argc > 2 ? static_cast<std::uint32_t>(std::strtoul(argv[2], nullptr, 10)) : 60U;
  const std::uint32_t cells = argc > 3 ? static_cast<std::uint32_t>(std::strtoul(argv[3], nullptr, 10)) : 300U;
  const std::uint64_t seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1U;
  const std::int32_t window = argc > 5 ? static_cast<std::int32_t>(std::strtol(argv[5], nullptr, 10)) : 120;
  if (n < 2U || n > 4096U || steps < 1U || cells < 1U || window < 1 || window > 500) {
    std::fprintf(stderr,
                 "usage: bench_dp_map [particles 2..4096] [steps] [cells_per_particle_per_step] [seed] "
                 "[half_window_cells 1..500]\n");
    return 2;
  }

  sdpslam::DpMap::Options o;
  o.origin_x_m = -50.0;
  o.origin_y_m = -50.0;
  o.width_m = 100.0;
  o.height_m = 100.0;
  o.resolution_m = 0.05;
  o.tile_capacity = 8000U;
  o.observation_capacity = 4000000U;
  const std::uint32_t nodes = sdpslam::capacity::kAncestryNodesPerParticle * n;
  const std::uint32_t path_entries = 64U * n;
  std::vector<unsigned char> buffer(sdpslam::AncestryTree::required_arena_bytes(nodes, path_entries) +
                                    sdpslam::DpMap::required_arena_bytes(o, nodes));
  sdpslam::Arena arena(buffer.data(), buffer.size());
  sdpslam::AncestryTree tree;
  sdpslam::DpMap map;
  if (!tree.init(arena, nodes, path_entries) || !map.init(arena, o, tree)) {
    std::fprintf(stderr, "init failed\n");
    return 1;
  }

  sdpslam::test::SplitMix64 rng(seed);
  std::vector<sdpslam::NodeId> current{tree.create_root()};
  std::vector<sdpslam::NodeId> next(n);
  NullSink sink;
  double t_update = 0.0, t_lookup = 0.0, t_prune = 0.0;
  std::uint64_t n_update = 0U, n_lookup = 0U, n_known = 0U, n_prune = 0U;
  const std::uint32_t warmup = steps / 4U;

  for (std::uint32_t s = 0; s < steps; ++s) {
    const bool measure = s >= warmup;
    // Resampling: half of the draws from the best 10 % (a peaked posterior).
    const std::uint32_t m = static_cast<std::uint32_t>(current.size());
    for (std::uint32_t k = 0; k < n; ++k) {
      const std::uint32_t pick = rng.below(2U) == 0U ? rng.below(m / 10U + 1U) : rng.below(m);
      next[k] = tree.add_child(current[pick]);
    }
    for (sdpslam::NodeId p : current) tree.set_active(p, false);
    auto t0 = Clock::now();
    tree.prune(&map);
    if (measure) {
      t_prune += seconds_since(t0);
      ++n_prune;
    }
    current = next;
    tree.drain_committed(sink);

    // Robot drives 0.1 m (2 cells) per step along x; each particle writes its scan.
    const std::int32_t cx = 1000 - 800 + static_cast<std::int32_t>(2U * s);
    const std::int32_t cy = 1000;
    t0 = Clock::now();
    for (std::uint32_t k = 0; k < n; ++k) {
      tree.append_pose(current[k], static_cast<std::int64_t>(s) * 100000, sdpslam::Pose2{});
      for (std::uint32_t c = 0; c < cells; ++c) {
        const std::int32_t ix = cx + static_cast<std::int32_t>(rng.below(static_cast<std::uint32_t>(2 * window))) - window;
        const std::int32_t iy = cy + static_cast<std::int32_t>(rng.below(static_cast<std::uint32_t>(2 * window))) - window;
        map.add(current[k], ix, iy, 1U, 0U);
      }
    }
    if (measure) {
      t_update += seconds_since(t0);
      n_update += static_cast<std::uint64_t>(n) * cells;
    }

    // Weighting: every particle reads its map where its next scan would land.
    t0 = Clock::now();
    sdpslam::CellObservation v;
    for (std::uint32_t k = 0; k < n; ++k) {
      for (std::uint32_t c = 0; c < 4U * cells; ++c) {
        const std::int32_t ix = cx + 2 + static_cast<std::int32_t>(rng.below(static_cast<std::uint32_t>(2 * window))) - window;
        const std::int32_t iy = cy + static_cast<std::int32_t>(rng.below(static_cast<std::uint32_t>(2 * window))) - window;
        n_known += map.lookup(current[k], ix, iy, &v) ? 1U : 0U;
      }
    }
    if (measure) {
      t_lookup += seconds_since(t0);
      n_lookup += static_cast<std::uint64_t>(n) * 4U * cells;
    }
  }

  std::uint64_t entries = 0U, lists = 0U;
  const std::int32_t cx = 1000 - 800 + static_cast<std::int32_t>(2U * (steps - 1U));
  for (std::int32_t iy = 1000 - window; iy < 1000 + window; ++iy) {
    for (std::int32_t ix = cx - window; ix < cx + window; ++ix) {
      const std::uint32_t e = map.entries_in_cell(ix, iy);
      entries += e;
      lists += e > 0U ? 1U : 0U;
    }
  }
  std::printf("particles %u, steps %u (%u measured), cells/particle/step %u, window +-%d cells\n", n, steps,
              steps - warmup, cells, window);
  std::printf("(rates per second of process CPU time)\n");
  std::printf("lookups/s        %.3g  (%llu lookups, %.1f %% known)\n", static_cast<double>(n_lookup) / t_lookup,
              static_cast<unsigned long long>(n_lookup),
              100.0 * static_cast<double>(n_known) / static_cast<double>(n_lookup + (n_lookup == 0U)));
  std::printf("updates/s (add)  %.3g  (%llu lookup+update pairs)\n", static_cast<double>(n_update) / t_update,
              static_cast<unsigned long long>(n_update));
  std::printf("prune+merge      %.1f us CPU/step\n", 1e6 * t_prune / static_cast<double>(n_prune));
  std::printf("tree nodes %u (peak %u of %u), observations %u (peak %u), tiles %u (peak %u)\n", tree.size(),
              tree.peak_used(), tree.capacity(), map.observations_used(), map.observations_peak(), map.tiles_used(),
              map.tiles_peak());
  std::printf("mean list length in the scan window %.2f, committed poses %llu, footprint %.1f MiB\n",
              lists > 0U ? static_cast<double>(entries) / static_cast<double>(lists) : 0.0,
              static_cast<unsigned long long>(sink.count),
              static_cast<double>(map.footprint_bytes() + tree.footprint_bytes()) / (1024.0 * 1024.0));
  std::printf("oom: nodes %u, paths %u, tiles %llu, observations %llu\n", tree.node_oom_count(), tree.path_oom_count(),
              static_cast<unsigned long long>(map.tile_oom_count()), static_cast<unsigned long long>(map.observation_oom_count()));
  return 0;
}
