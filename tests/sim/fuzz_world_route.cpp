// libFuzzer: the simulator's world and route readers (sim::parse_world, sim::parse_route,
// the text of `sdpslam simulate --world FILE --route FILE`), both over the same input.
// Checks beyond the sanitizers: an accepted world has walls of coordinates within
// ±kMaxCoordinate_m and of finite, non-zero length, and its text (format_world) reads
// back to the identical doubles; an accepted route has at least two waypoints within
// ±kMaxCoordinate_m, consecutive ones distinct, and a finite length and start heading; a
// refusal names "fuzz.txt:N: reason" (N a line of the input) or "fuzz.txt: reason" and
// keeps what the lines before the bad one gave.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "sdpslam/sim/world.h"
#include "fuzz_text.h"

namespace {

using sdpslam::test::fuzz::check;
using sdpslam::test::fuzz::error_line;
using sdpslam::test::fuzz::first_lines;
using sdpslam::test::fuzz::line_count;

const char* const kName = "fuzz.txt";

// N of "fuzz.txt:N: ...", a line of the input; 0 for "fuzz.txt: ..." (a problem of the
// whole file). Any other message fails.
std::size_t refused_line(const std::string& text, const std::string& error) {
  check(error.compare(0, std::string(kName).size() + 1U, std::string(kName) + ":") == 0);
  if (error.compare(0, std::string(kName).size() + 2U, std::string(kName) + ": ") == 0) return 0;
  const std::size_t n = error_line(error, kName);
  check(n >= 1U && n <= line_count(text));
  return n;
}

bool finite(const sdpslam::sim::Point2& p) {
  return std::fabs(p.x_m) <= sdpslam::sim::kMaxCoordinate_m && std::fabs(p.y_m) <= sdpslam::sim::kMaxCoordinate_m;
}

void check_world(const sdpslam::sim::World& w) {
  for (const sdpslam::sim::Segment& s : w.segments) {
    check(finite(s.a) && finite(s.b));
    const double length = std::hypot(s.b.x_m - s.a.x_m, s.b.y_m - s.a.y_m);
    check(std::isfinite(length) && length > 0.0);
  }
}

void check_route(const sdpslam::sim::Route& r) {
  for (std::size_t i = 0; i < r.waypoints.size(); ++i) {
    check(finite(r.waypoints[i]));
    if (i > 0) {
      const sdpslam::sim::Point2& a = r.waypoints[i - 1];
      const sdpslam::sim::Point2& b = r.waypoints[i];
      const double leg = std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
      check(std::isfinite(leg) && leg > 0.0);
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);

  sdpslam::sim::World world;
  std::string error;
  if (sdpslam::sim::parse_world(text, kName, &world, &error)) {
    check(!world.segments.empty());
    check_world(world);
    sdpslam::sim::World back;
    std::string again;
    check(sdpslam::sim::parse_world(sdpslam::sim::format_world(world), kName, &back, &again));
    check(back.segments.size() == world.segments.size());
    for (std::size_t i = 0; i < back.segments.size(); ++i) {
      const sdpslam::sim::Segment& a = world.segments[i];
      const sdpslam::sim::Segment& b = back.segments[i];
      check(a.a.x_m == b.a.x_m && a.a.y_m == b.a.y_m && a.b.x_m == b.b.x_m && a.b.y_m == b.b.y_m);
    }
    check(!std::isnan(sdpslam::sim::distance_to_nearest_wall_m(world, 0.0, 0.0)));
  } else {
    check_world(world);
    const std::size_t n = refused_line(text, error);
    if (n > 0U) {
      sdpslam::sim::World before;
      std::string again;
      const bool ok = sdpslam::sim::parse_world(first_lines(text, n - 1U), kName, &before, &again);
      check(ok || refused_line(text, again) == 0U);
      check(before.segments.size() == world.segments.size());
    }
  }

  sdpslam::sim::Route route;
  error.clear();
  if (sdpslam::sim::parse_route(text, kName, &route, &error)) {
    check(route.waypoints.size() >= 2U);
    check_route(route);
    check(std::isfinite(sdpslam::sim::route_length_m(route)));
    check(std::isfinite(sdpslam::sim::route_start_heading_rad(route)));
  } else {
    check_route(route);
    const std::size_t n = refused_line(text, error);
    if (n > 0U) {
      sdpslam::sim::Route before;
      std::string again;
      const bool ok = sdpslam::sim::parse_route(first_lines(text, n - 1U), kName, &before, &again);
      check(ok || refused_line(text, again) == 0U);
      check(before.waypoints.size() == route.waypoints.size());
    }
  }
  return 0;
}
