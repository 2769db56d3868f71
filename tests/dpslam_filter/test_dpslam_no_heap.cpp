// The filter never touches the heap after init: hundreds of scans (processed and
// skipped, with resampling, pruning and commitment) under the allocation counter.
#include <CppUTest/TestHarness.h>

#include "alloc_counter.h"
#include "filter_harness.h"

using namespace sdpslam;

namespace {
class CountingSink final : public PoseSink {
 public:
  void on_committed(std::int64_t, const Pose2&) override { ++count; }
  std::uint64_t count = 0;
};
}  // namespace

TEST_GROUP(DpSlamNoHeap){};

namespace {
// loops: one lap of the loop is ~350 scans.
void run_without_heap(const DpSlamOptions& options, std::uint32_t loops) {
  CHECK_TRUE(sdpslam::test::allocation_counting_active());
  const test::SimRun run = test::make_loop(loops);
  const auto world = test::room_world();
  // Scans are generated before counting starts (the generator uses the heap, the filter
  // must not).
  std::vector<std::unique_ptr<RangeScan>> scans;
  for (std::size_t i = 0; i < run.truth.size(); ++i) {
    scans.push_back(std::make_unique<RangeScan>());
    test::make_scan(world, run.truth[i], static_cast<std::int64_t>(i) * 100000, scans.back().get());
  }
  test::FilterRig rig;
  CHECK_TRUE(rig.init(options, 9));
  CountingSink sink;
  rig.filter->set_pose_sink(&sink);
  std::size_t processed = 0;
  double checksum = 0.0;
  {
    sdpslam::test::AllocationScope scope;
    for (std::size_t i = 0; i < run.truth.size(); ++i) {
      OdometrySample od;
      od.stamp_us = scans[i]->stamp_us;
      od.pose = run.odom[i];
      const StepResult r = rig.filter->process(od, *scans[i]);
      processed += r.status == StepResult::Status::kProcessed ? 1U : 0U;
      checksum += r.pose.x_m;
      rig.filter->for_each_best_pose([&](std::int64_t, const Pose2& p) { checksum += p.y_m; });
    }
    LONGS_EQUAL(0, scope.allocations());
  }
  CHECK(run.truth.size() > 300U * loops);
  CHECK(processed > 100U * loops);
  CHECK(sink.count > 0U);
  CHECK(checksum == checksum);
  CHECK(rig.filter->stats().resamplings > 0U);
  if (options.proposal == DpSlamOptions::Proposal::kScanMatch) {
    CHECK(rig.filter->stats().proposal_matched > 0U);  // the matcher really ran
  }
}

}  // namespace

// Two laps, so the second revisits mapped space (closing the loop, merging, pruning).
TEST(DpSlamNoHeap, hundreds_of_scans_after_init_allocate_nothing) { run_without_heap(test::sim_options(20), 2U); }

// One lap with fewer particles: the scan matcher runs per particle and dominates the time
// (this suite also runs under qemu for the cross builds); its code paths are all taken
// within the first lap.
TEST(DpSlamNoHeap, improved_proposal_allocates_nothing_either) {
  DpSlamOptions o = test::sim_options(10);
  o.proposal = DpSlamOptions::Proposal::kScanMatch;
  run_without_heap(o, 1U);
}
