// Loss maps of the machine's power conversion (issue 41, item 2): what the battery (or the
// engine shaft) gives for a wheel torque and speed, and for a pump pressure and flow. They replace
// the flat efficiencies P/η of the energy counters.
//
// Electric drive (traction motor, its inverter and the gearing to the wheels), at motor torque T
// and speed ω (Larminie & Lowry, "Electric Vehicle Technology Explained", Wiley 2003, on motor
// losses and efficiency maps: P_loss = k_c T² + k_i ω + k_w ω³ + C; the Simscape Electrical
// "Motor & Drive (System Level)" block's simplified losses have terms of the same kinds: fixed
// converter, torque-dependent copper, speed-dependent iron):
//
//   P_loss = k_c T²                    copper (stator and rotor), and the inverter's I² r part
//          + k_I |T|                   inverter: switching and on-state drop, ∝ |I| ∝ |T|
//          + C T²/(T² + T_g²)          inverter: gate drives, control (only while it modulates)
//          + k_f |ω|                   bearings, and the gearing's churning (no-load) loss
//          + (k_h |ω| + k_e ω²) ψ²(ω)  iron: hysteresis ∝ f B², eddy currents ∝ f² B²
//          + λ |T ω|                   gear mesh: a fraction of the power transmitted
//   ψ²(ω) = 1/sqrt(1 + (ω/ω_r)⁴)       the flux, squared: constant below the corner speed ω_r,
//                                      ∝ 1/ω² above it (field weakening at constant voltage)
//
// Each |x| is sqrt(x² + ε²) − ε (0 with zero slope at 0, C^∞), so the map is differentiable
// everywhere for CVODE and for an optimiser's dual numbers. The battery gives P = T ω + P_loss:
// when the motor brakes (T ω < 0) it receives |T ω| − P_loss if that is positive
// (PowerLossOptions::credit_regeneration; the counter then decreases).
//
// Calibration: the description's efficiency η is read at the rated (corner) point, T_r = the
// motor's largest torque, ω_r = P_max/T_r: P_loss(T_r, ω_r) = P_max (1/η − 1), divided among the
// terms by ElectricLossSplit. Each coefficient is its share of that loss over its basis function
// at the rated point, so the map gives η there exactly, whatever the regularisation.
//
// Hydraulic pump of every machine (constant shaft speed, variable displacement, load sensing), at
// pump pressure p and delivered flow Q (W. E. Wilson, "Performance criteria for positive
// displacement pumps and fluid motors", Trans. ASME 71, 1949; H. E. Merritt, "Hydraulic Control
// Systems", Wiley 1967; J. Ivantysyn & M. Ivantysynova, "Hydrostatic Pumps and Motors", 2001):
// leakage through the gaps is laminar, Q_L = C_s p; the torque lost is a Coulomb part ∝ p and a
// viscous/churning part that is constant at constant speed:
//
//   P_pump,loss = g(Q) (C_s p² + ω_p C_f |p| + ω_p T_0),   g(Q) = Q²/(Q² + Q_g²)
//
// g gates the losses to the time the pump delivers: with the spools centred (Q = 0) nothing is
// booked, so idle segments stay comparable with the flat model's (a real pump standing by at
// its standby pressure does lose a little; that is left out, on purpose). On an electric machine
// the pump's motor adds the electric map above at its constant speed ω_p with T = P_shaft/ω_p,
// gated the same way. Calibrated so that p_r Q_r / (p_r Q_r + P_loss) = pump_efficiency at the
// rated point: p_r = hydraulics.pump_pressure, Q_r = hydraulics.pump_max_flow if set, else the
// largest rated flow of a valve (the pump sized for the largest single function; without a flow
// limit the plant may ask for more, and the map goes on: its losses do not grow with the flow).
//
// The diesel traction drive keeps its flat η (engine and torque converter are out of scope):
// P = max(T ω, 0)/η, as before.
#pragma once

#include <cmath>
#include <numbers>
#include <optional>
#include <string>

#include "runtime/model/description.h"

