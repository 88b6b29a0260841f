// A grouped bar chart as a PNG (OpenCV drawing): residuals per measurement before and after an
// identification, where a person would rather look than read a table.
#pragma once

#include <string>
#include <vector>

namespace autoshovel::plot {

struct BarSeries {
  std::string name;
  std::vector<double> values;  ///< one per group; NaN draws nothing
  unsigned char bgr[3] = {80, 80, 80};
};

struct BarChart {
  std::string title;
  std::string unit;                 ///< of the values, shown on the axis
  std::vector<std::string> groups;  ///< a label under each group of bars
  std::vector<BarSeries> series;
};

/// Writes the chart to `path` (a .png). Throws std::runtime_error when it cannot be written.
void WriteBarChartPng(const BarChart& chart, const std::string& path);
/// Several charts, each with its own scale, one above the other in one PNG.
void WriteBarChartsPng(const std::vector<BarChart>& charts, const std::string& path);

}  // namespace autoshovel::plot
