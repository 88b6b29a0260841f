// Where each scan of a sequence was taken (`map --cloud … --poses FILE`, issue 43): one line per
// cloud, `name x y z roll pitch yaw` — the cloud's file name (without folders), the scanner's
// position [m] and attitude [deg] in the first cloud's frame, R = Rz(yaw) Ry(pitch) Rx(roll) —
// separated by commas or blanks; `#` starts a comment; a first line starting with `name` is a
// header. Every value must be finite. Refusals are core::InputError `file:line:column: …`.
#pragma once

#include <Eigen/Geometry>
#include <map>
#include <string>

namespace autoshovel::perception {

/// Poses by cloud file name (T_first_scan). Throws core::InputError.
std::map<std::string, Eigen::Isometry3d> ParseScanPoses(const std::string& text,
                                                        const std::string& source);
std::map<std::string, Eigen::Isometry3d> ReadScanPoses(const std::string& path);

/// R = Rz(yaw) Ry(pitch) Rx(roll), angles in degrees; translation in metres.
Eigen::Isometry3d PoseFromXyzRpyDegrees(double x, double y, double z, double roll, double pitch,
                                        double yaw);

}  // namespace autoshovel::perception
