#include "runtime/plant/plant.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "runtime/model/interpreted_model.h"
#include "runtime/plant/earthmoving.h"
#include "runtime/plant/energy_audit.h"

namespace autoshovel::plant {

namespace {

/// Dead band of a pressure compensator [Pa].
constexpr double kCompensatorBand = 2e5;

struct Layout {
  int joints = 0;
  int arm = 0;  // 5J
  int speed() const { return arm; }
  int wheel() const { return arm + 1; }
  int throttle() const { return arm + 2; }
  int x() const { return arm + 3; }
  int y() const { return arm + 4; }
  int heading() const { return arm + 5; }
  int articulation() const { return arm + 6; }
  int travel_energy() const { return arm + 7; }
  int hydraulic_energy() const { return arm + 8; }
  // Pilot lag states π, one per actuator whose valve has a pilot stage (valve_command.h), after
  // everything else: a machine without pilot stages keeps the state vector it always had.
  int pilots = 0;
  int pilot(int k) const { return arm + 9 + k; }
  int size() const { return arm + 9 + pilots; }
};

// Link frame origins in M (n + 1, the last is the tip) and link angles, Eq. (2).
void ArmGeometry(const model::MachineDescription& machine, const double* q,
                 std::vector<Eigen::Vector2d>& origins, std::vector<double>& angles) {
  const int n = static_cast<int>(machine.links.size());
  origins.assign(n + 1, Eigen::Vector2d::Zero());
  angles.assign(n, 0.0);
  double phi = 0;
  for (int k = 0; k < n; ++k) {
    phi += q[k];
    angles[k] = phi;
    origins[k + 1] =
        origins[k] + machine.links[k].length * Eigen::Vector2d(std::cos(phi), std::sin(phi));
  }
}

}  // namespace

// The ODE system of one machine: generated arm right-hand side plus drive, steering kinematics,
// cutting resistance and energy quadratures, with the inputs held over a segment.
class Plant::System : public OdeSystem {
 public:
  struct Held {
    std::vector<double> spool_reference;  // per joint (0 for a joint whose valve has a pilot stage)
    std::vector<double> pilot_input;      // per joint: delayed command into the pilot lag, or 0
    double drive = 0, brake = 0, articulation_rate = 0;
    double payload = 0;
    std::vector<double> section_supply;  // per joint's valve section, after its compensator [Pa]
    double pump_pressure = 0;            // load-sensing pump output [Pa]
    ResistanceState resistance;          // magnitudes held over the segment
    // A discrete event: a command reaching the machine, or the bucket entering or leaving
    // the material. The other held inputs (payload, resistance magnitudes, compensated supply
    // pressures) are samples of quantities that vary continuously with the state; they are
    // updated at every tick without restarting the integrator's history.
    bool IsEventAgainst(const Held& o) const {
      return spool_reference != o.spool_reference || pilot_input != o.pilot_input ||
             drive != o.drive || brake != o.brake || articulation_rate != o.articulation_rate ||
             resistance.in_contact != o.resistance.in_contact ||
             resistance.cut_side != o.resistance.cut_side;
    }
  };

  System(const model::MachineDescription& machine, const generated::MachineFunctions& functions,
         const PlantOptions& options)
      : machine_(machine),
        functions_(functions),
        options_(options),
        travel_losses_(machine, options.losses),
        hydraulic_losses_(machine, options.losses) {
    layout_.joints = functions.num_joints;
    layout_.arm = functions.num_states;
    pilot_state_.assign(layout_.joints, -1);
    for (int a = 0; a < functions.num_actuators; ++a) {
      if (!HasPilotStage(machine.hydraulics.actuators[a].valve)) continue;
      pilot_state_[functions.actuator_joint[a]] = layout_.pilot(layout_.pilots++);
    }
    held_.spool_reference.assign(layout_.joints, 0.0);
    held_.pilot_input.assign(layout_.joints, 0.0);
    u_.assign(functions.num_inputs, 0.0);
    arm_rhs_.assign(layout_.arm, 0.0);
    arm_jacobian_.assign(static_cast<std::size_t>(layout_.arm) * layout_.arm, 0.0);
    is_loader_ = machine.kind == model::MachineKind::kWheelLoader;
    if (options.energy_audit) audit_model_ = std::make_unique<model::InterpretedModel>(machine);
  }

  int size() const override { return layout_.size(); }
  int quadrature_size() const override { return audit_model_ ? kEnergyTermCount : 0; }
  void Quadrature(double, const double* y, double* integrand) override {
    const EnergyAudit powers = AuditPowers(y);
    std::copy(powers.terms.begin(), powers.terms.end(), integrand);
  }
  const Layout& layout() const { return layout_; }
  Held& held() { return held_; }
  bool can_regenerate() const { return is_loader_ && travel_losses_.can_regenerate(); }

  struct Outputs {
    Eigen::Vector2d tip_force = Eigen::Vector2d::Zero();  // on the bucket, base x–z [N]
    DriveRates drive;
    double hydraulic_power = 0;
  };

