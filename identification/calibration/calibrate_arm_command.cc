#include "identification/calibration/calibrate_arm_command.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>

#include "generated/registry.h"
#include "identification/calibration/arm_calibration_csv.h"
#include "identification/common/overlay_file.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/model/interpreted_model.h"
#include "runtime/plot/bar_chart.h"

namespace autoshovel::identification {

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// Seven poses spread over the joint ranges (§7.1), IMU noise 0.1°, rangefinder noise 5 mm.
void Simulate(const model::MachineDescription& machine, const std::string& path,
              unsigned long long seed) {
  const model::InterpretedModel reference(machine);
  const std::vector<double> params = reference.NominalParams();
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double boom_plan[] = {0.05, 0.95, 0.5, 0.2, 0.8, 0.35, 0.65};
  const double other_plan[] = {0.9, 0.1, 0.5, 0.15, 0.85, 0.7, 0.3};
  // Composed in memory, then one checked atomic write (core/file_output.h).
  std::ostringstream out;
  out << "# simulated by autoshovel calibrate arm --simulate: machine " << machine.name << ", seed "
      << seed << ", IMU noise 0.1 deg, rangefinder noise 5 mm\n";
  out << "theta_cab_deg";
  for (const auto& link : machine.links) out << ",theta_" << link.name << "_deg";
  out << ",dx_m,dz_m\n";
  std::vector<std::vector<double>> rows;
  std::vector<Eigen::Vector4d> tips;
  for (int i = 0; i < 7; ++i) {
    std::vector<double> q(machine.num_joints(), 0.0);
    for (std::size_t j = 0; j < machine.num_links(); ++j) {
      const auto& link = machine.links[j];
      q[j] =
          link.joint_min + (j == 0 ? boom_plan : other_plan)[i] * (link.joint_max - link.joint_min);
    }
    std::vector<double> angles = reference.AnglesFromJoints(q.data(), params.data());
    for (std::size_t k = 0; k <= machine.num_links(); ++k) angles[k] += 0.1 * kDeg * gauss(rng);
    angles.resize(machine.num_links() + 1);
    rows.push_back(angles);
    tips.push_back(reference.TipFromJoints(q.data()));
  }
  char cell[64];
  for (std::size_t i = 0; i < rows.size(); ++i) {
    for (std::size_t k = 0; k < rows[i].size(); ++k) {
      std::snprintf(cell, sizeof cell, "%s%.4f", k ? "," : "", rows[i][k] / kDeg);
      out << cell;
    }
    if (i + 1 < rows.size()) {
      const Eigen::Vector4d d = tips[i] - tips[i + 1];
      std::snprintf(cell, sizeof cell, ",%.4f,%.4f", d.x() + 0.005 * gauss(rng),
                    d.z() + 0.005 * gauss(rng));
      out << cell;
    } else {
      out << ",,";
    }
    out << "\n";
  }
  core::WriteFileAtomically(path, out.str());
}

}  // namespace

