#include "runtime/app/plant_step_command.h"

#include <cmath>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <numbers>
#include <random>
#include <sstream>

#include "generated/registry.h"
#include "runtime/core/diagnostics.h"
#include "runtime/core/file_output.h"
#include "runtime/machines/machine_code.h"
#include "runtime/model/description.h"
#include "runtime/plant/plant.h"

namespace autoshovel::app {

namespace {

// A mid-range arm pose (each joint halfway through its range, the boom a little lower) on an
// empty yard: the arm moves freely both ways and no end stop is near.
plant::MachineState StartState(const model::MachineDescription& machine) {
  plant::MachineState state;
  state.q.resize(machine.num_joints());
  for (std::size_t j = 0; j < machine.num_links(); ++j) {
    const model::Link& link = machine.links[j];
    state.q[j] = link.joint_min + 0.45 * (link.joint_max - link.joint_min);
  }
  if (machine.swing) state.q.back() = 0.0;
  return state;
}

}  // namespace

int RunPlantStep(const PlantStepOptions& options, std::ostream& out, std::ostream& err) {
  try {
    const model::MachineDescription machine = model::LoadMachineDescription(
        model::ResolveMachineDescription(options.machine, options.models_dir));
    const generated::MachineFunctions* functions = nullptr;
    try {
      functions = &machines::MachineFunctionsFor(machine);
    } catch (const machines::MachineCodeError& e) {
      err << "autoshovel plant step: " << e.what() << "\n";
      return 2;
    }
    int actuator = -1;
    for (std::size_t a = 0; a < machine.hydraulics.actuators.size(); ++a) {
      // By actuator name ("boom_cylinders") or by the joint it drives ("boom").
      const model::Actuator& act = machine.hydraulics.actuators[a];
      if (act.name == options.actuator) actuator = static_cast<int>(a);
    }
    for (std::size_t a = 0; actuator < 0 && a < machine.hydraulics.actuators.size(); ++a) {
      if (machine.hydraulics.actuators[a].joint == options.actuator) {
        actuator = static_cast<int>(a);
      }
    }
    if (actuator < 0) {
      err << "autoshovel plant step: machine '" << machine.name << "' has no actuator '"
          << options.actuator << "'; it has:";
      for (const auto& act : machine.hydraulics.actuators) {
        err << " " << act.name << " (joint " << act.joint << ")";
      }
      err << "\n";
      return 2;
    }
    if (!std::isfinite(options.amplitude) || std::abs(options.amplitude) > 1.0) {
      err << "autoshovel plant step: --amplitude must be in [-1, 1], got " << options.amplitude
          << "\n";
      return 2;
    }
    if (!(options.sample_rate > 0) || !(options.duration > 0)) {
      err << "autoshovel plant step: --rate and --duration must be > 0\n";
      return 2;
    }

    // A 20 m × 20 m empty yard: the experiment needs no material.
    plant::World world = plant::EmptyYard(machine);
    plant::Plant plant(machine, *functions, world, StartState(machine));

    // The log is composed in memory and written in one checked, atomic write at the end: a
    // full disk or an unwritable path is an error, never a truncated log reported as written.
    std::ostringstream file;
    std::ostream& csv = options.output.empty() ? out : file;
    const int joint = functions->actuator_joint[actuator];
    csv << "# autoshovel plant step: machine " << machine.name << ", actuator " << options.actuator
        << ", " << (options.chirp ? "chirp" : "step") << " amplitude " << options.amplitude
        << ", noise " << (options.noise ? "on" : "off") << ", seed " << options.seed << "\n";
    csv << "# units: s, duty [-1,1], spool [-1,1], Pa, rad, rad/s\n";
    csv << "t,command,spool,pressure,joint_angle,joint_rate\n";
    std::mt19937_64 rng(options.seed);
    std::normal_distribution<double> gauss(0.0, 1.0);
    // Sensor noise of a typical data logger: spool LVDT 0.5 %, pressure transducer 0.1 MPa,
    // angle encoder 0.05°, rate from the gyro 0.2°/s.
    const double noise = options.noise ? 1.0 : 0.0;
    core::ActuatorCommand command;
    command.valve.assign(machine.hydraulics.actuators.size(), 0.0);
    const double dt = 1.0 / options.sample_rate;
    const long samples = std::lround(options.duration * options.sample_rate);
    csv << std::setprecision(9);
    // The true joint (not the noisy column) tells when the arm first moves after the step.
    const double q_start = plant.state().q[joint];
    double motion_time = -1;
    for (long i = 0; i <= samples; ++i) {
      const double t = plant.time();
      double u = 0;
      if (t >= options.step_time - 1e-12) {
        if (options.chirp) {
          const double tau = t - options.step_time;
          const double span = options.duration - options.step_time;
          const double phase = 2 * std::numbers::pi *
                               (options.chirp_f0 * tau +
                                0.5 * (options.chirp_f1 - options.chirp_f0) / span * tau * tau);
          u = options.amplitude * std::sin(phase);
        } else {
          u = options.amplitude;
        }
      }
      command.valve[actuator] = u;
      if (!plant.SetCommand(command)) {
        err << "autoshovel plant step: command refused at t = " << t << "\n";
        return 1;
      }
      const plant::MachineState& s = plant.state();
      csv << t << ',' << u << ',' << s.spool[joint] + noise * 0.005 * gauss(rng) << ','
          << s.pressure_a[joint] + noise * 1e5 * gauss(rng) << ','
          << s.q[joint] + noise * 0.05 * std::numbers::pi / 180 * gauss(rng) << ','
          << s.qd[joint] + noise * 0.2 * std::numbers::pi / 180 * gauss(rng) << '\n';
      if (motion_time < 0 && t >= options.step_time &&
          std::abs(s.q[joint] - q_start) > 0.1 * std::numbers::pi / 180) {
        motion_time = t - options.step_time;
      }
      if (i < samples) plant.Advance(dt);
    }
    if (options.output.empty()) {
      core::FlushStandardOutput();
    } else {
      core::WriteFileAtomically(options.output, file.str());
    }
    // On standard error so that the CSV on standard output stays clean.
    if (!options.chirp) {
      if (motion_time >= 0) {
        err << "command to motion (0.1 deg): " << motion_time << " s\n";
      } else {
        err << "the joint did not move 0.1 deg within the log\n";
      }
    }
    return 0;
  } catch (const core::InputError& e) {
    err << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    err << "autoshovel plant step: " << e.what() << "\n";
    return 1;
  }
}

}  // namespace autoshovel::app
