// SDP-SLAM never touches the heap after init: a run over many segments, with a full PGS
// whose oldest levels become permanent, under the allocation counter.
#include <CppUTest/TestHarness.h>

#include <cstring>
#include <vector>

#include "alloc_counter.h"
#include "sdp_harness.h"

using namespace sdpslam;

namespace {
class CountingSink final : public SdpPathSink {
 public:
  void on_pose(std::uint32_t, std::int64_t, const Pose2&) override { ++count; }
  void on_frame(std::uint32_t, const Pose2&) override { ++frames; }
  std::uint64_t count = 0;
  std::uint64_t frames = 0;
};
class CountingListener final : public TopLevelListener {
 public:
  void on_round(std::int64_t, double, double, std::uint32_t) override { ++count; }
  std::uint64_t count = 0;
};
}  // namespace

TEST_GROUP(SdpNoHeap){};

// init() builds its objects (bottom filter, ICP, segmenter, PGS) by placement new in the
// caller's arena: with the arena's buffer allocated beforehand, init itself allocates
// nothing either.
TEST(SdpNoHeap, init_builds_everything_in_the_arena) {
  CHECK_TRUE(sdpslam::test::allocation_counting_active());
  const DpSlamOptions b = test::sim_options(5);
  const SdpOptions s = test::small_sdp_options();
  std::vector<unsigned char> buffer(SdpSlam::required_arena_bytes(b, s), 0);
  Arena arena;
  auto slam = std::make_unique<SdpSlam>();
  {
    sdpslam::test::AllocationScope scope;
    arena.reset(buffer.data(), buffer.size());
    CHECK_TRUE(slam->init(b, s, arena, 9));
    LONGS_EQUAL(0, scope.allocations());
  }
}

namespace {
// Runs three loops with the allocation counter watching everything after init.
void run_without_heap(const SdpOptions& options, std::uint64_t seed = 9U) {
  CHECK_TRUE(sdpslam::test::allocation_counting_active());
  const test::ScanSet set(3);
  test::SdpRig rig;
  CHECK_TRUE(rig.init(test::sim_options(5), options, seed));
  CountingSink sink;
  CountingListener listener;
  rig.slam->set_permanent_sink(&sink);
  rig.slam->set_listener(&listener);
  double checksum = 0.0;
  {
    sdpslam::test::AllocationScope scope;
    for (std::size_t i = 0; i < set.scans.size(); ++i) {
      const SdpStepResult r = rig.slam->process(set.odom(i), *set.scans[i]);
      checksum += r.pose.x_m;
    }
    rig.slam->finish();
    rig.slam->for_each_best_pose([&](std::int64_t, const Pose2& p) { checksum += p.y_m; });
    LONGS_EQUAL(0, scope.allocations());
  }
  CHECK(checksum == checksum);
  CHECK(rig.slam->stats().segments > 8U);
  CHECK(rig.slam->stats().levels_made_permanent > 0U);
  CHECK(rig.slam->stats().evaluations > 0U);
  CHECK(sink.count > 0U);
  if (options.loop_closure) {
    CHECK(rig.slam->stats().loop_records_added > 0U);
    CHECK(rig.slam->stats().frame_adjustments > 0U);
    CHECK(sink.frames > rig.slam->stats().levels_made_permanent);  // frames moved
  }
  if (options.loop_search_window_m > 0.0) CHECK(rig.slam->stats().loop_searches > 0U);
}
}  // namespace

TEST(SdpNoHeap, many_segments_and_a_full_pgs_allocate_nothing_after_init) { run_without_heap(test::small_sdp_options()); }

// A DP map pool too small for every live level: segments end for the pool and levels
// become permanent early, released at once (SdpSlam::make_room).
TEST(SdpNoHeap, a_short_observation_pool_allocates_nothing_after_init) {
  SdpOptions s = test::small_sdp_options();
  s.map_observation_capacity = 110000U;
  run_without_heap(s);
}

// Loop closure: obstacle points, loop records, the frame graph's solves. The seed is one
// whose run records loops (checked: a run that closes none would prove nothing here);
// seed 9 closes none since new segments start from four scans.
TEST(SdpNoHeap, loop_closure_allocates_nothing_after_init) {
  SdpOptions s = test::small_sdp_options();
  s.loop_closure = true;
  run_without_heap(s, 8U);
}

// Wide loop search: the correlative matcher's grids and its searches.
TEST(SdpNoHeap, wide_loop_search_allocates_nothing_after_init) {
  SdpOptions s = test::small_sdp_options();
  s.loop_closure = true;
  s.loop_search_window_m = 3.0;
  run_without_heap(s);
}

namespace {
// Into and out of a buffer sized beforehand.
class FixedBuffer final : public StateWriter, public StateReader {
 public:
  explicit FixedBuffer(std::size_t bytes) : bytes_(bytes, 0) {}
  bool write(const void* data, std::size_t n) override {
    if (n > bytes_.size() - end_) return false;
    std::memcpy(bytes_.data() + end_, data, n);
    end_ += n;
    return true;
  }
  bool read(void* data, std::size_t n) override {
    if (n > end_ - at_) return false;
    std::memcpy(data, bytes_.data() + at_, n);
    at_ += n;
    return true;
  }
  std::vector<unsigned char> bytes_;
  std::size_t end_ = 0U;
  std::size_t at_ = 0U;
};
}  // namespace

// Snapshots: writing the state and reading it into another engine touch no heap either
// (the robot writes them while it maps).
TEST(SdpNoHeap, snapshots_allocate_nothing) {
  CHECK_TRUE(sdpslam::test::allocation_counting_active());
  SdpOptions s = test::small_sdp_options();
  s.loop_closure = true;
  s.loop_search_window_m = 3.0;
  const test::ScanSet set(1);
  test::SdpRig a;
  test::SdpRig b;
  CHECK_TRUE(a.init(test::sim_options(5), s, 8U));
  CHECK_TRUE(b.init(test::sim_options(5), s, 8U));
  for (std::size_t i = 0; i < set.scans.size() / 2U; ++i) a.slam->process(set.odom(i), *set.scans[i]);
  FixedBuffer buffer(static_cast<std::size_t>(a.slam->state_bytes()));
  {
    sdpslam::test::AllocationScope scope;
    CHECK_TRUE(a.slam->save_state(buffer));
    CHECK_TRUE(b.slam->load_state(buffer));
    for (std::size_t i = set.scans.size() / 2U; i < set.scans.size(); ++i) b.slam->process(set.odom(i), *set.scans[i]);
    LONGS_EQUAL(0, scope.allocations());
  }
  LONGS_EQUAL(buffer.end_, buffer.at_);
}
