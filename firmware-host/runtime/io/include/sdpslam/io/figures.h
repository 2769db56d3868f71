#pragma once
// Figures of the outputs (a map with the path driven on it, a chart of a figure over
// time) as data, and the painter that draws them into PNG files.
//
// The runners (firmware-host/runtime/slam) describe what to draw; who draws it is chosen by the program:
// plain_painter() rasterises without text (libpng only: the robot program and the cross
// builds use it), the `sdpslam` CLI uses plot::painter() (tools/plot: cairo), which adds
// title, axes with tick labels and units, a legend and, on maps, a scale bar.
// Every write is atomic (atomic_file.h).
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "sdpslam/core/pose2.h"
#include "sdpslam/io/map_image.h"
#include "sdpslam/io/trajectory_io.h"

namespace sdpslam::io {

struct Rgb8 {
  std::uint8_t r = 0U;
  std::uint8_t g = 0U;
  std::uint8_t b = 0U;
};

// The colours every painter uses for the path and its marks (map_image.cpp's too).
inline constexpr Rgb8 kFigurePathColour{220, 20, 20};
inline constexpr Rgb8 kFigureStartColour{0, 170, 0};
inline constexpr Rgb8 kFigureEndColour{20, 40, 230};
inline constexpr Rgb8 kFigurePointColour{255, 140, 0};

struct ChartSeries {
  enum class Style : std::uint8_t {
    kLine,    // y over x, joined
    kPoints,  // y over x, a dot each
    kBand,    // the area between y (lower edge) and y_high (upper edge)
  };
  std::string label;  // its legend entry
  Rgb8 colour;
  Style style = Style::kLine;
  std::vector<double> x;
  std::vector<double> y;
  std::vector<double> y_high;  // kBand only, as many as y

  static ChartSeries named(std::string label, Rgb8 colour, Style style = Style::kLine) {
    ChartSeries s;
    s.label = std::move(label);
    s.colour = colour;
    s.style = style;
    return s;
  }
};

// One x axis and one y axis; labels carry their units ("time since the first scan (s)").
// Non-finite values are left out; the y axis starts at 0 unless a value is negative.
struct Chart {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<ChartSeries> series;
};

// A map with the path on it (start and end marked) and points (a particle set) under it.
// The figure refers to the caller's data (null: none), which must outlive the drawing.
struct MapFigure {
  std::string title;
  const OccupancyImage* map = nullptr;
  const std::vector<StampedPose>* path = nullptr;
  std::string path_label = "path";
  const std::vector<Pose2>* points = nullptr;
  std::string points_label = "particles";
  // The path and the points, empty when not given.
  const std::vector<StampedPose>& path_poses() const;
  const std::vector<Pose2>& point_poses() const;
};

// A painter writes a figure to a PNG file; false with `error` naming the file and why.
struct Painter {
  std::function<bool(const std::string& path, const Chart& chart, std::string* error)> chart;
  std::function<bool(const std::string& path, const MapFigure& figure, std::string* error)> map;
};

// Without text: the map as write_map_png() draws it; a chart as its series on two axes
// (bands grey, the first line series and the points in the path and point colours).
Painter plain_painter();

// Whether a chart has something to draw: a series with a finite point.
bool chart_has_data(const Chart& chart);

}  // namespace sdpslam::io
