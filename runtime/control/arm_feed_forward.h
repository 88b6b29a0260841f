// Feed-forward for holding the bucket's attitude while the boom moves (wheel-loader seed §6.2:
// the bucket is lifted out of the pile racked back, then levelled and carried).
//
// The attitude in the arm plane is q_boom + q_bucket, and the bucket joint is relative to the
// boom, so holding it while the boom rises means q̇_bucket = −q̇_boom. A feedback loop alone
// cannot: both valves answer ~0.6 s after their command (transport delay + spool lag), and in
// that time a full-speed boom (≈0.2 rad/s) tips the bucket back by ≈0.1 rad, past the angle at
// which its heap stays (bucket_terrain.cc HoldableVolume) — the pushing scoop lost 0.22 m³ of a
// full sand load that way. Commanding the tilt valve from the boom valve's *demand* instead
// starts both motions together, because the two valves share their delays.
//
// The valve model is the machine's load-sensing hydraulics: each section's compensator keeps its
// spool's drop at the margin, the largest rated drop of the machine's valves (as the plant does,
// plant.cc LoadSensing), so a spool open by x ∈ [−1, 1] passes x·Q_full (Q_rated when rated at
// the margin) into the cap side (x > 0, extending, area A_cap) or the rod side
// (x < 0, retracting, A_rod): L̇ = x·Q_full / A. Joint rates follow from the generated cylinder
// lengths: L̇ = Σ_k ∂L/∂q_k · q̇_k (central differences of generated cylinder_length; a Z-bar's
// tilt cylinder may be mounted on the chassis, making its length depend on the boom too).
#pragma once

#include <deque>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/model/description.h"

namespace autoshovel::control {

class AttitudeHoldFeedForward {
 public:
  /// A two-link loader arm (boom joint 0, bucket joint 1) with a cylinder on each joint. Throws
  /// std::invalid_argument otherwise or when a valve's rated flow or a cylinder's bore is not
  /// positive. `functions` must outlive this object.
  AttitudeHoldFeedForward(const model::MachineDescription& machine,
                          const generated::MachineFunctions& functions);

  /// Joint rate [rad/s] of joint `joint` (0 boom, 1 bucket) that its spool opening `demand`
  /// ∈ [−1, 1] gives at arm angles q = {q_boom, q_bucket} [rad] while the other joint stands
  /// still.
  double JointRate(int joint, double demand, const std::vector<double>& q) const;

  /// Σ JointRate(joint, opening, q)·dt over `openings` [rad]: how far the openings sent and not
  /// yet acting will move the joint. One length gradient for all of them (the Smith predictor
  /// sums a valve delay's worth of openings every control tick).
  double JointTravel(int joint, const std::deque<double>& openings, const std::vector<double>& q,
                     double dt) const;

  /// q̇_bucket per q̇_boom with the tilt cylinder standing still [-]: 0 when the tilt cylinder
  /// rides on the boom, nonzero for one mounted on the chassis.
  double PassiveBucketPerBoom(const std::vector<double>& q) const;

  /// Tilt spool opening ∈ [−1, 1] that turns the bucket at −q̇_boom (constant attitude) while the
  /// boom moves at the rate `boom_demand` gives; 0 for non-finite inputs.
  double BucketDemand(double boom_demand, const std::vector<double>& q) const;

  /// The spool opening a valve duty `duty` ∈ [−1, 1] gives past the valve's dead zone (the
  /// machine's rule, plant/valve_command.h ApplyDeadZone), for actuator of `joint`.
  double OpeningOfDuty(int joint, double duty) const;

  /// Seconds by which the boom valve answers later than the tilt valve (transport delay +
  /// spool time constant), ≥ 0: the boom demand to use is the one issued this long ago.
  double boom_lag() const { return boom_lag_; }

 private:
  /// The cylinder driving a joint, as the valve model sees it.
  struct Cylinder {
    int actuator = -1;
    double cap_area = 0, rod_area = 0;  ///< all cylinders of the actuator together [m²]
    double full_flow = 0;               ///< at a fully open spool [m³/s]
    double dead_zone = 0;               ///< of its valve [-]
  };

  /// ∂L/∂q_joint of `actuator` at q [m/rad].
  double LengthGradient(int actuator, int joint, const std::vector<double>& q) const;
  /// Cylinder length rate [m/s] of a spool opening x, and its inverse.
  static double LengthRateOfOpening(const Cylinder& cylinder, double opening);
  static double OpeningOfLengthRate(const Cylinder& cylinder, double length_rate);
  const Cylinder& CylinderOf(int joint) const;

  const generated::MachineFunctions& functions_;
  Cylinder boom_, bucket_;
  double boom_lag_ = 0;
};

}  // namespace autoshovel::control