  // Inputs of the generated arm model at state y (external torques from the resistance).
  Eigen::Vector2d FillArmInputs(const double* y) {
    const int J = layout_.joints;
    const int n = static_cast<int>(machine_.links.size());
    for (int j = 0; j < J; ++j) {
      // With a pilot stage the spool reference follows the pilot state through the opening law.
      u_[j] = pilot_state_[j] < 0
                  ? held_.spool_reference[j]
                  : ValveOpening(machine_.hydraulics.actuators[actuator_of_joint(j)].valve,
                                 y[pilot_state_[j]]);
      u_[J + j] = 0.0;
    }
    u_[2 * J] = held_.payload;
    u_[2 * J + 1] = 0.0;  // the yard floor is level: frame M is not pitched
    for (int j = 0; j < J; ++j) u_[2 * J + 2 + j] = held_.section_supply[j];
    const ResistanceState& R = held_.resistance;
    if (!R.in_contact) return Eigen::Vector2d::Zero();
    const double* q = y;
    const double* qd = y + J;
    ArmGeometry(machine_, q, origins_, angles_);
    const Eigen::Vector2d tip = origins_[n];
    Eigen::Vector2d tip_velocity(is_loader_ ? y[layout_.speed()] : 0.0, 0.0);
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d r = tip - origins_[j];
      tip_velocity += Eigen::Vector2d(-r.y(), r.x()) * qd[j];
    }
    const double eps = options_.resistance_speed;
    const double c = R.cut_side;
    const double sign_s = c * tip_velocity.x() / std::hypot(tip_velocity.x(), eps);
    const double sign_z = tip_velocity.y() / std::hypot(tip_velocity.y(), eps);
    const Eigen::Vector2d force(
        -sign_s * c * (sign_s > 0 ? R.cut : R.withdraw),
        -sign_z * (sign_z > 0 ? R.lift : R.cut) - R.press * std::max(sign_s, 0.0));
    for (int j = 0; j < n; ++j) {
      const Eigen::Vector2d r = tip - origins_[j];
      u_[J + j] = Eigen::Vector2d(-r.y(), r.x()).dot(force);  // τ = Jᵀ F
    }
    return force;
  }

  Outputs Evaluate(const double* y, double* ydot) {
    Outputs out;
    out.tip_force = FillArmInputs(y);
    functions_.plant_rhs(0.0, y, u_.data(), ydot);
    EvaluateRest(y, out, ydot);
    return out;
  }

  void EvaluateRest(const double* y, Outputs& out, double* ydot) {
    const int J = layout_.joints;
    // Hydraulic power: the pump's pressure times the flow it delivers into the chambers.
    double flow = 0;
    const double pump = held_.pump_pressure;
    for (int j = 0; j < J; ++j) {
      const model::Actuator& act = machine_.hydraulics.actuators[actuator_of_joint(j)];
      const double xs = y[2 * J + j], pa = y[3 * J + j], pb = y[4 * J + j];
      const double supply = held_.section_supply[j];
      using model::internal::OrificeRoot;
      using model::internal::SmoothPositive;
      constexpr double kCheck = model::plant::kCheckValveWidth;
      const double in_a = act.valve.flow_gain * SmoothPositive(xs, model::plant::kSpoolUnderlap) *
                          OrificeRoot(SmoothPositive(supply - pa, kCheck));
      const double in_b = act.valve.flow_gain * SmoothPositive(-xs, model::plant::kSpoolUnderlap) *
                          OrificeRoot(SmoothPositive(supply - pb, kCheck));
      flow += std::max(in_a, 0.0) + std::max(in_b, 0.0);
    }
    out.hydraulic_power = hydraulic_losses_.Drawn(pump, flow);
    ydot[layout_.hydraulic_energy()] = out.hydraulic_power;
    // Pilot lags: T_p π̇ = u(t − τ_p − τ_d) − π (the delayed command is held per segment).
    for (int j = 0; j < J; ++j) {
      const int k = pilot_state_[j];
      if (k < 0) continue;
      const model::Valve& valve = machine_.hydraulics.actuators[actuator_of_joint(j)].valve;
      ydot[k] = (held_.pilot_input[j] - y[k]) / valve.pilot_time_constant;
    }

    for (int i = layout_.speed(); i <= layout_.travel_energy(); ++i) ydot[i] = 0.0;
    if (!is_loader_) return;
    DriveState drive_state{y[layout_.speed()], y[layout_.wheel()], y[layout_.throttle()]};
    DriveInput input{held_.drive, held_.brake, held_.payload, out.tip_force.x(), out.tip_force.y()};
    out.drive = EvaluateDrive(machine_, options_.drive, drive_state, input);
    ydot[layout_.speed()] = out.drive.speed_dot;
    ydot[layout_.wheel()] = out.drive.wheel_speed_dot;
    ydot[layout_.throttle()] = out.drive.throttle_dot;
    // Articulated steering kinematics (see plant.h).
    const double v = y[layout_.speed()];
    const double psi = y[layout_.heading()], gamma = y[layout_.articulation()];
    const double lf = machine_.chassis.hinge_to_front_axle;
    const double lr = machine_.chassis.hinge_to_rear_axle;
    const double gamma_dot = held_.articulation_rate;
    const double psi_dot = (v * std::sin(gamma) + lr * gamma_dot) / (lf * std::cos(gamma) + lr);
    ydot[layout_.x()] = v * std::cos(psi) + lf * psi_dot * std::sin(psi);
    ydot[layout_.y()] = v * std::sin(psi) - lf * psi_dot * std::cos(psi);
    ydot[layout_.heading()] = psi_dot;
    ydot[layout_.articulation()] = gamma_dot;
    ydot[layout_.travel_energy()] =
        travel_losses_.Evaluate(out.drive.wheel_torque, y[layout_.wheel()]).drawn;
  }

  void Rhs(double, const double* y, double* ydot) override { Evaluate(y, ydot); }

