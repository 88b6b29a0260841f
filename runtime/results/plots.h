// Line plots as PNG files (OpenCV drawing, no plotting library): axes with "nice" ticks, axis
// labels with units, a title, a legend, optional vertical and horizontal marker lines. Enough for
// the run report's figures; OpenCV stays in plots.cc.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/results/results_db.h"

namespace autoshovel::results {

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

/// V1 and V1+V2 [m³] against time [s] for one cycle, a vertical line at the trigger (omitted when
/// NaN) and a horizontal line at the target volume (omitted when NaN).
void WriteVolumePlotPng(const CycleRecord& cycle, double target_volume_m3,
                        const std::filesystem::path& path);

/// Predicted and actual bucket-tip paths in the x–z plane of the vehicle frame [m], equal aspect.
void WriteTipPathPlotPng(const CycleRecord& cycle, const std::filesystem::path& path);

/// Fill rate [%] per cycle index, one line per strategy, markers at each cycle.
void WriteFillRatePlotPng(const std::vector<CycleRecord>& cycles,
                          const std::filesystem::path& path);

}  // namespace autoshovel::results
