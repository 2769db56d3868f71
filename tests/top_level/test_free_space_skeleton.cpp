// Points from the middle of free space (medial axis of an occupancy patch).
#include <CppUTest/TestHarness.h>

#include <cmath>
#include <cstring>

#include "sdpslam/core/arena.h"
#include "top/free_space_skeleton.h"
#include "top_level_fixtures.h"

using sdpslam::CellState;
using sdpslam::FreeSpaceSkeleton;
using sdpslam::GridPatchView;
using sdpslam::Point2;
using sdpslam::SkeletonOptions;
using sdpslam::SkeletonResult;
using sdpslam::test::fill;
using sdpslam::test::rect;

namespace {

constexpr std::uint32_t kMaxSide = 256U;
constexpr double kRes = 0.05;

FreeSpaceSkeleton& skeleton() {
  alignas(16) static unsigned char buffer[640U * 1024U];
  static sdpslam::Arena arena(buffer, sizeof buffer);
  static FreeSpaceSkeleton s;
  if (!s.initialised()) CHECK_TRUE(s.init(arena, kMaxSide, kMaxSide));
  return s;
}

CellState g_cells[kMaxSide * kMaxSide];
Point2 g_points[4096];

GridPatchView view(std::uint32_t w, std::uint32_t h, double ox = 0.0, double oy = 0.0) {
  GridPatchView v;
  v.width = w;
  v.height = h;
  v.resolution_m = kRes;
  v.origin_x_m = ox;
  v.origin_y_m = oy;
  v.cells = g_cells;
  return v;
}

// Cell index of a world coordinate along one axis of a patch with origin o.
int cell_of(double v_m, double o_m) { return static_cast<int>(std::floor((v_m - o_m) / kRes)); }

// 60 × 31 patch, unknown everywhere except a horizontal corridor of `free_rows` free rows
// starting at row 11, between occupied walls.
void horizontal_corridor(std::uint32_t free_rows) {
  fill(g_cells, 60U, 31U, CellState::kUnknown);
  rect(g_cells, 60U, 31U, 0, 10, 60, 11, CellState::kOccupied);
  rect(g_cells, 60U, 31U, 0, 11, 60, 11 + free_rows, CellState::kFree);
  rect(g_cells, 60U, 31U, 0, 11 + free_rows, 60, 12 + free_rows, CellState::kOccupied);
}

CellState classify_from_array(const void* context, std::uint32_t x, std::uint32_t y) {
  const auto* cells = static_cast<const CellState*>(context);
  return cells[static_cast<std::size_t>(y) * 60U + x];
}

}  // namespace

TEST_GROUP(FreeSpaceSkeleton){};

TEST(FreeSpaceSkeleton, straight_corridor_yields_its_centre_line) {
  horizontal_corridor(9U);  // rows 11..19: centre row 15
  const double ox = 1.0, oy = 2.0;
  const SkeletonResult r = skeleton().extract(view(60U, 31U, ox, oy), SkeletonOptions{}, g_points, 4096U);
  CHECK_TRUE(r.status == SkeletonResult::Status::kOk);
  CHECK(r.point_count >= 55U);
  double min_x = 1e9, max_x = -1e9;
  for (std::uint32_t i = 0; i < r.point_count; ++i) {
    DOUBLES_EQUAL(oy + 15.5 * kRes, g_points[i].y_m, kRes);
    min_x = std::fmin(min_x, g_points[i].x_m);
    max_x = std::fmax(max_x, g_points[i].x_m);
  }
  CHECK(min_x < ox + 3.0 * kRes);   // reaches both patch edges: the edge is a cut, not a wall
  CHECK(max_x > ox + 57.0 * kRes);
}

TEST(FreeSpaceSkeleton, even_width_corridor_stays_within_one_cell_of_the_centre_line) {
  horizontal_corridor(8U);  // rows 11..18: the centre line is the edge between rows 14 and 15
  const SkeletonResult r = skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 4096U);
  CHECK(r.point_count >= 55U);
  for (std::uint32_t i = 0; i < r.point_count; ++i) DOUBLES_EQUAL(15.0 * kRes, g_points[i].y_m, kRes);
}

