#include "runtime/perception/scan/scan_poses.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <vector>

#include "runtime/core/diagnostics.h"

namespace autoshovel::perception {

namespace {

constexpr std::uintmax_t kMaxPosesBytes = std::uintmax_t{16} << 20;

// The first problem refuses the file (core::RefuseInput).
[[noreturn]] void Refuse(const std::string& source, int line, int column,
                         const std::string& message) {
  core::RefuseInput({source, line, column}, message);
}

}  // namespace

Eigen::Isometry3d PoseFromXyzRpyDegrees(double x, double y, double z, double roll, double pitch,
                                        double yaw) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = (Eigen::AngleAxisd(yaw * kDeg, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(pitch * kDeg, Eigen::Vector3d::UnitY()) *
                Eigen::AngleAxisd(roll * kDeg, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

std::map<std::string, Eigen::Isometry3d> ParseScanPoses(const std::string& text,
                                                        const std::string& source) {
  std::map<std::string, Eigen::Isometry3d> poses;
  std::istringstream in(text);
  std::string line;
  int line_number = 0;
  bool first = true;
  while (std::getline(in, line)) {
    ++line_number;
    const std::string content = line.substr(0, line.find('#'));
    // Fields and where each starts.
    std::vector<std::pair<std::string, int>> fields;
    std::size_t i = 0;
    while (i < content.size()) {
      if (content[i] == ',' || content[i] == ' ' || content[i] == '\t' || content[i] == '\r') {
        ++i;
        continue;
      }
      std::size_t end = i;
      while (end < content.size() && content[end] != ',' && content[end] != ' ' &&
             content[end] != '\t' && content[end] != '\r') {
        ++end;
      }
      fields.emplace_back(content.substr(i, end - i), static_cast<int>(i) + 1);
      i = end;
    }
    if (fields.empty()) continue;
    const bool header = first && fields[0].first == "name";
    first = false;
    if (header) continue;
    if (fields.size() != 7) {
      Refuse(source, line_number, fields[0].second,
             "expected 7 fields (name x y z roll pitch yaw), got " + std::to_string(fields.size()));
    }
    double v[6];
    for (int k = 0; k < 6; ++k) {
      const auto& [word, column] = fields[static_cast<std::size_t>(k + 1)];
      char* stop = nullptr;
      errno = 0;
      v[k] = std::strtod(word.c_str(), &stop);
      if (stop != word.c_str() + word.size() || errno == ERANGE || !std::isfinite(v[k])) {
        Refuse(source, line_number, column,
               "expected a finite number, got '" + word.substr(0, 40) + "'");
      }
    }
    const std::string& name = fields[0].first;
    if (poses.count(name) != 0) {
      Refuse(source, line_number, fields[0].second,
             "cloud '" + name.substr(0, 80) + "' given twice");
    }
    poses[name] = PoseFromXyzRpyDegrees(v[0], v[1], v[2], v[3], v[4], v[5]);
  }
  if (poses.empty()) Refuse(source, 0, 0, "no poses (lines 'name x y z roll pitch yaw')");
  return poses;
}

std::map<std::string, Eigen::Isometry3d> ReadScanPoses(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) Refuse(path, 0, 0, "no such file");
  if (std::filesystem::file_size(path, ec) > kMaxPosesBytes) {
    Refuse(path, 0, 0, "larger than 16 MiB: not a poses file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) Refuse(path, 0, 0, "cannot open");
  std::ostringstream text;
  text << in.rdbuf();
  return ParseScanPoses(text.str(), path);
}

}  // namespace autoshovel::perception