namespace autoshovel::plant {

namespace loss_internal {
/// |x| made smooth: sqrt(x² + ε²) − ε: 0 with zero slope at 0, |x| − ε for |x| ≫ ε.
template <typename S>
S SmoothAbs(const S& x, double width) {
  using std::sqrt;
  return sqrt(x * x + width * width) - width;
}
/// max(x, 0) made smooth: (x + sqrt(x² + ε²) − ε)/2: 0 at 0, within ε/2 of max(x, 0).
template <typename S>
S SmoothPositivePart(const S& x, double width) {
  return (x + SmoothAbs(x, width)) / 2.0;
}
}  // namespace loss_internal

/// How an electric drive's loss at its rated point divides among its mechanisms. Each group's
/// fractions sum to 1 (Check says which does not).
struct ElectricLossSplit {
  // Components. Typical rated-point efficiencies: IGBT inverter 0.97, traction motor 0.94, a
  // loader's three reduction stages (transfer gear, axle bevel, hub planetary; about 0.98 each)
  // 0.94; 0.97 · 0.94 · 0.94 = 0.857, close to the 0.85 the 968EV's description gives. The
  // shares are those losses' ratios, 3 : 6 : 6 (estimates, not measurements of the 968EV).
  double motor = 0.4;
  double inverter = 0.2;
  double gearing = 0.4;
  // The motor's loss: the measured split of an 18.5 kW motor at its nominal point (Modelica
  // Standard Library, Electrical.Machines.Examples.InductionMachines.IMC_withLosses: copper
  // 770.13 + 481.60 W, stray load 102.22 W, core 410 W, friction 180 W). A permanent-magnet
  // motor has no rotor copper and relatively more iron loss; the split is a stand-in.
  double motor_copper = 1353.95 / 1943.95;  ///< copper + stray load, ∝ T²
  double motor_core = 410.0 / 1943.95;      ///< iron
  double motor_friction = 180.0 / 1943.95;  ///< bearings and windage, ∝ |ω|
  double core_hysteresis = 0.5;             ///< of the iron loss at ω_r; the rest eddy currents
  // The inverter's loss: an IGBT's on-state loss V_CE0 I + r_CE I² and its switching loss ∝ I
  // (Semikron, "Application Manual Power Semiconductors", 2015) put most of it ∝ |I|; gate
  // drives and control are a small constant.
  double inverter_current = 0.75;  ///< ∝ |T|
  double inverter_ohmic = 0.20;    ///< ∝ T² (joins k_c)
  double inverter_fixed = 0.05;    ///< C, while the inverter modulates
  // The gearing's loss: load-dependent (mesh) and no-load (churning, bearings, seals), as
  // ISO/TR 14179-2 splits a gear drive's loss; at full load the mesh loss dominates.
  double gearing_mesh = 0.8;  ///< λ |T ω|; the rest ∝ |ω|
  /// Regularisation widths, as fractions of the rated torque, speed and power.
  double smoothing = 1e-3;
  /// T_g: torque below which the inverter's constant loss fades, as a fraction of T_r.
  double fixed_loss_torque = 0.02;

  /// Empty when valid, else what is wrong.
  std::string Check() const;
};

/// The pump's loss at its rated point, divided (fractions; each group sums to 1).
struct PumpLossSplit {
  /// On an electric machine, the pump's share of the pump-and-motor loss; the motor and its
  /// inverter take the rest. 0.6: the pump about 0.90 overall at its rated point (Ivantysyn &
  /// Ivantysynova's axial-piston maps reach about 0.9), the motor with its inverter about 0.94
  /// (docs/energy_audit.md: "adds 5–10 %"); 0.90 · 0.94 ≈ 0.85.
  double pump = 0.6;
  // The pump: volumetric (leakage) against hydromechanical (torque) loss. At rated pressure an
  // axial piston pump's volumetric efficiency is about 0.95–0.97 and its hydromechanical about
  // 0.93–0.95; most of the torque loss is pressure-dependent (Coulomb) at full pressure.
  double leakage = 0.4;             ///< C_s p²
  double pressure_friction = 0.42;  ///< ω_p C_f |p|
  double constant_friction = 0.18;  ///< ω_p T_0
  /// Q_g of the delivery gate g(Q), as a fraction of the rated flow.
  double delivery_gate = 0.01;
  /// Regularisation width of |p|, as a fraction of the rated pressure.
  double smoothing = 1e-3;

