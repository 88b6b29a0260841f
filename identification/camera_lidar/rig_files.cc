#include "identification/camera_lidar/rig_files.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "runtime/core/diagnostics.h"

namespace autoshovel::identification {

namespace {

constexpr std::uintmax_t kMaxRigFileBytes = std::uintmax_t{1} << 20;

struct Number {
  double value = 0;
  int line = 0, column = 0;
};

// The first problem refuses the file (core::RefuseInput).
[[noreturn]] void Refuse(const std::string& source, int line, int column,
                         const std::string& message) {
  core::RefuseInput({source, line, column}, message);
}

// The numbers of one line after `begin`, each with its column; stops at `#`. Refuses a token
// that is not a finite number.
std::vector<Number> NumbersOf(const std::string& line, std::size_t begin, int line_number,
                              const std::string& source) {
  std::vector<Number> numbers;
  std::size_t i = begin;
  while (i < line.size()) {
    const char c = line[i];
    if (c == '#') break;
    if (c == ' ' || c == '\t' || c == '\r' || c == ',') {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < line.size() && line[end] != ' ' && line[end] != '\t' && line[end] != '\r' &&
           line[end] != ',' && line[end] != '#') {
      ++end;
    }
    const std::string token = line.substr(i, end - i);
    char* stop = nullptr;
    errno = 0;
    const double value = std::strtod(token.c_str(), &stop);
    if (stop != token.c_str() + token.size() || errno == ERANGE || !std::isfinite(value)) {
      Refuse(source, line_number, static_cast<int>(i) + 1,
             "expected a finite number, got '" + token.substr(0, 40) + "'");
    }
    numbers.push_back({value, line_number, static_cast<int>(i) + 1});
    i = end;
  }
  return numbers;
}

std::string ReadSmallFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) Refuse(path, 0, 0, "no such file");
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) Refuse(path, 0, 0, "cannot read: " + ec.message());
  if (size > kMaxRigFileBytes) {
    Refuse(path, 0, 0,
           "is " + std::to_string(size) + " bytes; a calibration file has at most 1 MiB");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Refuse(path, 0, 0, "cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Rows 0–2 of a row-major 3×4 block into an isometry; refuses a rotation that is not one.
Eigen::Isometry3d IsometryFrom(const std::vector<Number>& v, const std::string& source) {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R(r, c) = v[static_cast<std::size_t>(4 * r + c)].value;
    t[r] = v[static_cast<std::size_t>(4 * r + 3)].value;
  }
  const double orthogonality = (R.transpose() * R - Eigen::Matrix3d::Identity()).norm();
  if (!(orthogonality < 1e-3) || !(R.determinant() > 0)) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "the rotation block is not a rotation (|RᵀR − I| = %.3g, det %.3g): a scaled, "
                  "sheared or mirrored matrix is refused, not repaired",
                  orthogonality, R.determinant());
    Refuse(source, v.front().line, v.front().column, text);
  }
  // Re-orthonormalise what is left of the file's rounding (6 digits) so that products stay
  // rigid.
  const Eigen::Quaterniond q(R);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace

