// libFuzzer target for the top-level building blocks. The first byte picks one of:
//   0: free-space skeleton of a grid patch decoded from the bytes (size, flags, cells);
//   1: ICP between two point sets decoded from the bytes (int16 pairs, 1 cm units);
//   2: a sequence of Probabilistic Graph of Segments operations decoded from the bytes.
// Any out-of-contract result (point outside the patch, count beyond capacity, broken PGS
// invariant, probability outside [0, 1]) traps, so the fuzzer reports it.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "sdpslam/core/arena.h"
#include "top/free_space_skeleton.h"
#include "sdpslam/core/top/icp2d.h"
#include "top/segment_graph.h"

namespace {

using namespace sdpslam;

constexpr std::uint32_t kSide = 64U;

void require(bool ok) {
  if (!ok) __builtin_trap();
}

struct Reader {
  const std::uint8_t* data;
  std::size_t size;
  std::size_t at = 0U;
  std::uint8_t byte() { return at < size ? data[at++] : 0U; }
  std::int16_t i16() {
    const auto lo = static_cast<std::uint16_t>(byte());
    const auto hi = static_cast<std::uint16_t>(byte());
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(lo | (hi << 8U)));
  }
  bool empty() const { return at >= size; }
};

void fuzz_skeleton(Reader& in) {
  alignas(16) static unsigned char buffer[128U * 1024U];
  static Arena arena(buffer, sizeof buffer);
  static FreeSpaceSkeleton skeleton;
  static bool ready = skeleton.init(arena, kSide, kSide);
  require(ready);
  static CellState cells[kSide * kSide];
  static Point2 out[96];
  GridPatchView view;
  view.width = 1U + in.byte() % kSide;
  view.height = 1U + in.byte() % kSide;
  const std::uint8_t flags = in.byte();
  view.resolution_m = 0.01 * (1 + in.byte() % 20);
  view.origin_x_m = 0.1 * static_cast<double>(in.i16());
  view.origin_y_m = 0.1 * static_cast<double>(in.i16());
  SkeletonOptions options;
  options.unknown_is_obstacle = (flags & 1U) != 0U;
  options.patch_border_is_obstacle = (flags & 2U) != 0U;
  options.min_clearance_m = 0.01 * static_cast<double>((flags >> 2U) & 7U);
  options.max_points = 1U + in.byte() % 90U;
  const std::size_t capacity = in.byte() % 97U;
  for (std::uint32_t i = 0; i < view.width * view.height; ++i) {
    cells[i] = static_cast<CellState>(in.byte() % 3U);
  }
  view.cells = cells;
  const SkeletonResult r = skeleton.extract(view, options, capacity > 0U ? out : nullptr, capacity);
  require(r.status == SkeletonResult::Status::kOk);
  require(r.point_count <= capacity);
  require(r.point_count <= options.max_points);
  require(r.ridge_cell_count <= r.free_cell_count);
  const double w_m = view.width * view.resolution_m;
  const double h_m = view.height * view.resolution_m;
  for (std::uint32_t i = 0; i < r.point_count; ++i) {
    require(out[i].x_m > view.origin_x_m && out[i].x_m < view.origin_x_m + w_m);
    require(out[i].y_m > view.origin_y_m && out[i].y_m < view.origin_y_m + h_m);
  }
}