  // ∂f/∂y: the generated Jacobian for the arm block at the held inputs, plus forward
  // differences of what the generated code does not see: the resistance's dependence on the
  // arm and vehicle speeds and positions (through the external torques), the drive, steering
  // and energy rows. Those are a handful of cheap columns; the hydraulic block, where the
  // stiffness is, stays exact.
  void Jacobian(double, const double* y, double* jacobian) override {
    const int n = layout_.size(), arm = layout_.arm, J = layout_.joints;
    std::fill(jacobian, jacobian + static_cast<std::size_t>(n) * n, 0.0);
    FillArmInputs(y);
    functions_.plant_jacobian(0.0, y, u_.data(), arm_jacobian_.data());
    for (int r = 0; r < arm; ++r) {
      for (int c = 0; c < arm; ++c) jacobian[c * n + r] = arm_jacobian_[r * arm + c];
    }
    base_.resize(n);
    probe_.resize(n);
    work_.assign(y, y + n);
    const std::vector<double> u_fixed = u_;
    Residual(work_.data(), u_fixed, base_.data());
    columns_.clear();
    for (int j = 0; j < 2 * J; ++j) columns_.push_back(j);  // q, q̇
    // Speed, wheel speed and throttle couple stiffly (tyre slip, resistance). The pose columns
    // are left out: the pose integrates non-stiff rates and feeds nothing back, so Newton
    // converges on its rows without them, at a third less cost per Jacobian.
    if (is_loader_) {
      for (int c : {layout_.speed(), layout_.wheel(), layout_.throttle()}) columns_.push_back(c);
    }
    // Pilot states: their own lag and the spool reference they set through the opening law.
    for (int k = 0; k < layout_.pilots; ++k) columns_.push_back(layout_.pilot(k));
    for (int c : columns_) {
      const double h = 1e-7 * std::max(1.0, std::abs(y[c]));
      work_[c] = y[c] + h;
      Residual(work_.data(), u_fixed, probe_.data());
      work_[c] = y[c];
      for (int r = 0; r < n; ++r) jacobian[c * n + r] += (probe_[r] - base_[r]) / h;
    }
  }

  // The powers of the energy audit at state y (energy_audit.h gives the identities they obey).
  EnergyAudit AuditPowers(const double* y) {
    using model::internal::OrificeRoot;
    using model::internal::SmoothPositive;
    EnergyAudit p;
    audit_ydot_.resize(layout_.size());
    const Outputs out = Evaluate(y, audit_ydot_.data());  // also sets u_ (τ_ext)
    const int J = layout_.joints;
    const double* q = y;
    const double* qd = y + J;
    const double* qdd = audit_ydot_.data() + J;
    const model::Hydraulics& hyd = machine_.hydraulics;
    const double pump = held_.pump_pressure, tank = hyd.tank_pressure;
    double pump_flow = 0;
    for (int j = 0; j < J; ++j) {
      const int a = actuator_of_joint(j);
      const model::Actuator& act = hyd.actuators[a];
      const model::Valve& valve = act.valve;
      const double xs = y[2 * J + j], pa = y[3 * J + j], pb = y[4 * J + j];
      const double pa_dot = audit_ydot_[3 * J + j], pb_dot = audit_ydot_[4 * J + j];
      const double supply = held_.section_supply[j];
      const double open_a = SmoothPositive(xs, model::plant::kSpoolUnderlap);
      const double open_b = SmoothPositive(-xs, model::plant::kSpoolUnderlap);
      constexpr double kCheck = model::plant::kCheckValveWidth;
      const double in_a =
          valve.flow_gain * open_a * OrificeRoot(SmoothPositive(supply - pa, kCheck));
      const double in_b =
          valve.flow_gain * open_b * OrificeRoot(SmoothPositive(supply - pb, kCheck));
      const double out_a = valve.flow_gain * open_b * OrificeRoot(pa - tank);
      const double out_b = valve.flow_gain * open_a * OrificeRoot(pb - tank);
      const double relief_gain = valve.rated_flow / model::plant::kReliefFullFlowOverpressure;
      auto relief = [&](double pressure) {
        return relief_gain *
               (SmoothPositive(pressure - act.relief_pressure, model::plant::kReliefPressureWidth) -
                SmoothPositive(tank - pressure, model::plant::kReliefPressureWidth));
      };
      const double in_a_pos = std::max(in_a, 0.0), in_b_pos = std::max(in_b, 0.0);
      pump_flow += in_a_pos + in_b_pos;
      p[EnergyTerm::kCompensator] += (pump - supply) * (in_a_pos + in_b_pos);
      p[EnergyTerm::kMeterIn] += (supply - pa) * in_a_pos + (supply - pb) * in_b_pos;
      p[EnergyTerm::kBackflow] += pa * (in_a_pos - in_a) + pb * (in_b_pos - in_b);
      p[EnergyTerm::kMeterOut] += pa * out_a + pb * out_b;
      p[EnergyTerm::kRelief] += pa * relief(pa) + pb * relief(pb);
      double volume_a = act.line_volume, volume_b = act.line_volume;
      if (act.kind == model::ActuatorKind::kCylinder) {
        const double area_a = act.count * std::numbers::pi / 4.0 * act.bore * act.bore;
        const double area_b =
            act.count * std::numbers::pi / 4.0 * (act.bore * act.bore - act.rod * act.rod);
        const double s = audit_model_->CylinderLength(a, q) - act.retracted_length;
        volume_a = act.dead_volume + area_a * s;
        volume_b = act.dead_volume + area_b * (act.stroke - s);
        const std::vector<double> lever = audit_model_->LeverArms(a, q);
        double s_dot = 0;
        for (int i = 0; i < J; ++i) s_dot += lever[i] * qd[i];
        namespace k = model::plant;
        const double end_force =
            act.count * k::kEndStopStiffness *
                (SmoothPositive(-s, k::kEndStopSmoothing) -
                 SmoothPositive(s - act.stroke, k::kEndStopSmoothing)) -
            act.count * k::kEndStopDamping * s_dot *
                (model::internal::SmoothStep(-s, k::kEndStopSmoothing) +
                 model::internal::SmoothStep(s - act.stroke, k::kEndStopSmoothing));
        p[EnergyTerm::kEndStops] -= end_force * s_dot;
      }
      p[EnergyTerm::kCompression] +=
          (pa * volume_a * pa_dot + pb * volume_b * pb_dot) / hyd.bulk_modulus;
    }
    p[EnergyTerm::kPumpLoss] = hydraulic_losses_.Loss(pump, pump_flow);
    // The arm: M q̈ + h = Q_g + Σ F ∂L/∂q + τ_ext − b q̇ (interpreted_model.h).
    audit_mass_.assign(static_cast<std::size_t>(J) * J, 0.0);
    audit_h_.assign(J, 0.0);
    audit_gravity_.assign(J, 0.0);
    audit_model_->Dynamics(q, qd, held_.payload, 0.0, audit_mass_.data(), audit_h_.data(),
                           audit_gravity_.data());
    const int n = static_cast<int>(machine_.links.size());
    for (int i = 0; i < J; ++i) {
      double inertial = audit_h_[i];
      for (int c = 0; c < J; ++c) inertial += audit_mass_[i * J + c] * qdd[c];
      p[EnergyTerm::kArmKinetic] += qd[i] * inertial;
      p[EnergyTerm::kLifting] -= audit_gravity_[i] * qd[i];
      const double b =
          i < n ? machine_.links[i].viscous_friction : machine_.swing->viscous_friction;
      p[EnergyTerm::kArmFriction] += b * qd[i] * qd[i];
      p[EnergyTerm::kSoilByArm] -= u_[J + i] * qd[i];
    }
    if (!is_loader_) return p;
    const DriveRates& d = out.drive;
    const double v = y[layout_.speed()], w = y[layout_.wheel()];
    const double r = machine_.chassis.wheel_radius;
    const TravelPowerSplit<double> travel = travel_losses_.Evaluate(d.wheel_torque, w);
    p[EnergyTerm::kTravelDriveLoss] = travel.loss;
    p[EnergyTerm::kTravelNotRecovered] = travel.not_recovered;
    p[EnergyTerm::kBrake] = d.brake_torque * w;
    p[EnergyTerm::kTyreSlip] = d.traction_force * (w * r - v);
    p[EnergyTerm::kRolling] = d.rolling_force * v;
    p[EnergyTerm::kSoilByDrive] = -out.tip_force.x() * v;
    p[EnergyTerm::kMachineKinetic] =
        d.mass * v * d.speed_dot + options_.drive.wheel_inertia * w * d.wheel_speed_dot;
    return p;
  }

