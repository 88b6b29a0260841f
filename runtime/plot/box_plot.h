// Box plots as PNG (OpenCV drawing), the seed's Fig. 22 style: per category the median, the
// quartiles (box), whiskers to the farthest sample within 1.5 IQR of the box (Tukey), and the
// samples beyond as dots; the sample count under each box. Several panels side by side.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace autoshovel::plot {

struct BoxGroup {
  std::string name;
  std::vector<double> samples;  ///< non-finite samples are ignored
};

struct BoxPlot {
  std::string title;
  std::string unit;  ///< of the samples, shown on the axis
  std::vector<BoxGroup> groups;
};

/// Tukey's five numbers of a sample (linear-interpolated quartiles, as NumPy's default).
struct BoxStatistics {
  int count = 0;
  double q1 = 0, median = 0, q3 = 0;
  double low_whisker = 0, high_whisker = 0;  ///< farthest samples within 1.5 IQR of the box
  std::vector<double> outliers;
};
BoxStatistics ComputeBoxStatistics(std::vector<double> samples);

/// The panels side by side in one PNG. Throws std::runtime_error naming the file when it
/// cannot be written.
void WriteBoxPlotsPng(const std::vector<BoxPlot>& panels, const std::filesystem::path& path);

}  // namespace autoshovel::plot
