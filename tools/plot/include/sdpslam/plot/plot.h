#pragma once
// Figures people can read (io::Painter, figures.h), drawn with cairo (Debian libcairo2):
//   - charts: title, axes with 1-2-5 ticks, tick labels, axis labels with their units, a
//     light grid and a legend of the series;
//   - maps: the occupancy map (grey as map_server reads it), the path with its start and
//     end, the points under them, a title, a scale bar in metres and a legend.
// Host tools only (the `sdpslam` CLI); the robot program keeps io::plain_painter().
// Output is a PNG written atomically (atomic_file.h). Same input, same bytes.
#include <string>
#include <vector>

#include "sdpslam/io/figures.h"

namespace sdpslam::plot {

// The painter of this module: charts and maps as below.
io::Painter painter();

bool write_chart_png(const std::string& path, const io::Chart& chart, std::string* error);
bool write_map_figure_png(const std::string& path, const io::MapFigure& figure, std::string* error);

// Axis ticks: the multiples of one step (1, 2 or 5 × 10^k) inside [lo, hi], the finest
// step giving at most max_count of them (max_count >= 2; an empty or reversed range gives
// no tick).
std::vector<double> nice_ticks(double lo, double hi, int max_count);
// A scale bar's length: the largest 1, 2 or 5 × 10^k not above max_value (0 if max_value
// is not positive and finite).
double nice_length(double max_value);
// A tick's text with as many decimals as the step between ticks needs ("0.25", "10").
std::string tick_label(double value, double step);

}  // namespace sdpslam::plot
