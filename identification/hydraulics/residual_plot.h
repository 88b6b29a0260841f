// The residual figure of hydraulic identification: per file, measured and fitted joint angle
// (and spool, if logged) against time, and the angle residual. OpenCV stays in residual_plot.cc.
#pragma once

#include <string>
#include <vector>

#include "identification/hydraulics/hydraulic_identification.h"
#include "runtime/plot/line_plot.h"

namespace autoshovel::identification {

/// One panel of the identification figures: `title`, time on x, `y_label`, 560×300 px.
plot::LinePlot TimePanel(const std::string& title, const std::string& y_label);

/// Writes the PNG to `path` (through a temporary file, renamed once complete). Throws
/// std::runtime_error naming the path when it cannot be written.
void WriteResidualPlot(const std::vector<ActuatorIdentification>& results, const std::string& path);

}  // namespace autoshovel::identification