  std::string Check() const;
};

struct PowerLossOptions {
  /// False: the flat efficiencies, P/η (what the plant did before the maps).
  bool loss_maps = true;
  /// An electric drive braking with its motor feeds the battery |T ω| − P_loss, and the travel
  /// counter decreases by it. False: that energy is dissipated (a brake resistor) and booked as
  /// "motor braking, not recovered".
  bool credit_regeneration = true;
  ElectricLossSplit traction;
  /// The pump's motor drives the pump directly: no gearing.
  ElectricLossSplit pump_motor{.motor = 2.0 / 3.0, .inverter = 1.0 / 3.0, .gearing = 0.0};
  PumpLossSplit pump;
  /// ω_p, the pump's (and its motor's) constant speed [rad/s]. At constant speed the map does
  /// not depend on its value (T = P/ω_p at the rated point and everywhere else): 1500 rpm.
  double pump_speed = 50 * std::numbers::pi;

  std::string Check() const;
};

/// The electric map P_loss(T, ω) of one motor with its inverter (and gearing), see above.
struct ElectricLossMap {
  double rated_torque = 0;                                    ///< T_r [N·m]
  double rated_speed = 0;                                     ///< ω_r [rad/s]
  double copper = 0;                                          ///< k_c [W/(N·m)²]
  double current = 0;                                         ///< k_I [W/(N·m)]
  double fixed = 0;                                           ///< C [W]
  double friction = 0;                                        ///< k_f [W/(rad/s)]
  double hysteresis = 0;                                      ///< k_h [W/(rad/s)]
  double eddy = 0;                                            ///< k_e [W/(rad/s)²]
  double mesh = 0;                                            ///< λ [-]
  double torque_width = 0, speed_width = 0, power_width = 0;  ///< ε of |T|, |ω|, |T ω|
  double fixed_torque = 0;                                    ///< T_g [N·m]

  /// P_loss [W] at motor torque T [N·m] and speed ω [rad/s]; never negative.
  template <typename S>
  S Loss(const S& torque, const S& speed) const {
    using loss_internal::SmoothAbs;
    using std::sqrt;
    const S t2 = torque * torque;
    const S x = speed / rated_speed;
    const S flux2 = 1.0 / sqrt(1.0 + x * x * x * x);
    const S abs_speed = SmoothAbs(speed, speed_width);
    return copper * t2 + current * SmoothAbs(torque, torque_width) +
           fixed * t2 / (t2 + fixed_torque * fixed_torque) + friction * abs_speed +
           (hysteresis * abs_speed + eddy * speed * speed) * flux2 +
           mesh * SmoothAbs(S(torque * speed), power_width);
  }
  /// T ω / (T ω + P_loss) for T ω > 0 [-].
  double Efficiency(double torque, double speed) const {
    const double out = torque * speed;
    return out / (out + Loss(torque, speed));
  }
};

/// Calibrates the map: P_loss(T_r, ω_r) = T_r ω_r (1/η − 1), shared by `split`. Throws
/// std::invalid_argument naming the bad value.
ElectricLossMap MakeElectricLossMap(double rated_torque, double rated_speed, double efficiency,
                                    const ElectricLossSplit& split);

/// Power drawn by the travel drive and where it goes: drawn = T ω + loss + not_recovered [W].
template <typename S>
struct TravelPowerSplit {
  S drawn;          ///< from the battery (electric) or the engine shaft (diesel)
  S loss;           ///< motor, inverter and drivetrain
  S not_recovered;  ///< braking power the battery does not get (dissipated)
};

/// The travel drive of a wheel loader: the electric map at the motor, or the diesel's flat η.
class TravelDriveLosses {
 public:
  TravelDriveLosses(const model::MachineDescription& machine, const PowerLossOptions& options);

