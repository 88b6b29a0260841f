// Stacked area plots as PNG (OpenCV drawing, in stacked_area_plot.cc): where a wheel loader's
// energy goes over a scoop. Several non-negative series over one increasing x (power per
// category in kW over time, or cumulative energy in kJ) are stacked bottom first, the stack's
// total is a thin dark line on top, phase boundaries are labelled vertical lines, and a legend
// right of the plotting area (so that it hides nothing) lists the series top of the stack first.
//
// Drawing: each pixel column shows the mean of each series over the column's x interval (the
// series linear between samples), so the painted area of a power series is its energy to
// within the pixel grid even where there are several samples per pixel; the y axis runs from 0
// to the largest total so drawn. A value that is negative or not finite is drawn as 0: a caller
// should not pass one, but a plot never fails on its data values.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "runtime/plot/line_plot.h"

namespace autoshovel::plot {

struct StackedSeries {
  std::string name;            ///< legend entry; empty: not in the legend
  std::vector<double> values;  ///< one per x; >= 0 (negative or non-finite: drawn as 0)
  Color color;
};

struct StackedAreaPlot {
  std::string title;
  std::string x_label;                ///< with the unit, e.g. "t [s]"
  std::string y_label;                ///< e.g. "P [kW]"
  std::vector<double> x;              ///< finite, strictly increasing
  std::vector<StackedSeries> series;  ///< each values.size() == x.size(); bottom first
  std::vector<MarkerLine> vertical;   ///< phase boundaries
  int width_px = 1000;                ///< of the whole image, legend included
  int height_px = 600;
};

/// Draws `plot` into `path` (.png), written atomically through WriteImageFile. A plot without
/// samples draws empty axes with "no data". Throws std::invalid_argument (naming the plot and the
/// series or the sample) when x is not finite and strictly increasing or a series' length differs
/// from x's, and core::OutputError naming the path when the file cannot be written.
void WriteStackedAreaPlotPng(const StackedAreaPlot& plot, const std::filesystem::path& path);

/// Several stacked plots one above the other in one PNG (written whole or not at all), as wide
/// as the widest. Throws like WriteStackedAreaPlotPng, and std::invalid_argument for no plots.
void WriteStackedAreaPlotsPng(const std::vector<StackedAreaPlot>& plots,
                              const std::filesystem::path& path);

/// A colour for series k of n, distinct and readable: the Okabe–Ito qualitative palette
/// (Okabe & Ito, "Color Universal Design", 2008; safe for colour-blind readers) without its
/// black, cycling after 7 colours. Any k, negative included.
Color PaletteColor(int k);

}  // namespace autoshovel::plot
