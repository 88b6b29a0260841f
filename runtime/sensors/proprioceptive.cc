#include "runtime/sensors/proprioceptive.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace autoshovel::sensors {

double TrueImuPitch(const model::MachineDescription& description, const model::Imu& imu,
                    const plant::MachineState& state) {
  const double theta_cab = state.pitch;
  if (imu.body == "chassis") return theta_cab;
  const int k = description.LinkIndex(imu.body);
  if (k < 0) throw std::invalid_argument("IMU '" + imu.name + "': unknown body '" + imu.body + "'");
  if (static_cast<int>(state.q.size()) <= k) {
    throw std::invalid_argument("IMU '" + imu.name + "': the state has too few joints");
  }
  double phi = 0;  // φ_k = q_1 + … + q_k
  for (int j = 0; j <= k; ++j) phi += state.q[j];
  return phi + theta_cab - description.links[k].imu_offset;  // Eq. 1 solved for θ_k
}

ProprioceptiveSensors::ProprioceptiveSensors(const model::MachineDescription& description,
                                             const ProprioceptiveOptions& options)
    : description_(&description), options_(options) {
  for (const auto& imu : description.sensors.imus) biases_.push_back(imu.bias);
}

std::vector<ImuSample> ProprioceptiveSensors::ReadImus(const plant::MachineState& state, Rng& rng) {
  const double dt = started_ ? std::max(0.0, state.time - last_time_) : 0.0;
  started_ = true;
  last_time_ = state.time;
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<ImuSample> samples;
  samples.reserve(biases_.size());
  const auto& imus = description_->sensors.imus;
  for (std::size_t i = 0; i < imus.size(); ++i) {
    const double pitch_noise = gauss(rng), roll_noise = gauss(rng), walk = gauss(rng);
    biases_[i] += options_.imu_bias_random_walk * std::sqrt(dt) * walk;
    ImuSample s;
    s.stamp = state.time;
    s.name = imus[i].name;
    s.pitch = TrueImuPitch(*description_, imus[i], state) + biases_[i] +
              imus[i].angle_noise * pitch_noise;
    s.roll = imus[i].angle_noise * roll_noise;
    samples.push_back(std::move(s));
  }
  return samples;
}

ArticulationSample ProprioceptiveSensors::ReadArticulation(const plant::MachineState& state,
                                                           Rng& rng) const {
  std::normal_distribution<double> gauss(0.0, 1.0);
  return {state.time, state.articulation + options_.encoder_noise * gauss(rng)};
}

PoseSample ProprioceptiveSensors::ReadPose(const plant::MachineState& state, Rng& rng) const {
  double swing = 0;
  if (description_->swing) {
    const std::size_t j = description_->num_links();
    if (state.q.size() <= j) throw std::invalid_argument("ReadPose: the state has no swing joint");
    swing = state.q[j];
  }
  const Eigen::Isometry3d T = state.T_world_cab(swing);
  // Heading of the cab's x axis projected on the ground plane.
  const Eigen::Vector3d x_axis = T.linear().col(0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const double nx = gauss(rng), ny = gauss(rng), nyaw = gauss(rng);
  PoseSample p;
  p.stamp = state.time;
  p.x = T.translation().x() + options_.position_noise * nx;
  p.y = T.translation().y() + options_.position_noise * ny;
  p.yaw = std::remainder(std::atan2(x_axis.y(), x_axis.x()) + options_.yaw_noise * nyaw,
                         2 * std::numbers::pi);
  return p;
}

}  // namespace autoshovel::sensors