int RunCalibrateArm(const CalibrateArmOptions& options, std::ostream& out, std::ostream& err) {
  try {
    const model::MachineDescription machine = model::LoadMachineDescription(
        model::ResolveMachineDescription(options.machine, options.models_dir));
    if (!options.simulate.empty()) {
      Simulate(machine, options.simulate, options.seed);
      out << "simulated measurements: " << options.simulate << "\n";
      return 0;
    }
    const generated::MachineFunctions* functions = nullptr;
    try {
      functions = &machines::MachineFunctionsFor(machine);
    } catch (const machines::MachineCodeError& e) {
      err << "autoshovel calibrate arm: " << e.what() << "\n";
      return 2;
    }
    if (machine.swing) {
      err << "autoshovel calibrate arm: " << machine.name
          << " has a swing joint; calibrate it with the swing at zero (not supported yet)\n";
      return 2;
    }
    std::vector<std::string> links;
    for (const auto& link : machine.links) links.push_back(link.name);
    const ArmCalibrationData data = ReadArmCalibrationCsv(options.data, links);
    std::vector<double> initial = options.initial;
    const int n = functions->num_links;
    if (!initial.empty()) {
      if (static_cast<int>(initial.size()) != 2 * n) {
        err << "autoshovel calibrate arm: --initial needs " << 2 * n
            << " values (lengths in m, then offsets in deg)\n";
        return 2;
      }
      for (int k = 0; k < n; ++k) initial[n + k] *= kDeg;
    }
    const ArmCalibrationResult r = CalibrateArm(*functions, data, initial);
    if (!r.ok) {
      err << options.data << ": degenerate data: " << r.degenerate << "; nothing written\n";
      return 1;
    }
    char line[200];
    out << "arm calibration of " << machine.name << " from " << options.data << " ("
        << data.angles.size() << " poses)\n";
    out << "  parameter          nominal     calibrated   1-sigma\n";
    for (int k = 0; k < n; ++k) {
      std::snprintf(line, sizeof line, "  l_%d (%-8s)  %9.4f m  %9.4f m  %7.4f m\n", k + 1,
                    links[k].c_str(), functions->nominal_params[k], r.params[k], r.std_dev[k]);
      out << line;
    }
    for (int k = 0; k < n; ++k) {
      std::snprintf(line, sizeof line, "  alpha_%d         %9.3f deg %9.3f deg %7.3f deg\n", k + 1,
                    functions->nominal_params[n + k] / kDeg, r.params[n + k] / kDeg,
                    r.std_dev[n + k] / kDeg);
      out << line;
    }
    double rms = 0;
    for (const auto& res : r.residuals) rms += res.squaredNorm();
    rms = std::sqrt(rms / std::max<std::size_t>(1, r.residuals.size()));
    std::snprintf(line, sizeof line,
                  "  residual RMS %.2f mm, gradient inf-norm %.1e, condition number %.1f, "
                  "%d iterations\n",
                  1e3 * rms, r.gradient_max_norm, r.condition_number, r.iterations);
    out << line;

    const std::string overlay =
        options.overlay.empty() ? options.data + ".overlay.yaml" : options.overlay;
    std::string text = OverlayHeader(machine, "autoshovel calibrate arm " + options.data) +
                       "# 1-sigma in comments.\narm:\n  links:\n";
    for (int k = 0; k < n; ++k) {
      std::snprintf(line, sizeof line,
                    "    - name: %s\n      length: %.5f          # m, +/- %.5f\n"
                    "      imu_offset_deg: %.4f   # +/- %.4f\n",
                    links[k].c_str(), r.params[k], r.std_dev[k], r.params[n + k] / kDeg,
                    r.std_dev[n + k] / kDeg);
      text += line;
    }
    WriteFileAtomically(overlay, text);
    // Residuals per displacement, at the start and calibrated, each on its own scale.
    plot::BarChart before, after;
    before.title = machine.name + ": tip displacement residuals at the start";
    after.title = machine.name + ": tip displacement residuals, calibrated";
    before.unit = after.unit = "mm";
    plot::BarSeries before_x{"x", {}, {200, 120, 40}}, before_z{"z", {}, {40, 80, 220}};
    plot::BarSeries after_x = before_x, after_z = before_z;
    for (std::size_t i = 0; i < r.residuals.size(); ++i) {
      before.groups.push_back("pose " + std::to_string(i + 1) + "-" + std::to_string(i + 2));
      before_x.values.push_back(1e3 * r.initial_residuals[i].x());
      before_z.values.push_back(1e3 * r.initial_residuals[i].y());
      after_x.values.push_back(1e3 * r.residuals[i].x());
      after_z.values.push_back(1e3 * r.residuals[i].y());
    }
    after.groups = before.groups;
    before.series = {before_x, before_z};
    after.series = {after_x, after_z};
    const std::string png = options.png.empty() ? overlay + ".png" : options.png;
    plot::WriteBarChartsPng({before, after}, png);
    out << "residuals: " << png << "\n";
    out << "overlay: " << overlay << "\n";
    return 0;
  } catch (const core::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "autoshovel calibrate arm: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace autoshovel::identification