  int actuator_of_joint(int j) const { return actuator_of_joint_[j]; }
  /// Index in y of joint j's pilot state, or -1 when its valve has no pilot stage.
  int pilot_state(int j) const { return pilot_state_[j]; }
  void set_actuator_of_joint(std::vector<int> map) { actuator_of_joint_ = std::move(map); }

 private:
  // The part of f the generated Jacobian does not cover: arm rows f(x, u(y)) − f(x, u_fixed),
  // all other rows in full.
  void Residual(const double* y, const std::vector<double>& u_fixed, double* r) {
    Evaluate(y, r);
    functions_.plant_rhs(0.0, y, u_fixed.data(), arm_rhs_.data());
    for (int i = 0; i < layout_.arm; ++i) r[i] -= arm_rhs_[i];
  }

  const model::MachineDescription& machine_;
  const generated::MachineFunctions& functions_;
  const PlantOptions& options_;
  const TravelDriveLosses travel_losses_;
  const HydraulicLosses hydraulic_losses_;
  Layout layout_;
  Held held_;
  bool is_loader_ = true;
  std::vector<int> actuator_of_joint_;
  std::vector<int> pilot_state_;  // per joint
  std::vector<double> u_, arm_rhs_, arm_jacobian_, base_, probe_, work_;
  std::vector<int> columns_;
  std::unique_ptr<model::InterpretedModel> audit_model_;  // with PlantOptions::energy_audit
  std::vector<double> audit_ydot_, audit_mass_, audit_h_, audit_gravity_;
  std::vector<Eigen::Vector2d> origins_;
  std::vector<double> angles_;
};

