#include "identification/calibration/arm_calibration_csv.h"

#include <cmath>
#include <fstream>
#include <map>
#include <numbers>
#include <sstream>

#include "runtime/core/diagnostics.h"
#include "runtime/core/input_file.h"

namespace autoshovel::identification {

namespace {

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) {
    const auto b = cell.find_first_not_of(" \t\r");
    const auto e = cell.find_last_not_of(" \t\r");
    cells.push_back(b == std::string::npos ? "" : cell.substr(b, e - b + 1));
  }
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

struct Column {
  int index = -1;
  double scale = 1.0;  // to SI
};

}  // namespace

ArmCalibrationData ReadArmCalibrationCsv(const std::string& path,
                                         const std::vector<std::string>& link_names) {
  core::DiagnosticSink sink;
  // Checked before opening: a named pipe would block the open, a folder would read as empty.
  if (const std::string why = core::NotARegularFile(path); !why.empty()) {
    sink.Add({path, 0, 0}, "", "cannot open: " + why);
    sink.ThrowIfAny();
  }
  std::ifstream file(path);
  if (!file) {
    sink.Add({path, 0, 0}, "", "cannot open the file");
    sink.ThrowIfAny();
  }
  std::string line;
  int row = 0;
  std::vector<std::string> header;
  int header_row = 0;
  while (std::getline(file, line)) {
    ++row;
    if (line.empty() || line[0] == '#') continue;
    header = SplitCsv(line);
    header_row = row;
    break;
  }
  if (header.empty()) {
    sink.Add({path, 0, 0}, "", "no header row (the file is empty or only comments)");
    sink.ThrowIfAny();
  }
  // Find each wanted column with its unit.
  const double deg = std::numbers::pi / 180.0;
  auto find = [&](const std::string& stem,
                  const std::vector<std::pair<std::string, double>>& units) {
    Column column;
    for (std::size_t i = 0; i < header.size(); ++i) {
      for (const auto& [suffix, scale] : units) {
        if (header[i] == stem + suffix) column = {static_cast<int>(i), scale};
      }
    }
    if (column.index < 0) {
      std::string expected;
      for (const auto& [suffix, scale] : units) {
        expected += (expected.empty() ? "" : " or ") + stem + suffix;
      }
      sink.Add({path, header_row, 1}, "", "no column " + expected + " in the header");
    }
    return column;
  };
  const std::vector<std::pair<std::string, double>> angle_units{{"_deg", deg}, {"_rad", 1.0}};
  const std::vector<std::pair<std::string, double>> length_units{{"_m", 1.0}, {"_mm", 1e-3}};
  std::vector<Column> angles{find("theta_cab", angle_units)};
  for (const std::string& link : link_names) angles.push_back(find("theta_" + link, angle_units));
  const Column dx = find("dx", length_units), dz = find("dz", length_units);
  sink.ThrowIfAny();

  ArmCalibrationData data;
  data.source = path;
  std::vector<int> rows;
  std::vector<std::pair<bool, Eigen::Vector2d>> displacement;
  while (std::getline(file, line)) {
    ++row;
    if (line.empty() || line[0] == '#') continue;
    const std::vector<std::string> cells = SplitCsv(line);
    if (cells.size() != header.size()) {  // a cell lost or added shifts every column after it
      sink.Add({path, row, 1}, "",
               std::to_string(cells.size()) + " cells, expected " + std::to_string(header.size()) +
                   " like the header (row " + std::to_string(header_row) + ")");
      continue;
    }
    auto number = [&](const Column& c, const std::string& name, bool optional, bool& present) {
      present = false;
      if (c.index >= static_cast<int>(cells.size()) || cells[c.index].empty()) {
        if (!optional) sink.Add({path, row, c.index + 1}, name, "missing value");
        return 0.0;
      }
      char* end = nullptr;
      const double v = std::strtod(cells[c.index].c_str(), &end);
      if (end == cells[c.index].c_str() || *end != '\0' || !std::isfinite(v)) {
        sink.Add({path, row, c.index + 1}, name,
                 "expected a finite number, got '" + cells[c.index] + "'");
        return 0.0;
      }
      present = true;
      return v * c.scale;
    };
    std::vector<double> pose;
    bool present = false;
    for (std::size_t k = 0; k < angles.size(); ++k) {
      pose.push_back(number(angles[k], header[angles[k].index], false, present));
    }
    bool has_dx = false, has_dz = false;
    const double x = number(dx, header[dx.index], true, has_dx);
    const double z = number(dz, header[dz.index], true, has_dz);
    if (has_dx != has_dz) {
      sink.Add({path, row, (has_dx ? dz : dx).index + 1}, "", "dx and dz go together");
    }
    data.angles.push_back(pose);
    rows.push_back(row);
    displacement.push_back({has_dx && has_dz, Eigen::Vector2d(x, z)});
  }
  if (rows.empty() && sink.empty()) {
    sink.Add({path, header_row, 1}, "", "no pose rows after the header");
  }
  // Every pose but the last needs its displacement to the next one.
  for (std::size_t i = 0; i + 1 < displacement.size(); ++i) {
    if (!displacement[i].first) {
      sink.Add({path, rows[i], dx.index + 1}, "",
               "missing the displacement to the next pose (only the last row may omit it)");
    }
    data.displacements.push_back(displacement[i].second);
  }
  sink.ThrowIfAny();
  return data;
}

}  // namespace autoshovel::identification
