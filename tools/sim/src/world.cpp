#include "sdpslam/sim/world.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "wall_builder.h"

namespace sdpslam::sim {
namespace {

using detail::WallBuilder;

// Strips a trailing comment and splits into numbers. Returns false with `reason` iff a
// token is not a finite number within ±kMaxCoordinate_m.
bool split_numbers(const std::string& line, std::vector<double>* out, std::string* reason) {
  out->clear();
  const std::string body = line.substr(0, line.find('#'));
  std::istringstream in(body);
  std::string token;
  while (in >> token) {
    double v = 0.0;
    const char* first = token.data();
    const char* last = token.data() + token.size();
    if (*first == '+') ++first;  // from_chars does not accept a leading '+'
    const auto res = std::from_chars(first, last, v);
    if (res.ec != std::errc() || res.ptr != last || !std::isfinite(v)) {
      *reason = "'" + token + "' is not a finite number";
      return false;
    }
    if (std::fabs(v) > kMaxCoordinate_m) {
      *reason = "'" + token + "' lies beyond the largest coordinate, 1e6 m";
      return false;
    }
    out->push_back(v);
  }
  return true;
}

bool read_text_file(const std::string& path, std::string* text, std::string* error) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *error = path + ": cannot open for reading";
    return false;
  }
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) {
    *error = path + ": read failed";
    return false;
  }
  *text = ss.str();
  return true;
}

void append_shortest(std::string* out, double v) {
  char buf[32];
  const auto res = std::to_chars(buf, buf + sizeof buf, v);
  out->append(buf, res.ptr);
}

}  // namespace

World builtin_world() {
  World w;
  WallBuilder b(&w);
  // Outer boundary (free side inside), 0.9 m outside the outer centre-line rectangle.
  b.wall({-0.9, -0.9}, {24.9, -0.9}, 0.0, -1.0,
         {{2.0, 1.2, 0.6}, {11.9, 1.5, 1.5}, {17.9, 0.3, -0.15}, {21.9, 0.3, -0.15}});
  b.wall({24.9, -0.9}, {24.9, 16.9}, 1.0, 0.0, {{5.9, 1.0, 0.8}, {11.4, 0.3, -0.15}});
  b.wall({24.9, 16.9}, {-0.9, 16.9}, 0.0, 1.0, {{4.0, 2.0, 1.2}, {12.0, 0.3, -0.15}, {18.0, 1.0, 0.6}});
  b.wall({-0.9, 16.9}, {-0.9, -0.9}, -1.0, 0.0, {{4.0, 1.2, 0.7}, {13.5, 1.0, 0.5}});
  // Block inside the inner loop: [0.9, 7.1] x [0.9, 5.1].
  b.wall({0.9, 0.9}, {7.1, 0.9}, 0.0, 1.0, {{3.0, 0.3, -0.15}});
  b.wall({7.1, 0.9}, {7.1, 5.1}, -1.0, 0.0, {{1.5, 1.0, 0.6}});
  b.wall({7.1, 5.1}, {0.9, 5.1}, 0.0, -1.0, {{2.0, 0.3, -0.15}});
  b.wall({0.9, 5.1}, {0.9, 0.9}, 1.0, 0.0, {});
  // L-shaped block between the inner loop and the outer loop.
  b.wall({8.9, 0.9}, {23.1, 0.9}, 0.0, 1.0, {{3.0, 0.3, -0.15}, {6.5, 1.4, 0.9}, {10.5, 0.3, -0.15}});
  b.wall({23.1, 0.9}, {23.1, 15.1}, -1.0, 0.0, {{3.5, 0.3, -0.15}, {8.0, 1.2, 0.7}});
  b.wall({23.1, 15.1}, {0.9, 15.1}, 0.0, -1.0,
         {{3.0, 0.3, -0.15}, {9.0, 1.5, 1.0}, {15.0, 0.3, -0.15}, {19.0, 1.0, 0.6}});
  b.wall({0.9, 15.1}, {0.9, 6.9}, 1.0, 0.0, {{3.0, 1.0, 0.7}});
  b.wall({0.9, 6.9}, {8.9, 6.9}, 0.0, 1.0, {{4.0, 0.3, -0.15}});
  b.wall({8.9, 6.9}, {8.9, 0.9}, 1.0, 0.0, {{2.5, 0.8, 0.5}});
  // A pillar inside the side room off the south corridor (x 11.0..12.5, y -2.4..-0.9).
  b.pillar(11.75, -1.9, 0.15);
  return w;
}

Route builtin_route() {
  Route r;
  r.waypoints = {{4.0, 0.0},  {8.0, 0.0},  {8.0, 6.0},  {0.0, 6.0}, {0.0, 0.0}, {4.0, 0.0},  // inner, 28 m
                 {24.0, 0.0}, {24.0, 16.0}, {0.0, 16.0}, {0.0, 0.0}, {4.0, 0.0}};            // outer, 80 m
  return r;
}

