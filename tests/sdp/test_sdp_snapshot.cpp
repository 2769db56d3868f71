// Snapshots (SdpSlam::save_state / load_state, core/state_io.h): an engine restored from
// a snapshot into another arena continues exactly as the one that wrote it, and a stream
// that does not belong to it is refused, naming why.
#include <CppUTest/TestHarness.h>

#include <cstring>
#include <string>
#include <vector>

#include "memory_state.h"
#include "sdp_harness.h"
#include "top/segment_graph.h"

using namespace sdpslam;
using sdpslam::test::MemoryReader;
using sdpslam::test::MemoryWriter;

namespace {

// The product's configuration on the test room: loop closure and the wide loop search on,
// so that every part of the engine holds state across scans.
SdpOptions snapshot_options() {
  SdpOptions s = test::small_sdp_options();
  s.loop_closure = true;
  s.loop_search_window_m = 4.0;
  s.loop_search_max_window_m = 8.0;
  return s;
}

// Everything a run shows the outside: each step's result, the permanent path (with the
// latest frame of each level) and, at the end, the best poses and the global map.
struct Outputs {
  std::vector<Pose2> step_poses;
  std::vector<std::uint32_t> step_kinds;  // status, segmentation, evaluations, work
  test::CollectPoses permanent;
  std::vector<Pose2> best;
  std::vector<double> cells;
  std::uint64_t evaluations = 0U;
  double error_sum_m = 0.0;
};

void step(test::SdpRig& rig, const test::ScanSet& set, std::size_t i, Outputs* out) {
  const SdpStepResult r = rig.slam->process(set.odom(i), *set.scans[i]);
  out->step_poses.push_back(r.pose);
  out->step_kinds.push_back(static_cast<std::uint32_t>(r.bottom.status));
  out->step_kinds.push_back(static_cast<std::uint32_t>(r.segmented));
  out->step_kinds.push_back(r.evaluations);
  out->step_kinds.push_back(r.work_cells);
}

void finish(test::SdpRig& rig, Outputs* out) {
  rig.slam->finish();
  rig.slam->for_each_best_pose([&](std::int64_t, const Pose2& p) { out->best.push_back(p); });
  rig.slam->for_each_permanent_cell([&](double x, double y, const CellObservation& c) {
    out->cells.push_back(x);
    out->cells.push_back(y);
    out->cells.push_back(static_cast<double>(c.hits));
    out->cells.push_back(static_cast<double>(c.misses));
  });
  out->evaluations = rig.slam->stats().evaluations;
  out->error_sum_m = rig.slam->stats().error_sum_m;
}

bool same_poses(const std::vector<Pose2>& a, const std::vector<Pose2>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(Pose2)) == 0);
}

}  // namespace

TEST_GROUP(SdpSnapshot){};

// The uninterrupted run against runs cut at several scans: the first engine writes a
// snapshot at the cut and is dropped, a second one (another arena, so every pointer
// differs) loads it and runs to the end. Bit for bit the same, whatever the cut: inside
// a segment, during a top-level round, with loops and permanent levels held.
TEST(SdpSnapshot, a_restored_engine_continues_bit_for_bit) {
  const test::ScanSet set(3);
  const DpSlamOptions b = test::sim_options(5);
  const SdpOptions s = snapshot_options();
  Outputs whole;
  {
    test::SdpRig rig;
    CHECK_TRUE(rig.init(b, s, 21));
    rig.slam->set_permanent_sink(&whole.permanent);
    for (std::size_t i = 0; i < set.scans.size(); ++i) step(rig, set, i, &whole);
    finish(rig, &whole);
  }
  CHECK(whole.evaluations > 0U);
  CHECK(whole.permanent.local.size() > 0U);

  const std::size_t n = set.scans.size();
  for (const std::size_t cut : {std::size_t{1}, n / 3U + 7U, (2U * n) / 3U + 1U, n - 2U}) {
    Outputs resumed;
    std::vector<unsigned char> snapshot;
    {
      test::SdpRig first;
      CHECK_TRUE(first.init(b, s, 21));
      first.slam->set_permanent_sink(&resumed.permanent);
      for (std::size_t i = 0; i < cut; ++i) step(first, set, i, &resumed);
      CHECK_TRUE(first.slam->bottom().map().invariants_hold());
      MemoryWriter w;
      CHECK_TRUE_TEXT(first.slam->save_state(w), first.slam->why());
      snapshot = w.bytes_;
      LONGS_EQUAL(snapshot.size(), first.slam->state_bytes());
    }
    test::SdpRig second;
    CHECK_TRUE(second.init(b, s, 999));  // the seed does not matter: the generator's state is restored
    MemoryReader r(snapshot);
    CHECK_TRUE_TEXT(second.slam->load_state(r), second.slam->why());
    LONGS_EQUAL(snapshot.size(), r.at_);
    CHECK_TRUE(second.slam->bottom().tree().invariants_hold());
    CHECK_TRUE(second.slam->bottom().map().invariants_hold());
    second.slam->set_permanent_sink(&resumed.permanent);
    for (std::size_t i = cut; i < n; ++i) step(second, set, i, &resumed);
    finish(second, &resumed);

    const std::string at = "cut at scan " + std::to_string(cut);
    CHECK_TRUE_TEXT(same_poses(whole.step_poses, resumed.step_poses), at.c_str());
    CHECK_TRUE_TEXT(whole.step_kinds == resumed.step_kinds, at.c_str());
    CHECK_TRUE_TEXT(same_poses(whole.permanent.local, resumed.permanent.local), at.c_str());
    CHECK_TRUE_TEXT(same_poses(whole.permanent.frames, resumed.permanent.frames), at.c_str());
    CHECK_TRUE_TEXT(whole.permanent.stamps == resumed.permanent.stamps, at.c_str());
    CHECK_TRUE_TEXT(same_poses(whole.best, resumed.best), at.c_str());
    CHECK_TRUE_TEXT(whole.cells == resumed.cells, at.c_str());
    LONGS_EQUAL_TEXT(whole.evaluations, resumed.evaluations, at.c_str());
    CHECK_TRUE_TEXT(whole.error_sum_m == resumed.error_sum_m, at.c_str());
    CHECK_TRUE(second.slam->bottom().tree().invariants_hold());
    CHECK_TRUE(second.slam->bottom().map().invariants_hold());
    CHECK_TRUE(second.slam->graph().invariants_hold());
  }
}