RigCalibrationFile ParseCalibTxt(const std::string& text, const std::string& source) {
  RigCalibrationFile file;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  bool seen_k = false, seen_d = false, seen_t = false;
  while (std::getline(in, line)) {
    ++line_number;
    std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    const std::size_t colon = line.find(':', first);
    if (colon == std::string::npos) {
      Refuse(source, line_number, static_cast<int>(first) + 1,
             "expected `K:`, `D:` or `T:` followed by numbers");
    }
    std::string key = line.substr(first, colon - first);
    while (!key.empty() && (key.back() == ' ' || key.back() == '\t')) key.pop_back();
    const std::vector<Number> values = NumbersOf(line, colon + 1, line_number, source);
    const int column = static_cast<int>(first) + 1;
    if (key == "K") {
      if (seen_k) Refuse(source, line_number, column, "K: given twice");
      seen_k = true;
      if (values.size() != 9) {
        Refuse(source, line_number, column,
               "K: needs 9 values (3×3 row-major), got " + std::to_string(values.size()));
      }
      Eigen::Matrix3d K;
      for (int i = 0; i < 9; ++i) K(i / 3, i % 3) = values[static_cast<std::size_t>(i)].value;
      if (!(K(0, 0) > 0) || !(K(1, 1) > 0) || std::abs(K(2, 2) - 1.0) > 1e-9 || K(1, 0) != 0 ||
          K(2, 0) != 0 || K(2, 1) != 0) {
        Refuse(source, line_number, column,
               "K: expected a pinhole matrix [fx s cx; 0 fy cy; 0 0 1] with fx, fy > 0");
      }
      file.K = K;
    } else if (key == "D") {
      if (seen_d) Refuse(source, line_number, column, "D: given twice");
      seen_d = true;
      if (values.size() != 4 && values.size() != 5 && values.size() != 8) {
        Refuse(source, line_number, column,
               "D: needs 4, 5 or 8 values (k1 k2 p1 p2 [k3 [k4 k5 k6]]), got " +
                   std::to_string(values.size()));
      }
      for (const Number& n : values) file.D.push_back(n.value);
    } else if (key == "T") {
      if (seen_t) Refuse(source, line_number, column, "T: given twice");
      seen_t = true;
      if (values.size() != 12 && values.size() != 16) {
        Refuse(source, line_number, column,
               "T: needs 12 values (the first 3 rows of the 4×4 LiDAR→camera matrix) or 16, got " +
                   std::to_string(values.size()));
      }
      if (values.size() == 16 && (values[12].value != 0 || values[13].value != 0 ||
                                  values[14].value != 0 || values[15].value != 1)) {
        Refuse(source, line_number, values[12].column, "T: the last row must be 0 0 0 1");
      }
      file.T_optical_lidar = IsometryFrom(values, source);
    } else {
      Refuse(source, line_number, column,
             "unknown key '" + key.substr(0, 40) + "' (expected K, D or T)");
    }
  }
  if (!seen_k && !seen_d && !seen_t) Refuse(source, 0, 0, "no K:, D: or T: line");
  return file;
}

RigCalibrationFile ReadCalibTxt(const std::string& path) {
  return ParseCalibTxt(ReadSmallFile(path), path);
}

Eigen::Isometry3d ParseExtrinsic(const std::string& text, const std::string& source) {
  // A calib.txt when a line (outside comments) has a key; a comment may hold colons.
  bool keyed = false;
  {
    std::istringstream lines(text);
    std::string line;
    while (!keyed && std::getline(lines, line)) {
      keyed = line.substr(0, line.find('#')).find(':') != std::string::npos;
    }
  }
  if (keyed) {
    const RigCalibrationFile file = ParseCalibTxt(text, source);
    if (!file.T_optical_lidar) Refuse(source, 0, 0, "has no `T:` line (the extrinsic)");
    return *file.T_optical_lidar;
  }
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  std::vector<Number> values;
  while (std::getline(in, line)) {
    ++line_number;
    const std::vector<Number> row = NumbersOf(line, 0, line_number, source);
    values.insert(values.end(), row.begin(), row.end());
  }
  if (values.size() != 12 && values.size() != 16) {
    Refuse(source, 0, 0,
           "expected a 3×4 or 4×4 LiDAR→camera matrix (12 or 16 numbers), got " +
               std::to_string(values.size()));
  }
  if (values.size() == 16 && (values[12].value != 0 || values[13].value != 0 ||
                              values[14].value != 0 || values[15].value != 1)) {
    Refuse(source, values[12].line, values[12].column, "the last row must be 0 0 0 1");
  }
  return IsometryFrom(values, source);
}

Eigen::Isometry3d ReadExtrinsic(const std::string& path) {
  return ParseExtrinsic(ReadSmallFile(path), path);
}

