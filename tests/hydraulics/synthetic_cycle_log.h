// A long boom log made from the valve model itself (valve_model.h), cheap enough for tests and
// benchmarks of any length: steps of 30, 60 and 100 % up then down in each 8 s, the cylinder
// held at its stroke ends (an end stop) when the flow would carry it past them, so that the
// log has a segment between end-stop contacts every few cycles. Noise: 0.05 deg on the angle,
// 0.5 % on the spool, deterministic.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>

#include "identification/hydraulics/log_reader.h"
#include "identification/hydraulics/valve_model.h"

namespace autoshovel::identification::testing {

inline double CycleCommand(double t) {
  const double levels[] = {0.3, 0.6, 1.0};
  const int k = static_cast<int>(std::floor(t / 8.0));
  const double phase = t - 8.0 * k;
  const double level = levels[k % 3];
  // 3.5 s each way: at 60 and 100 % the retraction (the faster, on the annulus) runs into the
  // retracted end stop, and the extension starts a new segment from there.
  if (phase < 0.5) return 0.0;
  if (phase < 4.0) return level;
  if (phase < 4.5) return 0.0;
  return -level;
}

inline HydraulicLog SyntheticCycleLog(const ActuatorKinematics& kinematics,
                                      const ValveParameters& truth, std::size_t rows,
                                      unsigned seed = 1) {
  HydraulicLog log;
  log.file = "synthetic_cycle_" + std::to_string(rows);
  for (std::size_t j = 0; j < rows; ++j) {
    log.row.push_back(static_cast<int>(j) + 2);
    log.time.push_back(0.01 * static_cast<double>(j));
    log.command.push_back(CycleCommand(log.time.back()));
  }
  std::mt19937 random(seed);
  std::normal_distribution<double> angle_noise(0.0, 0.05 * 3.141592653589793 / 180);
  std::normal_distribution<double> spool_noise(0.0, 0.005);
  double length = 0.5 * (kinematics.length_min() + kinematics.length_max());
  double last_positive = 0, last_negative = 0;
  log.joint_angle.resize(rows);
  log.spool.resize(rows);
  ForEachValveSample(
      log.time, log.command, rows, [&](std::size_t j) { return log.time[j]; }, truth.dead_zone,
      truth.transport_delay, truth.spool_time_constant,
      [&](std::size_t j, double x, double positive, double negative) {
        length += truth.rated_flow * ((positive - last_positive) / kinematics.area_extend() +
                                      (negative - last_negative) / kinematics.area_retract());
        length = std::clamp(length, kinematics.length_min(), kinematics.length_max());
        last_positive = positive, last_negative = negative;
        log.joint_angle[j] = kinematics.Angle(length) + angle_noise(random);
        log.spool[j] = x + spool_noise(random);
      });
  return log;
}

}  // namespace autoshovel::identification::testing
