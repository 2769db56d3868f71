// MonteCarloLocalizer::update() never touches the heap: global start, KLD resizing,
// random particles and tracking all run in the arena carved at init.
#include <CppUTest/TestHarness.h>

#include <memory>

#include "alloc_counter.h"
#include "localizer_world.h"

using namespace sdpslam;

TEST_GROUP(LocalizerNoHeap){};

TEST(LocalizerNoHeap, updates_from_a_global_start_allocate_nothing) {
  test::LocalizerWorld world;
  const LocalizerMap m = world.map();
  LocalizerOptions o;
  o.max_particles = 3000U;
  const std::size_t n = MonteCarloLocalizer::required_arena_bytes(o, m);
  std::unique_ptr<unsigned char[]> buffer(new unsigned char[n]);
  Arena arena(buffer.get(), n);
  MonteCarloLocalizer mcl;
  char why[128];
  CHECK_TRUE_TEXT(mcl.init(o, m, arena, 3U, why, sizeof why), why);
  static RangeScan scan;
  const std::vector<Pose2> route = test::localizer_route();
  std::size_t allocations = 0U;
  {
    test::AllocationScope scope;
    mcl.start_global();
    allocations += scope.allocations();
  }
  for (std::size_t k = 0; k < route.size(); ++k) {
    world.scan(route[k], static_cast<std::int64_t>(k) * 100000, &scan);
    test::AllocationScope scope;
    (void)mcl.update(OdometrySample{static_cast<std::int64_t>(k) * 100000, route[k]}, scan);
    allocations += scope.allocations();
  }
  LONGS_EQUAL(0, allocations);
  CHECK(mcl.stats().filter_updates > 50U);
  CHECK(mcl.particle_count() < o.max_particles);  // KLD resized the set in place
}
