// Vehicle stop detection (v ≈ 0 of Algorithm 3), wheel-loader seed §6.2: "In each control cycle,
// if the vehicle speed is below 0.15 m/s, the confidence level increases by (0.1 − v) × 100. When
// the speed exceeds 0.15 m/s, the confidence level is reset to zero. A stopping state is confirmed
// once the confidence level reaches 100."
//
// Our readings where the seed is silent:
//  - v is the magnitude of the forward speed |v| [m/s] (rolling back is not standing still);
//  - for 0.1 < |v| < 0.15 the increment is negative, as written: the confidence decays; it is
//    held at ≥ 0 (a confidence below zero has no meaning and would delay a later stop);
//  - exactly 0.15 m/s counts as "below" (the reset needs the speed to exceed it);
//  - once confirmed, the stop state holds until the confidence is reset by a speed above 0.15;
//  - the cycle is the caller's: ScoopCycle updates it at the 20 Hz state-machine rate, so at
//    v = 0 a stop is confirmed after 10 cycles (0.5 s).
#pragma once

namespace autoshovel::control {

class StopDetector {
 public:
  static constexpr double kResetSpeed = 0.15;            ///< [m/s]
  static constexpr double kReferenceSpeed = 0.1;         ///< in (0.1 − v)·100 [m/s]
  static constexpr double kGainPerMetrePerSecond = 100;  ///< the ×100 [1/(m/s)]
  static constexpr double kStopConfidence = 100;         ///< [-]

  /// One control cycle with the measured speed `speed` [m/s]; returns stopped(). A NaN or
  /// infinite speed is no evidence of anything: the confidence is reset and false returned.
  bool Update(double speed);
  void Reset() { confidence_ = 0; }

  double confidence() const { return confidence_; }
  bool stopped() const { return confidence_ >= kStopConfidence; }

 private:
  double confidence_ = 0;
};

}  // namespace autoshovel::control