TEST(FreeSpaceSkeleton, vertical_corridor_yields_its_centre_line) {
  fill(g_cells, 31U, 60U, CellState::kOccupied);
  rect(g_cells, 31U, 60U, 11, 0, 20, 60, CellState::kFree);  // columns 11..19: centre 15
  const SkeletonResult r = skeleton().extract(view(31U, 60U), SkeletonOptions{}, g_points, 4096U);
  CHECK(r.point_count >= 55U);
  for (std::uint32_t i = 0; i < r.point_count; ++i) DOUBLES_EQUAL(15.5 * kRes, g_points[i].x_m, kRes);
}

TEST(FreeSpaceSkeleton, l_corridor_yields_the_l_centre_line) {
  const std::uint32_t n = 80U;
  fill(g_cells, n, n, CellState::kUnknown);
  rect(g_cells, n, n, 10, 10, 70, 19, CellState::kFree);  // horizontal leg, centre row 14
  rect(g_cells, n, n, 10, 10, 19, 70, CellState::kFree);  // vertical leg, centre column 14
  const SkeletonResult r = skeleton().extract(view(n, n), SkeletonOptions{}, g_points, 4096U);
  CHECK_TRUE(r.status == SkeletonResult::Status::kOk);
  bool covered_h[n] = {};
  bool covered_v[n] = {};
  for (std::uint32_t i = 0; i < r.point_count; ++i) {
    const int cx = cell_of(g_points[i].x_m, 0.0);
    const int cy = cell_of(g_points[i].y_m, 0.0);
    // Outside the bend (where the axis curves around the inner corner) every point lies
    // on a leg's centre line.
    if (cx >= 28) {
      CHECK(std::abs(cy - 14) <= 1);
      covered_h[cx] = true;
    } else if (cy >= 28) {
      CHECK(std::abs(cx - 14) <= 1);
      covered_v[cy] = true;
    } else {
      CHECK(cx >= 10 && cy >= 10 && cx < 28 && cy < 28);  // inside the bend box
    }
  }
  for (std::uint32_t k = 30U; k < 64U; ++k) {
    CHECK_TEXT(covered_h[k], "horizontal leg centre line has a gap");
    CHECK_TEXT(covered_v[k], "vertical leg centre line has a gap");
  }
}

TEST(FreeSpaceSkeleton, unknown_patch_yields_no_points) {
  fill(g_cells, 40U, 40U, CellState::kUnknown);
  const SkeletonResult r = skeleton().extract(view(40U, 40U), SkeletonOptions{}, g_points, 4096U);
  CHECK_TRUE(r.status == SkeletonResult::Status::kOk);
  LONGS_EQUAL(0, r.point_count);
  LONGS_EQUAL(0, r.free_cell_count);
}

TEST(FreeSpaceSkeleton, free_patch_without_obstacles_yields_no_points_and_infinite_clearance) {
  fill(g_cells, 40U, 40U, CellState::kFree);
  const SkeletonResult r = skeleton().extract(view(40U, 40U), SkeletonOptions{}, g_points, 4096U);
  LONGS_EQUAL(0, r.point_count);
  LONGS_EQUAL(1600, r.free_cell_count);
  CHECK_TRUE(std::isinf(skeleton().clearance_m(20U, 20U)));
}

TEST(FreeSpaceSkeleton, patch_border_counts_as_wall_only_when_asked) {
  fill(g_cells, 81U, 21U, CellState::kFree);  // a free rectangle: axis on row 10
  SkeletonOptions o;
  o.patch_border_is_obstacle = true;
  const SkeletonResult walled = skeleton().extract(view(81U, 21U), o, g_points, 4096U);
  CHECK(walled.point_count >= 50U);
  for (std::uint32_t i = 0; i < walled.point_count; ++i) DOUBLES_EQUAL(10.5 * kRes, g_points[i].y_m, 1e-9);
  DOUBLES_EQUAL(11.0 * kRes, skeleton().clearance_m(40U, 10U), 1e-12);
  o.patch_border_is_obstacle = false;
  LONGS_EQUAL(0, skeleton().extract(view(81U, 21U), o, g_points, 4096U).point_count);
}