// Written, loaded elsewhere and written again: the same bytes.
TEST(SdpSnapshot, a_snapshot_round_trips_byte_for_byte) {
  const test::ScanSet set(1);
  test::SdpRig a;
  CHECK_TRUE(a.init(test::sim_options(5), snapshot_options(), 4));
  for (std::size_t i = 0; i < set.scans.size(); ++i) a.slam->process(set.odom(i), *set.scans[i]);
  MemoryWriter first;
  CHECK_TRUE(a.slam->save_state(first));
  test::SdpRig b;
  CHECK_TRUE(b.init(test::sim_options(5), snapshot_options(), 4));
  MemoryReader r(first.bytes_);
  CHECK_TRUE_TEXT(b.slam->load_state(r), b.slam->why());
  MemoryWriter second;
  CHECK_TRUE(b.slam->save_state(second));
  CHECK_TRUE(first.bytes_ == second.bytes_);
}

// What is not this engine's is refused before anything is written, and says why; a
// stream cut short is refused too, and the engine is then out of use.
TEST(SdpSnapshot, a_foreign_or_truncated_stream_is_refused) {
  const test::ScanSet set(1);
  test::SdpRig a;
  CHECK_TRUE(a.init(test::sim_options(5), snapshot_options(), 4));
  for (std::size_t i = 0; i < 60U; ++i) a.slam->process(set.odom(i), *set.scans[i]);
  MemoryWriter w;
  CHECK_TRUE(a.slam->save_state(w));

  {  // other options: another arena layout
    SdpOptions other = snapshot_options();
    other.top_particles = 13U;
    test::SdpRig b;
    CHECK_TRUE(b.init(test::sim_options(5), other, 4));
    MemoryReader r(w.bytes_);
    CHECK_FALSE(b.slam->load_state(r));
    STRCMP_CONTAINS("arena layout differs", b.slam->why());
    // Only the header was read.
    CHECK(r.at_ < 256U);
  }
  {  // not a snapshot at all
    std::vector<unsigned char> junk(w.bytes_.size(), 0x5A);
    test::SdpRig b;
    CHECK_TRUE(b.init(test::sim_options(5), snapshot_options(), 4));
    MemoryReader r(junk);
    CHECK_FALSE(b.slam->load_state(r));
    STRCMP_CONTAINS("(part missing): sdpslam state", b.slam->why());
  }
  {  // cut short: refused, and the engine does nothing more
    std::vector<unsigned char> cut(w.bytes_.begin(), w.bytes_.begin() + static_cast<std::ptrdiff_t>(w.bytes_.size() / 2U));
    test::SdpRig b;
    CHECK_TRUE(b.init(test::sim_options(5), snapshot_options(), 4));
    MemoryReader r(cut);
    CHECK_FALSE(b.slam->load_state(r));
    STRCMP_CONTAINS("stream ends early", b.slam->why());
    const SdpStepResult step = b.slam->process(set.odom(60), *set.scans[60]);
    CHECK(step.bottom.status == StepResult::Status::kNotInitialised);
  }
}