double route_start_heading_rad(const Route& route) {
  if (route.waypoints.size() < 2) return 0.0;
  const Point2& a = route.waypoints[0];
  const Point2& b = route.waypoints[1];
  return std::atan2(b.y_m - a.y_m, b.x_m - a.x_m);
}

double route_length_m(const Route& route, std::size_t first, std::size_t last) {
  double sum = 0.0;
  last = std::min(last, route.waypoints.empty() ? 0 : route.waypoints.size() - 1);
  for (std::size_t i = first; i < last; ++i) {
    const Point2& a = route.waypoints[i];
    const Point2& b = route.waypoints[i + 1];
    sum += std::hypot(b.x_m - a.x_m, b.y_m - a.y_m);
  }
  return sum;
}

double route_length_m(const Route& route) {
  return route.waypoints.empty() ? 0.0 : route_length_m(route, 0, route.waypoints.size() - 1);
}

bool parse_world(const std::string& text, const std::string& source_name, World* world, std::string* error) {
  world->segments.clear();
  std::istringstream in(text);
  std::string line;
  std::vector<double> v;
  std::string reason;
  long line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!split_numbers(line, &v, &reason)) {
      *error = source_name + ":" + std::to_string(line_no) + ": " + reason;
      return false;
    }
    if (v.empty()) continue;
    if (v.size() != 4) {
      *error = source_name + ":" + std::to_string(line_no) + ": expected 4 numbers (x1 y1 x2 y2), got " +
               std::to_string(v.size());
      return false;
    }
    if (v[0] == v[2] && v[1] == v[3]) {
      *error = source_name + ":" + std::to_string(line_no) + ": segment has zero length";
      return false;
    }
    world->segments.push_back(Segment{{v[0], v[1]}, {v[2], v[3]}});
  }
  if (world->segments.empty()) {
    *error = source_name + ": no wall segments";
    return false;
  }
  return true;
}

bool load_world_file(const std::string& path, World* world, std::string* error) {
  std::string text;
  if (!read_text_file(path, &text, error)) return false;
  return parse_world(text, path, world, error);
}

std::string format_world(const World& world) {
  std::string out = "# sdpslam world: one wall segment per line, x1 y1 x2 y2 in metres\n";
  for (const Segment& s : world.segments) {
    append_shortest(&out, s.a.x_m);
    out += ' ';
    append_shortest(&out, s.a.y_m);
    out += ' ';
    append_shortest(&out, s.b.x_m);
    out += ' ';
    append_shortest(&out, s.b.y_m);
    out += '\n';
  }
  return out;
}

bool parse_route(const std::string& text, const std::string& source_name, Route* route, std::string* error) {
  route->waypoints.clear();
  std::istringstream in(text);
  std::string line;
  std::vector<double> v;
  std::string reason;
  long line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    if (!split_numbers(line, &v, &reason)) {
      *error = source_name + ":" + std::to_string(line_no) + ": " + reason;
      return false;
    }
    if (v.empty()) continue;
    if (v.size() != 2) {
      *error = source_name + ":" + std::to_string(line_no) + ": expected 2 numbers (x y), got " +
               std::to_string(v.size());
      return false;
    }
    if (!route->waypoints.empty() && route->waypoints.back().x_m == v[0] && route->waypoints.back().y_m == v[1]) {
      *error = source_name + ":" + std::to_string(line_no) + ": waypoint repeats the previous one";
      return false;
    }
    route->waypoints.push_back(Point2{v[0], v[1]});
  }
  if (route->waypoints.size() < 2) {
    *error = source_name + ": a route needs at least 2 waypoints";
    return false;
  }
  return true;
}

bool load_route_file(const std::string& path, Route* route, std::string* error) {
  std::string text;
  if (!read_text_file(path, &text, error)) return false;
  return parse_route(text, path, route, error);
}

double distance_to_nearest_wall_m(const World& world, double x_m, double y_m) {
  double best = std::numeric_limits<double>::infinity();
  for (const Segment& s : world.segments) {
    const double ex = s.b.x_m - s.a.x_m;
    const double ey = s.b.y_m - s.a.y_m;
    const double len2 = ex * ex + ey * ey;
    double u = ((x_m - s.a.x_m) * ex + (y_m - s.a.y_m) * ey) / len2;
    u = std::clamp(u, 0.0, 1.0);
    best = std::min(best, std::hypot(x_m - (s.a.x_m + u * ex), y_m - (s.a.y_m + u * ey)));
  }
  return best;
}

}  // namespace sdpslam::sim