TEST(FreeSpaceSkeleton, clearance_is_the_euclidean_distance_to_the_nearest_obstacle) {
  horizontal_corridor(9U);
  (void)skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 4096U);
  DOUBLES_EQUAL(5.0 * kRes, skeleton().clearance_m(30U, 15U), 1e-12);
  DOUBLES_EQUAL(1.0 * kRes, skeleton().clearance_m(30U, 11U), 1e-12);
  DOUBLES_EQUAL(0.0, skeleton().clearance_m(30U, 10U), 0.0);
  DOUBLES_EQUAL(-1.0, skeleton().clearance_m(60U, 0U), 0.0);
  // A single obstacle: distances are exact Euclidean, not chamfer approximations.
  fill(g_cells, 60U, 31U, CellState::kFree);
  g_cells[0] = CellState::kOccupied;
  (void)skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 4096U);
  DOUBLES_EQUAL(std::sqrt(3.0 * 3.0 + 4.0 * 4.0) * kRes, skeleton().clearance_m(3U, 4U), 1e-12);
  DOUBLES_EQUAL(std::sqrt(59.0 * 59.0 + 30.0 * 30.0) * kRes, skeleton().clearance_m(59U, 30U), 1e-12);
}

TEST(FreeSpaceSkeleton, ridge_closer_than_min_clearance_is_dropped) {
  horizontal_corridor(9U);  // centre clearance 0.25 m
  SkeletonOptions o;
  o.min_clearance_m = 0.3;
  LONGS_EQUAL(0, skeleton().extract(view(60U, 31U), o, g_points, 4096U).point_count);
  o.min_clearance_m = 0.2;
  CHECK(skeleton().extract(view(60U, 31U), o, g_points, 4096U).point_count >= 55U);
}

TEST(FreeSpaceSkeleton, output_overflow_is_counted_and_truncated_never_overrun) {
  horizontal_corridor(9U);
  const Point2 sentinel{-123.0, 456.0};
  g_points[5] = sentinel;
  const std::uint32_t overflow_before = skeleton().overflow_count();
  const SkeletonResult r = skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 5U);
  CHECK_TRUE(r.status == SkeletonResult::Status::kOk);
  LONGS_EQUAL(5, r.point_count);
  CHECK(r.ridge_cell_count > 5U);
  LONGS_EQUAL(r.ridge_cell_count - 5U, r.truncated_count);
  LONGS_EQUAL(overflow_before + r.truncated_count, skeleton().overflow_count());
  DOUBLES_EQUAL(sentinel.x_m, g_points[5].x_m, 0.0);
  DOUBLES_EQUAL(sentinel.y_m, g_points[5].y_m, 0.0);
  // Count-only call.
  const SkeletonResult counted = skeleton().extract(view(60U, 31U), SkeletonOptions{}, nullptr, 0U);
  LONGS_EQUAL(r.ridge_cell_count, counted.ridge_cell_count);
}

TEST(FreeSpaceSkeleton, max_points_subsamples_by_a_fixed_stride) {
  horizontal_corridor(9U);
  const SkeletonResult all = skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 4096U);
  static Point2 every[4096];
  std::memcpy(every, g_points, all.point_count * sizeof(Point2));
  SkeletonOptions o;
  o.max_points = 10U;
  const SkeletonResult few = skeleton().extract(view(60U, 31U), o, g_points, 4096U);
  CHECK(few.point_count <= 10U);
  CHECK(few.point_count >= 9U);
  LONGS_EQUAL((all.ridge_cell_count + 9U) / 10U, few.stride);
  LONGS_EQUAL(0, few.truncated_count);
  for (std::uint32_t i = 0; i < few.point_count; ++i) {
    DOUBLES_EQUAL(every[i * few.stride].x_m, g_points[i].x_m, 0.0);
    DOUBLES_EQUAL(every[i * few.stride].y_m, g_points[i].y_m, 0.0);
  }
}

