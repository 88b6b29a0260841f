// Simulated proprioceptive sensors: the arm and cab IMUs, the articulation encoder and the
// localisation of the cab, measured from the plant's true state.
//
// IMU model (wheel-loader seed Eq. 1, φ_k = θ_k − θ_cab + α_k). Link angles in frame M: φ_1 = q_1,
// φ_k = φ_{k−1} + q_k. An IMU on link k reads the pitch of its own axis, which is mounted α_k
// off the link line: θ_k = φ_k + θ_cab − α_k. The cab IMU reads θ_cab = the chassis pitch
// (plant::MachineState::pitch, nose up positive). Roll is 0 in the planar plant. Each reading
// adds the IMU's bias b (description `bias_deg`) and white noise of σ = `angle_noise_deg`:
// θ̃ = θ + b + n. The bias may drift as a random walk, b(t + Δt) = b(t) + σ_b·√Δt·N(0, 1), with
// σ_b = ProprioceptiveOptions::imu_bias_random_walk [rad/√s] (default 0: a constant bias, as
// the calibration of the seed's Eq. 3 assumes).
//
// Articulation encoder: γ + N(0, σ_γ), σ_γ = 0.1° by default (a 12-bit absolute encoder on the
// hinge pin: 0.09° resolution).
// Localisation: the cab frame's x, y and yaw with independent Gaussian errors, 2 cm per axis and
// 0.2° by default (RTK-GNSS with a dual-antenna heading, fix solution).
#pragma once

#include <numbers>
#include <vector>

#include "runtime/model/description.h"
#include "runtime/plant/machine_state.h"
#include "runtime/sensors/rng.h"
#include "runtime/sensors/sensor_data.h"

namespace autoshovel::sensors {

struct ProprioceptiveOptions {
  double imu_bias_random_walk = 0;                      ///< σ_b [rad/√s]
  double encoder_noise = 0.1 * std::numbers::pi / 180;  ///< 1σ [rad]
  double position_noise = 0.02;                         ///< 1σ per axis [m]
  double yaw_noise = 0.2 * std::numbers::pi / 180;      ///< 1σ [rad]
};

/// Noise-free, bias-free pitch θ an IMU of the description sees in `state` (Eq. 1). Throws
/// std::invalid_argument when the IMU's body is unknown or state.q has too few joints.
double TrueImuPitch(const model::MachineDescription& description, const model::Imu& imu,
                    const plant::MachineState& state);

/// The IMUs, the encoder and the localisation of one machine. Holds the IMU biases (which
/// drift when the random walk is on), so one instance follows one machine through time.
class ProprioceptiveSensors {
 public:
  explicit ProprioceptiveSensors(const model::MachineDescription& description,
                                 const ProprioceptiveOptions& options = {});
  /// The sensors refer to the description: a temporary would dangle.
  explicit ProprioceptiveSensors(model::MachineDescription&& description,
                                 const ProprioceptiveOptions& options = {}) = delete;

  /// One reading of every IMU of the description, in description order, stamped state.time.
  /// Advances the bias random walk by the time since the previous call. Draws three normal
  /// variates per IMU (pitch noise, roll noise, bias step).
  std::vector<ImuSample> ReadImus(const plant::MachineState& state, Rng& rng);
  /// Draws one normal variate.
  ArticulationSample ReadArticulation(const plant::MachineState& state, Rng& rng) const;
  /// The cab frame (excavators: the upper structure at the swing joint's angle). Draws three
  /// normal variates (x, y, yaw).
  PoseSample ReadPose(const plant::MachineState& state, Rng& rng) const;

  /// Current bias of each IMU [rad].
  const std::vector<double>& imu_biases() const { return biases_; }
  const ProprioceptiveOptions& options() const { return options_; }

 private:
  const model::MachineDescription* description_;
  ProprioceptiveOptions options_;
  std::vector<double> biases_;
  double last_time_ = 0;
  bool started_ = false;
};

}  // namespace autoshovel::sensors
