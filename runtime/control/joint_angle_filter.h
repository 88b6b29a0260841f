// Arm joint angles from the bucket and boom IMUs (wheel-loader seed Eq. (1)) through a
// complementary filter: the angle is carried forward by the gyro rate and pulled towards the
// measured angle with gain k each tick,
//   q̂⁻ = q̂ + q̇·Δt,   q̂ = q̂⁻ + k·(q_meas − q̂⁻).
// Why: Eq. (19) counts, for each map cell, the lowest tip that passed over it, and the volume
// trigger fires the first time V1 + V2 crosses V_t. Both are extreme-value statistics of the tip
// height, so white angle noise biases them: at 0.5° on both joints (five times the encoder
// rating, tests/closed_loop/faults_test.cc) the tip height is off by ≈ 3 cm per reading, Eq. (19)
// then over-counts ≈ 0.3 m³ over a 3 m wide cut and the bucket is triggered ≈ 10 % short of full.
// The gyro rate is what the IMU measures best, so carrying the angle by it costs no lag while the
// arm moves (a low-pass on the angle alone would trail a curling bucket by its time constant).
// The steady-state variance of the estimate is k / (2 − k) of the reading's: k = 0.1 at 100 Hz
// keeps 23 % of the noise's σ and follows a reading offset (IMU bias, a stuck sensor) within
// Δt / k = 0.1 s. A steady-state Kalman filter with a random-walk rate model gives the same
// structure; its gain would need the noise level, which is exactly what a fault changes.
#pragma once

namespace autoshovel::control {

class JointAngleFilter {
 public:
  /// `gain` k in (0, 1]: 1 passes the reading through. Throws std::invalid_argument otherwise.
  explicit JointAngleFilter(double gain = 0.1);

  /// One tick of `dt` [s] with the measured angle `angle` [rad] and rate `rate` [rad/s]; returns
  /// the estimate. The first finite reading initialises it. A non-finite angle is skipped (the
  /// estimate is carried by a finite rate, or held); a non-finite rate counts as zero.
  double Update(double angle, double rate, double dt);

  bool initialised() const { return initialised_; }
  double estimate() const { return estimate_; }
  double gain() const { return gain_; }

 private:
  double gain_;
  double estimate_ = 0;
  bool initialised_ = false;
};

}  // namespace autoshovel::control
