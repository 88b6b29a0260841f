// Line plots as PNG files (OpenCV drawing, no plotting library): axes with "nice" ticks, axis
// labels with units, a title, a legend, optional vertical and horizontal marker lines, and grids
// of such plots in one image. Used by the run report and the identification residual figures;
// OpenCV stays in line_plot.cc.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace autoshovel::plot {

struct Color {
  unsigned char b = 0, g = 0, r = 0;
};

inline constexpr Color kBlue{180, 110, 30};
inline constexpr Color kOrange{20, 130, 240};
inline constexpr Color kGreen{60, 160, 60};
inline constexpr Color kRed{40, 40, 210};
inline constexpr Color kGrey{120, 120, 120};

struct PlotSeries {
  std::string name;       ///< legend entry; empty: not in the legend
  std::vector<double> x;  ///< same length as y; a NaN in x or y breaks the line
  std::vector<double> y;
  Color color = kBlue;
  int thickness = 2;  ///< [px]
  bool dashed = false;
  bool markers = false;  ///< a dot at each point
};

/// A vertical (x = value) or horizontal (y = value) line across the plot, labelled.
struct MarkerLine {
  double value = 0.0;
  std::string label;
  Color color = kRed;
  bool dashed = true;
};

struct LinePlot {
  std::string title;
  std::string x_label;  ///< with the unit, e.g. "t [s]"
  std::string y_label;
  std::vector<PlotSeries> series;
  std::vector<MarkerLine> vertical;
  std::vector<MarkerLine> horizontal;
  bool equal_aspect = false;  ///< same metres per pixel on both axes (paths in x–z)
  bool y_from_zero = false;   ///< include y = 0 in the range
  int width_px = 900;
  int height_px = 540;
};

/// Draws `plot` into `path` (.png). A plot without any finite point draws empty axes with
/// "no data". Throws std::runtime_error naming the file when it cannot be written, and
/// std::invalid_argument when a series' x and y differ in length.
void WriteLinePlotPng(const LinePlot& plot, const std::filesystem::path& path);

/// Several plots, each with its own axes, `columns` per row, in one PNG (written whole or not
/// at all). Throws like WriteLinePlotPng.
void WriteLinePlotGridPng(const std::vector<LinePlot>& plots, int columns,
                          const std::filesystem::path& path);

}  // namespace autoshovel::plot