std::string ExtrinsicText(const Eigen::Isometry3d& T_optical_lidar, const std::string& comment) {
  std::ostringstream out;
  std::istringstream lines(comment);
  std::string line;
  while (std::getline(lines, line)) out << "# " << line << "\n";
  const Eigen::Matrix4d M = T_optical_lidar.matrix();
  for (int r = 0; r < 4; ++r) {
    char row[160];
    std::snprintf(row, sizeof row, "%.9g %.9g %.9g %.9g\n", M(r, 0), M(r, 1), M(r, 2), M(r, 3));
    out << row;
  }
  return out.str();
}

namespace {

// The rows of `text`, each with exactly `columns` numbers (blank and comment lines skipped).
std::vector<std::vector<Number>> Rows(const std::string& text, const std::string& source,
                                      std::size_t columns, const char* what) {
  std::vector<std::vector<Number>> rows;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    std::vector<Number> row = NumbersOf(line, 0, line_number, source);
    if (row.empty()) continue;
    if (row.size() != columns) {
      Refuse(source, line_number, row.front().column,
             "expected " + std::to_string(columns) + " numbers (" + what + "), got " +
                 std::to_string(row.size()));
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

void RequireFour(std::size_t count, const std::string& source) {
  if (count < 4) {
    Refuse(source, 0, 0,
           std::to_string(count) +
               " correspondences; PnP needs at least 4 (6 or more for RANSAC to reject any)");
  }
}

}  // namespace

std::vector<Correspondence> ParseCorrespondences(const std::string& text,
                                                 const std::string& source) {
  std::vector<Correspondence> out;
  for (const auto& row : Rows(text, source, 5, "u v x y z")) {
    out.push_back({{row[0].value, row[1].value}, {row[2].value, row[3].value, row[4].value}});
  }
  RequireFour(out.size(), source);
  return out;
}

std::vector<Correspondence> ParseCorrespondencePair(const std::string& image_text,
                                                    const std::string& image_source,
                                                    const std::string& lidar_text,
                                                    const std::string& lidar_source) {
  const auto pixels = Rows(image_text, image_source, 2, "u v");
  const auto points = Rows(lidar_text, lidar_source, 3, "x y z");
  if (pixels.size() != points.size()) {
    Refuse(lidar_source, 0, 0,
           std::to_string(points.size()) + " LiDAR points against " +
               std::to_string(pixels.size()) + " image points in " + image_source +
               ": the k-th line of each must be the same corner");
  }
  std::vector<Correspondence> out;
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    out.push_back({{pixels[k][0].value, pixels[k][1].value},
                   {points[k][0].value, points[k][1].value, points[k][2].value}});
  }
  RequireFour(out.size(), image_source);
  return out;
}

std::vector<Correspondence> ReadCorrespondences(const std::string& spec) {
  const auto comma = spec.find(',');
  if (comma == std::string::npos) return ParseCorrespondences(ReadSmallFile(spec), spec);
  const std::string image = spec.substr(0, comma), lidar = spec.substr(comma + 1);
  return ParseCorrespondencePair(ReadSmallFile(image), image, ReadSmallFile(lidar), lidar);
}

ProtocolError CompareExtrinsics(const Eigen::Isometry3d& T_ref_optical_lidar,
                                const Eigen::Isometry3d& T_est_optical_lidar) {
  const Eigen::Isometry3d E = T_ref_optical_lidar * T_est_optical_lidar.inverse();
  return {Eigen::AngleAxisd(E.linear()).angle(), E.translation().norm()};
}

Eigen::Isometry3d ProtocolDelta(const Eigen::Vector3d& roll_pitch_yaw, const Eigen::Vector3d& xyz) {
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  delta.linear() = (Eigen::AngleAxisd(roll_pitch_yaw.z(), Eigen::Vector3d::UnitZ()) *
                    Eigen::AngleAxisd(roll_pitch_yaw.y(), Eigen::Vector3d::UnitY()) *
                    Eigen::AngleAxisd(roll_pitch_yaw.x(), Eigen::Vector3d::UnitX()))
                       .toRotationMatrix();
  delta.translation() = xyz;
  return delta;
}

}  // namespace autoshovel::identification