Plant::Plant(const model::MachineDescription& machine, const generated::MachineFunctions& functions,
             World& world, const MachineState& initial, const PlantOptions& options)
    : machine_(machine), functions_(functions), world_(world), options_(options) {
  if (machine.name != functions.name || machine.sha256 != functions.source_sha256) {
    throw std::invalid_argument("Plant: generated code of '" + std::string(functions.name) +
                                "' does not match description '" + machine.name +
                                "' (regenerate: cmake --build build --target regen)");
  }
  system_ = std::make_unique<System>(machine, functions, options_);
  const Layout& layout = system_->layout();
  const int J = layout.joints;
  std::vector<int> actuator_of_joint(J, -1);
  for (int a = 0; a < functions.num_actuators; ++a) {
    actuator_of_joint[functions.actuator_joint[a]] = a;
  }
  system_->set_actuator_of_joint(actuator_of_joint);
  for (const model::Actuator& act : machine.hydraulics.actuators) {
    valves_.emplace_back(act.valve);
    pilot_signals_.emplace_back(act.valve.pilot_delay, act.valve.pilot_time_constant);
  }
  command_.valve.assign(machine.hydraulics.actuators.size(), 0.0);
  // The margin of a load-sensing system equals the drop at which its valves are rated, so a
  // fully open spool passes its rated flow.
  for (const model::Actuator& act : machine.hydraulics.actuators) {
    load_sensing_margin_ = std::max(load_sensing_margin_, act.valve.rated_pressure_drop);
  }

  if (options_.integrator.absolute_tolerance.size() != static_cast<std::size_t>(layout.size())) {
    // Per-state scales far below what any consumer resolves: 1 µrad on joints (3 µm at the
    // tip), 1e-5 on rates, spools and speeds, 100 Pa on pressures (transducers resolve 10 kPa),
    // 10 µm and 1 µrad on the pose. The energies are bookkeeping: weighted out of the error test
    // (1e20 J), they follow the steps the motion takes, like the audit's quadratures, so the
    // accounting (flat or loss maps, power_losses.h) never changes the trajectory. With the
    // maps' sharper integrand in the test, the steps changed enough to move a flow-limited
    // pump's delivery by 4 % (PumpFlowLimit).
    std::vector<double>& atol = options_.integrator.absolute_tolerance;
    atol.assign(layout.size(), 1e-5);
    for (int j = 0; j < J; ++j) {
      atol[j] = 1e-6;
      atol[3 * J + j] = atol[4 * J + j] = 100.0;
    }
    atol[layout.heading()] = atol[layout.articulation()] = 1e-6;
    atol[layout.travel_energy()] = atol[layout.hydraulic_energy()] = 1e20;
  }
  integrator_ = std::make_unique<OdeIntegrator>(*system_, options_.integrator);
  bucket_terrain_ = std::make_unique<BucketTerrain>(machine.bucket, world_,
                                                    machine.kind == model::MachineKind::kExcavator
                                                        ? CuttingDirection::kTowardsMachine
                                                        : CuttingDirection::kAwayFromMachine);

  y_.assign(layout.size(), 0.0);
  if (static_cast<int>(initial.q.size()) != J) {
    throw std::invalid_argument("Plant: initial state has " + std::to_string(initial.q.size()) +
                                " joints, machine '" + machine.name + "' has " + std::to_string(J));
  }
  // Start in static balance: each cylinder's rod side at a back pressure, its cap side at the
  // pressure that holds the arm against gravity (or the other way round for a cylinder that
  // must pull); motors at the back pressure on both ports.
  const model::InterpretedModel reference(machine);
  const std::vector<double> gravity = reference.GravityTorques(initial.q.data(), 0.0, 0.0);
  const double tank = machine.hydraulics.tank_pressure;
  const double back = tank + 1e6;
  // Distal joints first: a cylinder may also push on joints before the one it drives (a
  // frame-mounted tilt cylinder moves with the boom), never on those after it.
  std::vector<double> cylinder_force(J, 0.0);
  for (int j = J - 1; j >= 0; --j) {
    y_[j] = initial.q[j];
    y_[3 * J + j] = y_[4 * J + j] = back;
    const int a = actuator_of_joint[j];
    const model::Actuator& act = machine.hydraulics.actuators[a];
    if (act.kind != model::ActuatorKind::kCylinder) continue;
    double torque = -gravity[j];
    for (int k = j + 1; k < J; ++k) {
      torque -= cylinder_force[k] * reference.LeverArms(actuator_of_joint[k], initial.q.data())[j];
    }
    const double lever = functions.lever_arm(a, initial.q.data());
    const double area_a = act.count * std::numbers::pi / 4 * act.bore * act.bore;
    const double area_b =
        act.count * std::numbers::pi / 4 * (act.bore * act.bore - act.rod * act.rod);
    const double force = std::abs(lever) > 1e-6 ? torque / lever : 0.0;
    cylinder_force[j] = force;
    double p_a = (force + back * area_b) / area_a, p_b = back;
    if (p_a < back) p_a = back, p_b = (back * area_a - force) / area_b;
    y_[3 * J + j] = std::clamp(p_a, tank, act.relief_pressure);
    y_[4 * J + j] = std::clamp(p_b, tank, act.relief_pressure);
  }
  y_[layout.x()] = initial.hinge_xy.x();
  y_[layout.y()] = initial.hinge_xy.y();
  y_[layout.heading()] = initial.heading;
  y_[layout.articulation()] = initial.articulation;
  // The clock starts at the initial state's time: the main job's cycles run on one machine
  // clock (frame stamps, the map's process noise, a recording's timestamps) instead of each
  // cycle's restarting at 0.
  if (!std::isfinite(initial.time)) throw std::invalid_argument("Plant: initial time not finite");
  state_.time = initial.time;
  last_relax_time_ = initial.time;
  LoadSensing(OpeningReference(system_->held().spool_reference, system_->held().pilot_input),
              system_->held().section_supply, system_->held().pump_pressure);
  integrator_->Reset(initial.time, y_.data());
  dirty_ = false;
  UpdateState();
  UpdateResistance();
}

Plant::~Plant() = default;

bool Plant::SetCommand(const core::ActuatorCommand& command, std::string* why) {
  auto refuse = [&](const std::string& reason) {
    ++counters_.refused_commands;
    if (why) *why = reason;
    return false;
  };
  if (command.valve.size() != valves_.size()) {
    return refuse("expected " + std::to_string(valves_.size()) + " valve commands, got " +
                  std::to_string(command.valve.size()));
  }
  for (std::size_t a = 0; a < command.valve.size(); ++a) {
    const double u = command.valve[a];
    if (!std::isfinite(u) || u < -1.0 || u > 1.0) {
      return refuse("valve command of actuator '" + machine_.hydraulics.actuators[a].name +
                    "' must be a finite number in [-1, 1], got " + std::to_string(u));
    }
  }
  if (!std::isfinite(command.drive) || command.drive < -1.0 || command.drive > 1.0) {
    return refuse("drive command must be in [-1, 1], got " + std::to_string(command.drive));
  }
  if (!std::isfinite(command.brake) || command.brake < 0.0 || command.brake > 1.0) {
    return refuse("brake command must be in [0, 1], got " + std::to_string(command.brake));
  }
  if (!std::isfinite(command.articulation_rate)) {
    return refuse("articulation rate must be finite");
  }
  command_ = command;
  for (std::size_t a = 0; a < valves_.size(); ++a) {
    valves_[a].Command(time(), command.valve[a]);
    pilot_signals_[a].Command(time(), command.valve[a]);
  }
  return true;
}

void Plant::SetPhase(const std::string& phase) { phase_ = phase; }

Energy Plant::energy() const {
  const Layout& layout = system_->layout();
  return {y_[layout.travel_energy()], y_[layout.hydraulic_energy()]};
}

void Plant::SetTransportDelay(int actuator, double delay) {
  valves_.at(actuator).set_transport_delay(delay);
}