  /// At wheel torque T_wheel [N·m] and wheel speed ω [rad/s] (drive.h).
  template <typename S>
  TravelPowerSplit<S> Evaluate(const S& wheel_torque, const S& wheel_speed) const {
    const S wheel_power = wheel_torque * wheel_speed;
    if (!map_) {
      // Flat: max(T ω, 0)/η; motor braking is not recovered.
      const S driving = wheel_power > 0.0 ? wheel_power : S(0.0);
      const S drawn = driving / efficiency_;
      return {drawn, S(drawn - driving), S(driving - wheel_power)};
    }
    const S loss = map_->Loss(S(wheel_torque / gear_ratio_), S(wheel_speed * gear_ratio_));
    const S net = wheel_power + loss;
    if (credit_regeneration_) return {net, loss, S(0.0)};
    const S drawn = loss_internal::SmoothPositivePart(net, kRegenerationWidth);
    return {drawn, loss, S(drawn - net)};
  }

  /// True when the drawn power can be negative (an electric map crediting regeneration).
  bool can_regenerate() const { return map_ && credit_regeneration_; }
  /// The motor's map (electric drives with loss maps), else nullptr.
  const ElectricLossMap* map() const { return map_ ? &*map_ : nullptr; }
  double gear_ratio() const { return gear_ratio_; }

 private:
  static constexpr double kRegenerationWidth = 1.0;  ///< [W]
  std::optional<ElectricLossMap> map_;
  double gear_ratio_ = 1;
  double efficiency_ = 1;  ///< flat η
  bool credit_regeneration_ = true;
};

/// The hydraulic pump (and, on an electric machine, its motor): P_drawn = p Q + P_loss(p, Q).
class HydraulicLosses {
 public:
  HydraulicLosses(const model::MachineDescription& machine, const PowerLossOptions& options);

  /// P_loss [W] at pump pressure p [Pa] and delivered flow Q [m³/s]: the pump's and its
  /// motor's.
  template <typename S>
  S Loss(const S& pressure, const S& flow) const {
    const S pump = PumpLoss(pressure, flow);
    if (!maps_ || !motor_) return pump;
    const S shaft_torque = (pressure * flow + pump) / pump_speed_;
    return pump + Gate(flow) * motor_->Loss(shaft_torque, S(pump_speed_));
  }
  /// P_drawn = p Q + P_loss [W].
  template <typename S>
  S Drawn(const S& pressure, const S& flow) const {
    return pressure * flow + Loss(pressure, flow);
  }
  /// The pump's own loss [W] (without its motor's; with the flat η, the whole loss).
  template <typename S>
  S PumpLoss(const S& pressure, const S& flow) const {
    if (!maps_) return pressure * flow * (1.0 / efficiency_ - 1.0);
    return Gate(flow) * (leakage_ * pressure * pressure +
                         pressure_friction_ * loss_internal::SmoothAbs(pressure, pressure_width_) +
                         constant_friction_);
  }
  /// g(Q) = Q²/(Q² + Q_g²): the losses only while the pump delivers.
  template <typename S>
  S Gate(const S& flow) const {
    const S q2 = flow * flow;
    return q2 / (q2 + gate_flow_ * gate_flow_);
  }

  double rated_pressure() const { return rated_pressure_; }  ///< p_r [Pa]
  double rated_flow() const { return rated_flow_; }          ///< Q_r [m³/s]
  const ElectricLossMap* motor() const { return motor_ ? &*motor_ : nullptr; }

 private:
  bool maps_ = true;
  double efficiency_ = 1;  ///< flat η
  double rated_pressure_ = 0, rated_flow_ = 0;
  double leakage_ = 0;            ///< C_s [m³/(s·Pa)]
  double pressure_friction_ = 0;  ///< ω_p C_f [W/Pa]
  double constant_friction_ = 0;  ///< ω_p T_0 [W]
  double gate_flow_ = 0;          ///< Q_g [m³/s]
  double pressure_width_ = 0;     ///< [Pa]
  double pump_speed_ = 0;         ///< ω_p [rad/s]
  std::optional<ElectricLossMap> motor_;
};

}  // namespace autoshovel::plant