TEST(FreeSpaceSkeleton, callback_view_gives_the_same_points_as_array_view) {
  horizontal_corridor(9U);
  const SkeletonResult a = skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 4096U);
  static Point2 first[4096];
  std::memcpy(first, g_points, a.point_count * sizeof(Point2));
  GridPatchView v = view(60U, 31U);
  v.cells = nullptr;
  v.classify = classify_from_array;
  v.context = g_cells;
  const SkeletonResult b = skeleton().extract(v, SkeletonOptions{}, g_points, 4096U);
  LONGS_EQUAL(a.point_count, b.point_count);
  CHECK_EQUAL(0, std::memcmp(first, g_points, a.point_count * sizeof(Point2)));
}

TEST(FreeSpaceSkeleton, row_stride_selects_a_window_of_a_larger_grid) {
  // The corridor patch embedded at the left of a 100-wide grid.
  static CellState big[100U * 31U];
  horizontal_corridor(9U);
  for (std::size_t y = 0; y < 31U; ++y) {
    for (std::size_t x = 0; x < 100U; ++x) big[y * 100U + x] = x < 60U ? g_cells[y * 60U + x] : CellState::kOccupied;
  }
  const SkeletonResult a = skeleton().extract(view(60U, 31U), SkeletonOptions{}, g_points, 4096U);
  GridPatchView v = view(60U, 31U);
  v.cells = big;
  v.row_stride = 100U;
  const SkeletonResult b = skeleton().extract(v, SkeletonOptions{}, g_points, 4096U);
  LONGS_EQUAL(a.point_count, b.point_count);
}

TEST(FreeSpaceSkeleton, oversized_patch_and_bad_views_are_refused) {
  GridPatchView v = view(kMaxSide + 1U, 10U);
  CHECK_TRUE(skeleton().extract(v, SkeletonOptions{}, g_points, 10U).status == SkeletonResult::Status::kPatchTooLarge);
  v = view(0U, 10U);
  CHECK_TRUE(skeleton().extract(v, SkeletonOptions{}, g_points, 10U).status == SkeletonResult::Status::kInvalidPatch);
  v = view(10U, 10U);
  v.cells = nullptr;
  CHECK_TRUE(skeleton().extract(v, SkeletonOptions{}, g_points, 10U).status == SkeletonResult::Status::kInvalidPatch);
  v = view(10U, 10U);
  v.resolution_m = 0.0;
  CHECK_TRUE(skeleton().extract(v, SkeletonOptions{}, g_points, 10U).status == SkeletonResult::Status::kInvalidPatch);
  v = view(10U, 10U);
  CHECK_TRUE(skeleton().extract(v, SkeletonOptions{}, nullptr, 10U).status == SkeletonResult::Status::kInvalidPatch);
  SkeletonOptions o;
  o.max_points = 0U;
  CHECK_TRUE(skeleton().extract(view(10U, 10U), o, g_points, 10U).status == SkeletonResult::Status::kInvalidOptions);
}

TEST(FreeSpaceSkeleton, uninitialised_or_short_of_arena_is_refused) {
  FreeSpaceSkeleton fresh;
  CHECK_TRUE(fresh.extract(view(10U, 10U), SkeletonOptions{}, g_points, 10U).status ==
             SkeletonResult::Status::kNotInitialised);
  alignas(16) static unsigned char small[1024];
  sdpslam::Arena arena(small, sizeof small);
  CHECK_FALSE(fresh.init(arena, 64U, 64U));
  CHECK_FALSE(fresh.initialised());
  CHECK_FALSE(fresh.init(arena, 0U, 8U));
  CHECK_TRUE(fresh.init(arena, 8U, 8U));
  CHECK(arena.used_bytes() <= FreeSpaceSkeleton::required_bytes(8U, 8U));
  CHECK_FALSE(fresh.init(arena, 8U, 8U));  // once only
}