void Plant::Advance(double dt) {
  if (!(dt > 0) || !std::isfinite(dt))
    throw std::invalid_argument("Plant::Advance: dt must be > 0");
  const Layout& layout = system_->layout();
  const Energy before = energy();
  double t = time();
  const double t_end = t + dt;

  System::Held held = system_->held();
  held.drive = command_.drive;
  held.brake = command_.brake;
  // Steering cylinders stop at the articulation limit: the rate is cut so as to reach it exactly.
  if (machine_.kind == model::MachineKind::kWheelLoader) {
    const double limit = machine_.chassis.max_articulation;
    const double rate_limit = machine_.chassis.max_articulation_rate;
    double rate = std::clamp(command_.articulation_rate, -rate_limit, rate_limit);
    const double gamma = y_[layout.articulation()];
    if (gamma + rate * dt > limit) rate = std::max(0.0, (limit - gamma) / dt);
    if (gamma + rate * dt < -limit) rate = std::min(0.0, (-limit - gamma) / dt);
    held.articulation_rate = rate;
  }
  held.payload = bucket_terrain_->payload_mass();
  held.resistance = resistance_;

  while (t < t_end) {
    double t_next = t_end;
    for (const auto& valve : valves_) t_next = std::min(t_next, valve.NextSwitchAfter(t));
    for (int a = 0; a < static_cast<int>(valves_.size()); ++a) {
      const int joint = functions_.actuator_joint[a];
      (valves_[a].raw() ? held.pilot_input : held.spool_reference)[joint] =
          valves_[a].EffectiveAt(t);
    }
    LoadSensing(OpeningReference(held.spool_reference, held.pilot_input), held.section_supply,
                held.pump_pressure);
    const bool event = held.IsEventAgainst(system_->held()) || dirty_;
    system_->held() = held;
    if (event) {
      integrator_->Reset(t, y_.data());
      ++counters_.resets;
      dirty_ = false;
    }
    integrator_->AdvanceTo(t_next, y_.data());
    t = t_next;
  }
  for (auto& valve : valves_) valve.Prune(t_end);
  for (auto& pilot : pilot_signals_) pilot.Prune(t_end);
  state_.time = t_end;
  ++counters_.ticks;
  counters_.steps = integrator_->steps();
  counters_.rhs_evaluations = integrator_->rhs_evaluations();
  counters_.jacobian_evaluations = integrator_->jacobian_evaluations();

  const Energy after = energy();
  // The energies are integrator states, integrated along the motion's steps, so a tick of
  // little power may show a decrease within the integration error; a phase is never booked one,
  // except travel energy an electric drive regenerates (power_losses.h).
  Energy& booked = phase_energy_[phase_];
  const double travel = after.travel - before.travel;
  booked.travel += system_->can_regenerate() ? travel : std::max(travel, 0.0);
  booked.hydraulic += std::max(after.hydraulic - before.hydraulic, 0.0);
  if (options_.energy_audit) {
    EnergyAudit now;
    const std::vector<double>& integrals = integrator_->quadratures();
    std::copy(integrals.begin(), integrals.end(), now.terms.begin());
    phase_audit_[phase_] += now - audit_;
    audit_ = now;
    audit_trace_.push_back({t_end, phase_, now});
  }

  // Terrain exchange between ticks (a contact change resets the integrator at the next tick).
  UpdateState();
  const BucketPlacement placement = CurrentBucketPlacement();
  const ExchangeResult exchange = bucket_terrain_->Exchange(placement);
  terrain_unsettled_ |= exchange.captured_volume > 0 || exchange.spilled_volume > 0;
  // Relax only where and when the bucket changed the terrain: elsewhere it stays at repose.
  if (terrain_unsettled_ && t_end - last_relax_time_ >= options_.relax_period - 1e-12) {
    const double moved =
        bucket_terrain_->RelaxToRepose(placement.ToWorldXy(placement.pivot.x()),
                                       options_.relax_half_window, options_.relax_sweeps);
    terrain_unsettled_ = moved > 0;
    last_relax_time_ = t_end;
  }
  UpdateResistance();
  state_.payload_mass = bucket_terrain_->payload_mass();
  state_.payload_volume = bucket_terrain_->payload_volume();
}

std::vector<double> Plant::OpeningReference(const std::vector<double>& spool_reference,
                                            const std::vector<double>& pilot_input) const {
  // Where each spool is headed: the held reference, or with a pilot stage the opening law at
  // the pilot's input (what the pilot settles to).
  std::vector<double> opening = spool_reference;
  for (int j = 0; j < static_cast<int>(opening.size()); ++j) {
    if (system_->pilot_state(j) < 0) continue;
    const model::Actuator& act = machine_.hydraulics.actuators[system_->actuator_of_joint(j)];
    opening[j] = ValveOpening(act.valve, pilot_input[j]);
  }
  return opening;
}

double Plant::PilotSignal(int actuator) const { return pilot_signals_.at(actuator).At(time()); }

double Plant::PilotState(int actuator) const {
  const int joint = functions_.actuator_joint[actuator];
  const int k = system_->pilot_state(joint);
  return k >= 0 ? y_[k] : valves_.at(actuator).EffectiveAt(time());
}