void fuzz_icp(Reader& in) {
  static Icp2d icp;
  static Point2 target[256];
  static Point2 source[256];
  const std::uint8_t flags = in.byte();
  Icp2dOptions options;
  options.max_correspondence_m = 0.05 * (1 + in.byte() % 40);
  options.nn_cell_m = 0.01 * (1 + in.byte() % 50);
  options.min_correspondence_m = options.max_correspondence_m * 0.25;
  options.shrink_factor = (flags & 1U) != 0U ? 0.8 : 1.0;
  options.max_iterations = 1U + in.byte() % 30U;
  options.min_pairs = 2U + in.byte() % 8U;
  const Pose2 guess{0.01 * in.i16(), 0.01 * in.i16(), 0.001 * in.i16()};
  const std::size_t nt = in.byte() % 256U;
  const std::size_t ns = in.byte() % 256U;
  for (std::size_t i = 0; i < nt; ++i) target[i] = Point2{0.01 * in.i16(), 0.01 * in.i16()};
  for (std::size_t i = 0; i < ns; ++i) source[i] = Point2{0.01 * in.i16(), 0.01 * in.i16()};
  const Icp2dResult r = icp.match(target, nt, source, ns, guess, options);
  require(r.matched_pairs <= ns);
  if (r.usable()) {
    require(r.matched_pairs >= options.min_pairs);
    require(r.mean_nn_error_m >= 0.0 && r.mean_nn_error_m <= options.max_correspondence_m);
    require(r.rms_nn_error_m >= 0.0 && r.rms_nn_error_m <= options.max_correspondence_m);
  } else {
    require(!r.converged);
  }
  // Direction information of the pairing found (or of the guess): trace 1, positive
  // semi-definite, counts within bounds, whatever the points.
  const double radius_m = 0.02 * (1 + (flags >> 1U) % 32U);
  sdpslam::Icp2dInformation m;
  if (icp.direction_information(target, nt, source, ns, r.transform, options, radius_m, &m)) {
    require(m.pairs >= 1U && m.pairs <= ns && m.line_pairs <= m.pairs);
    require(m.xx >= -1e-12 && m.yy >= -1e-12 && m.xx * m.yy - m.xy * m.xy >= -1e-12);
    require(m.xx + m.yy > 1.0 - 1e-9 && m.xx + m.yy < 1.0 + 1e-9);
  }
}

void fuzz_graph(Reader& in) {
  alignas(16) static unsigned char buffer[64U * 1024U];
  Arena arena(buffer, sizeof buffer);
  SegmentGraphOptions options;
  options.max_levels = 2U + in.byte() % 6U;
  options.nodes_per_level = 1U + in.byte() % 10U;
  options.accumulation = (in.byte() & 1U) != 0U ? PgsAccumulation::kMean : PgsAccumulation::kSum;
  SegmentGraph g;
  require(g.init(options, arena));
  PgsNodeInput nodes[12];
  std::uint32_t chain[8];
  Pose2 frames[8];
  while (!in.empty()) {
    const std::uint8_t op = in.byte();
    const std::uint32_t level = g.first_live_level() + in.byte() % 8U;
    const std::uint32_t a = in.byte() % 12U;
    const std::uint32_t b = in.byte() % 12U;
    const double u = in.byte() / 256.0;
    switch (op % 8U) {
      case 0: {
        for (std::uint32_t i = 0; i < 12U; ++i) nodes[i].final_pose = Pose2{0.1 * a, 0.1 * b, u};
        (void)g.add_level(nodes, a);
        break;
      }
      case 1: (void)g.record_error(level, a, b, u * 4.0); break;
      case 2: {
        const double p = g.pair_probability(level, a, b);
        require(p < 0.0 || (p >= 0.0 && p <= 1.0));
        break;
      }
      case 3: {
        const PgsPick pick = g.sample_next(level, a, u);
        require(pick.status != PgsStatus::kOk || pick.node < g.node_count(level + 1U));
        break;
      }
      case 4: {
        const PgsPick pick = g.sample_previous(level, a, u);
        require(pick.status != PgsStatus::kOk || pick.node < g.node_count(level - 1U));
        break;
      }
      case 5: {
        const PgsPairPick pick = g.sample_pair(level, u);
        require(pick.status != PgsStatus::kOk ||
                (pick.node_a < g.node_count(level) && pick.node_b < g.node_count(level + 1U)));
        break;
      }
      case 6: (void)g.make_oldest_permanent(a); break;
      default: {
        const std::uint32_t count = g.levels_used() < 8U ? g.levels_used() : 8U;
        for (std::uint32_t k = 0; k < count; ++k) chain[k] = (a + k) % 12U;
        if (count >= 2U) (void)g.record_chain_error(g.first_live_level(), chain, count, u);
        if (count >= 1U) (void)g.compose_chain(chain, count, frames);
        break;
      }
    }
    require(g.invariants_hold());
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1U) return 0;
  Reader in{data + 1, size - 1U};
  switch (data[0] % 3U) {
    case 0: fuzz_skeleton(in); break;
    case 1: fuzz_icp(in); break;
    default: fuzz_graph(in); break;
  }
  return 0;
}
