// The measurement file of an arm calibration: one row per pose, a header naming the columns.
//
//   theta_cab_deg, theta_boom_deg, theta_bucket_deg, dx_m, dz_m
//   0.31, -20.4, 12.9, 0.412, -1.873
//   ...
//
// θ columns are the IMU pitch readings (Eq. 1), one for the cab and one per link named after the
// link, in degrees (`_deg`) or radians (`_rad`); dx, dz the measured tip displacement from this
// pose to the next in the arm plane (`_m` or `_mm`), empty on the last row. Lines starting with
// `#` are comments. Columns may come in any order; extra columns are ignored.
#pragma once

#include <string>
#include <vector>

#include "identification/calibration/arm_calibration.h"

namespace autoshovel::identification {

/// Reads the file for a machine with these link names. Throws core::InputError naming the file,
/// row and column of every problem (missing column, not a number, NaN, missing displacement).
ArmCalibrationData ReadArmCalibrationCsv(const std::string& path,
                                         const std::vector<std::string>& link_names);

}  // namespace autoshovel::identification