void Plant::LoadSensing(const std::vector<double>& spool_reference,
                        std::vector<double>& section_supply, double& pump_pressure) const {
  // Pressure-compensated load sensing: each valve section's compensator keeps the drop across
  // its spool at the margin, so it is supplied at (pressure of the chamber it feeds + margin);
  // the pump follows the highest such demand, up to its maximum. A section whose demand exceeds
  // the maximum is fed at the pump's maximum and passes flow only while its chamber is below it
  // (its load check valve). Held over a segment:
  // a real pump and compensator respond in tens of milliseconds, a control tick is 10 ms.
  //
  // A pump with a largest delivery Q_max (Hydraulics::pump_max_flow) cannot keep the margin when
  // the open spools ask for more: the sections' compensators sit after the spools and all see
  // the same drop (post-compensated flow sharing, Rexroth LUDV), so the drop falls alike for
  // every section to Δp' = margin·(Q_max/Q_ask)², Q_ask the flow the spools pass at the margin,
  // and each section gets the same fraction Q_max/Q_ask of what it asked for. Q_ask is taken at
  // the spools' positions at the segment's start (they move 10–15 % of a step per tick).
  const int J = static_cast<int>(spool_reference.size());
  const model::Hydraulics& hyd = machine_.hydraulics;
  section_supply.assign(J, 0.0);
  std::vector<double> fed(J, 0.0);
  std::vector<bool> flowing(J, false);
  double asked = 0;  // [m³/s] at the margin
  for (int j = 0; j < J; ++j) {
    const double xs = y_[2 * J + j];
    const double opening = spool_reference[j] != 0 ? spool_reference[j] : xs;
    fed[j] = opening >= 0 ? y_[3 * J + j] : y_[4 * J + j];
    flowing[j] = fed[j] + load_sensing_margin_ <= hyd.pump_pressure;
    if (flowing[j]) {
      const model::Valve& valve = hyd.actuators[system_->actuator_of_joint(j)].valve;
      asked += valve.flow_gain *
               model::internal::SmoothPositive(std::abs(xs), model::plant::kSpoolUnderlap) *
               model::internal::OrificeRoot(load_sensing_margin_);
    }
  }
  double drop = load_sensing_margin_;
  if (hyd.pump_max_flow > 0 && asked > hyd.pump_max_flow) {
    // The drop at which the orifices pass the share: Δp' = margin·share² where the flow goes as
    // √Δp, solved on the plant's own orifice law (laminar below 2 bar) by bisection.
    const double target =
        hyd.pump_max_flow / asked * model::internal::OrificeRoot(load_sensing_margin_);
    double low = 0, high = load_sensing_margin_;
    for (int k = 0; k < 40; ++k) {
      const double mid = 0.5 * (low + high);
      (model::internal::OrificeRoot(mid) < target ? low : high) = mid;
    }
    drop = 0.5 * (low + high);
  }
  // The compensators' dead band scales with the drop they hold: the same relative accuracy of
  // the flow whether or not the pump is at its limit.
  const double band =
      load_sensing_margin_ > 0 ? kCompensatorBand * drop / load_sensing_margin_ : kCompensatorBand;
  pump_pressure = hyd.tank_pressure + load_sensing_margin_;  // standby
  bool any_open = false;
  double highest = 0;
  for (int j = 0; j < J; ++j) {
    const double xs = y_[2 * J + j];
    const double opening = spool_reference[j] != 0 ? spool_reference[j] : xs;
    // A section whose load needs more than the pump can give sees the pump at its cut-off; its
    // load check valve (plant_constants.h) keeps the chamber from pushing oil back, and it fills
    // again only once its pressure falls below the pump's.
    double supply = flowing[j] ? fed[j] + drop : hyd.pump_pressure;
    // A compensator does not chase every pascal: within its dead band (kCompensatorBand) the
    // previous supply is kept, which also spares the integrator a reset at every tick.
    const std::vector<double>& previous = system_->held().section_supply;
    if (static_cast<int>(previous.size()) == J && std::abs(previous[j] - supply) < band) {
      supply = previous[j];
    }
    section_supply[j] = supply;
    if (std::abs(opening) > 0.01) {
      // The pump runs at the highest open section's load plus the margin, or plus the reduced
      // drop while it delivers all it can.
      highest = any_open ? std::max(highest, section_supply[j]) : section_supply[j];
      any_open = true;
    }
  }
  if (any_open) pump_pressure = std::max(pump_pressure, highest);
  pump_pressure = std::min(pump_pressure, hyd.pump_pressure);
}

void Plant::UpdateState() {
  const Layout& layout = system_->layout();
  const int J = layout.joints;
  state_.q.assign(y_.begin(), y_.begin() + J);
  state_.qd.assign(y_.begin() + J, y_.begin() + 2 * J);
  state_.spool.assign(y_.begin() + 2 * J, y_.begin() + 3 * J);
  state_.pressure_a.assign(y_.begin() + 3 * J, y_.begin() + 4 * J);
  state_.pressure_b.assign(y_.begin() + 4 * J, y_.begin() + 5 * J);
  state_.hinge_xy = Eigen::Vector2d(y_[layout.x()], y_[layout.y()]);
  state_.heading = y_[layout.heading()];
  state_.articulation = y_[layout.articulation()];
  state_.speed = y_[layout.speed()];
  state_.wheel_speed = y_[layout.wheel()];
  const double wheel_surface_speed = state_.wheel_speed * machine_.chassis.wheel_radius;
  state_.wheel_slip = (wheel_surface_speed - state_.speed) /
                      std::max({std::abs(state_.speed), std::abs(wheel_surface_speed), 0.1});
  state_.payload_mass = bucket_terrain_->payload_mass();
  state_.payload_volume = bucket_terrain_->payload_volume();
}

BucketPlacement Plant::CurrentBucketPlacement() const {
  std::vector<Eigen::Vector2d> origins;
  std::vector<double> angles;
  ArmGeometry(machine_, state_.q.data(), origins, angles);
  const int n = static_cast<int>(machine_.links.size());
  BucketPlacement placement;
  placement.plane_origin = state_.hinge_xy;
  placement.plane_heading = state_.heading;
  if (machine_.swing) placement.plane_heading += state_.q.back();
  placement.pivot = machine_.arm_pivot + origins[n - 1];
  placement.bucket_angle = angles[n - 1];
  return placement;
}

Eigen::Vector3d Plant::TipInWorld() const {
  const BucketPlacement placement = CurrentBucketPlacement();
  const Eigen::Vector2d tip = placement.ToPlane(machine_.bucket.profile.front());
  const Eigen::Vector2d xy = placement.ToWorldXy(tip.x());
  return {xy.x(), xy.y(), tip.y()};
}

void Plant::UpdateResistance() {
  const BucketPlacement placement = CurrentBucketPlacement();
  const BucketContact contact = bucket_terrain_->Contact(placement);
  ResistanceState next;
  if (contact.in_contact) {
    const model::Material& material = world_.materials.at(contact.material);
    const double unit_weight = material.density * model::plant::kGravity;
    // Which way the cutting edge points along the arm plane: from the bucket's interior (the
    // middle of its opening) to the tip.
    const Eigen::Vector2d middle = 0.5 * (contact.tip + contact.rim);
    next.cut_side = contact.tip.x() >= middle.x() - 1e-9 ? 1.0 : -1.0;
    // Rake angle: between the backward travel direction (−c along s) and the blade, here the
    // bucket's opening from the cutting edge to the top of the back wall (material in the
    // bucket acts as part of the tool once it has filled, so the opening, not the floor, is
    // the blade).
    const Eigen::Vector2d blade = contact.rim - contact.tip;
    next.rake_angle = std::acos(std::clamp(-next.cut_side * blade.x() / blade.norm(), -1.0, 1.0));
    // Blade height: the opening's rise above the edge; the material above it is surcharge.
    const double blade_height = std::max(0.3, blade.y());
    const double cut_depth = std::min(contact.depth, blade_height);
    CuttingInput input;
    input.width = machine_.bucket.width;
    input.depth = cut_depth;
    input.rake_angle = next.rake_angle;
    input.density = material.density;
    input.cohesion = material.cohesion;
    input.adhesion = options_.adhesion_fraction * material.cohesion;
    input.surcharge = unit_weight * std::max(0.0, contact.depth - blade_height);
    input.friction_angle = material.friction_angle;
    input.interface_angle = material.interface_friction_angle;
    if (reece_tables_.size() != world_.materials.size()) {
      reece_tables_.resize(world_.materials.size());
    }
    std::optional<ReeceTable>& table = reece_tables_[contact.material];
    if (!table) table.emplace(material.friction_angle, material.interface_friction_angle);
    input.table = &*table;
    const CuttingResistance cutting = ComputeCuttingResistance(input);
    next.cut = cutting.along;
    next.press = cutting.across;
    // Lifting: shear on the two side planes of the column (depth d, length of the opening)
    // under at-rest pressure, plus cohesion on them.
    const double d = contact.depth;
    const double k0 = 1.0 - std::sin(material.friction_angle);
    const double length = std::abs(blade.x()) + 0.1;
    next.lift = 2.0 * length *
                (0.5 * k0 * unit_weight * d * d * std::tan(material.friction_angle) +
                 material.cohesion * d);
    // Withdrawing: soil–steel friction under the weight of the column over the opening.
    next.withdraw = std::tan(material.interface_friction_angle) * unit_weight * d * length *
                    machine_.bucket.width;
    next.in_contact = true;
    next.depth = contact.depth;
    next.material = contact.material;
  }
  resistance_ = next;
}

double Plant::ActuatorPressure(int actuator, bool cap_side) const {
  const int joint = functions_.actuator_joint[actuator];
  return cap_side ? state_.pressure_a[joint] : state_.pressure_b[joint];
}

double Plant::PumpPressure() const { return system_->held().pump_pressure; }

double Plant::HydraulicPower() const {
  std::vector<double> ydot(y_.size());
  System::Outputs out = system_->Evaluate(y_.data(), ydot.data());
  return out.hydraulic_power;
}

double Plant::TravelPower() const {
  std::vector<double> ydot(y_.size());
  system_->Evaluate(y_.data(), ydot.data());
  return ydot[system_->layout().travel_energy()];
}

std::vector<OrientedBox> Plant::OwnBodies() const {
  std::vector<OrientedBox> boxes;
  const Eigen::Isometry3d T_world_base = state_.T_world_base();
  auto add = [&](const std::string& name, const Eigen::Vector3d& center_base,
                 const Eigen::Vector3d& half, double yaw_base,
                 const Eigen::Isometry3d& T_world_body) {
    OrientedBox box;
    box.name = name;
    box.center = T_world_body * center_base;
    box.half_extents = half;
    box.yaw = state_.heading + yaw_base;
    box.semantic_class = core::SemanticClass::kOwnLoader;
    box.reflectivity = 0.5;
    boxes.push_back(box);
  };
  if (machine_.kind == model::MachineKind::kWheelLoader) {
    const double lf = machine_.chassis.hinge_to_front_axle;
    const double lr = machine_.chassis.hinge_to_rear_axle;
    const double half_track = machine_.chassis.track_width / 2 + 0.3;
    const double r = machine_.chassis.wheel_radius;
    add("front_frame", {lf / 2 + 0.2, 0, r + 0.2}, {lf / 2 + 0.6, half_track, r + 0.2}, 0,
        T_world_base);
    add("rear_frame", {-lr / 2 - 0.8, 0, r + 0.6}, {lr / 2 + 1.2, half_track, r + 0.6},
        -state_.articulation, state_.T_world_cab());
  }
  // Boom and bucket: boxes along the links in the arm plane (a box turned only about z stands for
  // each short piece of an inclined link).
  std::vector<Eigen::Vector2d> origins;
  std::vector<double> angles;
  ArmGeometry(machine_, state_.q.data(), origins, angles);
  const double swing = machine_.swing ? state_.q.back() : 0.0;
  Eigen::Isometry3d T_world_arm = T_world_base;
  T_world_arm.rotate(Eigen::AngleAxisd(swing, Eigen::Vector3d::UnitZ()));
  const int n = static_cast<int>(machine_.links.size());
  for (int k = 0; k < n; ++k) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(machine_.links[k].length / 0.5)));
    const bool is_bucket = k == n - 1;
    const double half_width = is_bucket ? machine_.bucket.width / 2 : 0.4;
    for (int p = 0; p < pieces; ++p) {
      const double f = (p + 0.5) / pieces;
      const Eigen::Vector2d c = machine_.arm_pivot + origins[k] + f * (origins[k + 1] - origins[k]);
      const double piece = machine_.links[k].length / pieces;
      const double dx = std::abs(std::cos(angles[k])) * piece / 2 + 0.15;
      const double dz = std::abs(std::sin(angles[k])) * piece / 2 + 0.15;
      add(machine_.links[k].name + "_" + std::to_string(p), {c.x(), 0, c.y()}, {dx, half_width, dz},
          swing, T_world_arm);
    }
  }
  return boxes;
}

}  // namespace autoshovel::plant
