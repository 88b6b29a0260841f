// The simulated machine: the generated hydraulic–mechanical arm model, the drive, the bucket–
// terrain interaction and the energy counters, integrated by CVODE between control ticks.
//
// State y = [arm x (5J: q, q̇, spool, p_A, p_B, see interpreted_model.h) | v, ω, throttle,
// x_hinge, y_hinge, ψ, γ, E_travel, E_hydraulic | π per valve with a pilot stage]. Per segment
// (between two discrete events) the inputs are held: spool references (after the opening law
// and the delays) or the delayed commands into the pilot lags (valve_command.h), drive command,
// brake, articulation rate, payload mass and the magnitudes of the material's resistance. Inside
// the segment the resistance follows the bucket tip velocity v = (v_s, v_z) in the arm plane, each
// component through a smooth sign v/sqrt(v² + ε²), so that it acts like Coulomb friction that
// never pushes the bucket backwards:
//   F_s = −σ(c v_s)·c·(R_cut if cutting else R_withdraw)      c = ±1: the cutting edge's side
//   F_z = −σ(v_z)·(R_lift if rising else R_cut) − R_press·max(σ(c v_s), 0)
// R_cut and R_press are Reece's equation (earthmoving.h) for the cut ahead of the edge: the blade
// height is the bucket's opening and the material above it a surcharge. Lifting through the
// pile meets the shear on the two vertical planes bounding the column above the bucket (at-rest
// pressure K₀ = 1 − sin φ, Jaky) plus cohesion; the weight of the material taken is the
// payload. Withdrawing meets only soil–steel friction on the material's weight over the bucket.
// The force acts on the arm through the tip Jacobian (τ = Jᵀ F) and on the chassis as a
// longitudinal force and a vertical load.
//
// The hydraulics are pressure-compensated load sensing: each valve section is supplied at the
// pressure of the chamber it feeds plus a margin (the valves' rated drop), so a spool passes
// flow in proportion to its opening whatever the other loads; the pump runs at the highest such
// demand, within its maximum. Section supplies are inputs of the generated model, held per
// segment. Hydraulic energy is p_pump·ΣQ_in plus the pump's (and its motor's) loss map
// (power_losses.h; compensator losses included).
//
// Events that reset the integrator: a valve command reaching its spool (exactly τ_d after it was
// issued, see valve_command.h), any change of the held inputs at a control tick (command, payload,
// contact). The terrain is changed between ticks only (bucket_terrain.h), never inside a segment.
//
// Articulated steering (loaders): the hinge moves so that neither axle slips sideways,
//   ψ̇ = (v sin γ + l_r γ̇) / (l_f cos γ + l_r),  ḣ = v e_f − l_f ψ̇ n_f
// with v the front axle speed, e_f/n_f the front frame's axis and normal, l_f/l_r the hinge-to-
// axle distances (Corke & Ridley, "Steering kinematics for a center-articulated mobile robot",
// IEEE T-RA 17(2), 2001). Excavators do not travel in this plant: the undercarriage stands still.
#pragma once

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "generated/machine_functions.h"
#include "runtime/core/actuator_command.h"
#include "runtime/model/description.h"
#include "runtime/plant/bucket_terrain.h"
#include "runtime/plant/drive.h"
#include "runtime/plant/earthmoving.h"
#include "runtime/plant/energy_audit.h"
#include "runtime/plant/machine_state.h"
#include "runtime/plant/ode_integrator.h"
#include "runtime/plant/power_losses.h"
#include "runtime/plant/valve_command.h"
#include "runtime/plant/world.h"

namespace autoshovel::plant {

struct PlantOptions {
  /// Relative tolerance 1e-4: the energy of a cycle changes by < 0.5 % and the spool delay
  /// and time constant by < 0.1 % against 1e-6, at three times the speed (plant_bench).
  IntegratorOptions integrator{.relative_tolerance = 1e-4, .absolute_tolerance = {}};
  DriveConstants drive;
  /// Loss maps of the travel drive and the pump (power_losses.h) behind the energy counters.
  PowerLossOptions losses;
  /// How often the terrain relaxes to its angle of repose around the bucket [s].
  double relax_period = 0.25;
  double relax_half_window = 1.5;  ///< beyond the bucket pivot's foot [m]
  /// Sweeps per relaxation; an unfinished relaxation goes on at the next period (material
  /// slides over a few tenths of a second, not at once).
  int relax_sweeps = 10;
  /// Tip speed below which the cutting resistance fades (its smooth sign) [m/s].
  double resistance_speed = 0.05;
  /// Soil–steel adhesion as a fraction of cohesion (no material file gives it) [-].
  double adhesion_fraction = 0.5;
  /// Integrate the energy audit (energy_audit.h) as quadratures and keep it per phase and per
  /// tick. Off by default: it costs one more right-hand side and the arm's dynamics per step;
  /// it never changes the trajectory.
  bool energy_audit = false;
};

/// Energy in J, cumulative.
struct Energy {
  /// ∫ (T_wheel ω + P_loss(T, ω)) dt (electric, power_losses.h: negative while regenerating)
  /// or ∫ max(T_wheel ω, 0) dt / η (diesel)
  double travel = 0;
  double hydraulic = 0;  ///< ∫ (p_pump Σ Q_in + P_loss(p_pump, Σ Q_in)) dt (power_losses.h)
  double total() const { return travel + hydraulic; }
};

/// The resistance the bucket meets, evaluated at the last tick (see the model above).
struct ResistanceState {
  bool in_contact = false;
  double depth = 0;       ///< free surface above the cutting edge [m]
  double rake_angle = 0;  ///< [rad]
  double cut = 0;         ///< R_cut [N]
  double press = 0;       ///< R_press [N]
  double lift = 0;        ///< R_lift [N]
  double withdraw = 0;    ///< R_withdraw [N]
  double cut_side = 1;  ///< c: +1 when the edge points along +s (loader), −1 towards the machine
  int material = -1;
};

/// Counts of what the plant refused or did.
struct PlantCounters {
  long refused_commands = 0;  ///< NaN, infinite or out-of-range commands (never integrated)
  long ticks = 0;
  long resets = 0;                ///< integrator re-initialisations (discrete events)
  long steps = 0;                 ///< CVODE internal steps
  long rhs_evaluations = 0;       ///< right-hand side evaluations by CVODE
  long jacobian_evaluations = 0;  ///< Jacobian evaluations
};

class Plant {
 public:
  /// `functions` must be the generated code of `machine` (same name and hash). `world` is shared
  /// with the sensors and changed by digging. `initial` gives pose and joint positions; spools,
  /// pressures start in static balance, spools centred, at rest.
  Plant(const model::MachineDescription& machine, const generated::MachineFunctions& functions,
        World& world, const MachineState& initial, const PlantOptions& options = {});
  ~Plant();

  /// Applies a command at the current time. A command with a NaN, an infinity or a value out of
  /// range is refused whole (the previous one stays in force), counted, and false is returned
  /// with the reason in `why` if given.
  bool SetCommand(const core::ActuatorCommand& command, std::string* why = nullptr);

  /// Advances the simulated clock by `dt` (one control tick).
  void Advance(double dt);

  /// Names the phase the following energy is booked to ("travel", "crowd", "scoop", …).
  void SetPhase(const std::string& phase);
  const std::map<std::string, Energy>& phase_energy() const { return phase_energy_; }
  Energy energy() const;
  /// With PlantOptions::energy_audit (else empty): where the energy went since the start, per
  /// phase (booked like phase_energy), and after every tick.
  const EnergyAudit& energy_audit() const { return audit_; }
  const std::map<std::string, EnergyAudit>& phase_energy_audit() const { return phase_audit_; }
  const std::vector<EnergyAuditSample>& energy_audit_trace() const { return audit_trace_; }

  const MachineState& state() const { return state_; }
  double time() const { return state_.time; }
  const ResistanceState& resistance() const { return resistance_; }
  const PlantCounters& counters() const { return counters_; }
  const BucketTerrain& bucket() const { return *bucket_terrain_; }
  World& world() { return world_; }
  const World& world() const { return world_; }
  const model::MachineDescription& machine() const { return machine_; }

  /// Cap-side (A) and rod-side (B) pressure of an actuator [Pa]: the boom cylinder pressure that
  /// the pressure-triggered baseline reads.
  double ActuatorPressure(int actuator, bool cap_side = true) const;
  /// The load-sensing pump's output pressure now [Pa] (what a pump pressure transducer reads):
  /// the highest fed chamber of an open valve plus the margin, up to the pump's maximum.
  double PumpPressure() const;
  /// Hydraulic power drawn now [W] and wheel power now [W] (for tests of the energy integral).
  double HydraulicPower() const;
  double TravelPower() const;
  /// Where the bucket is now.
  BucketPlacement CurrentBucketPlacement() const;
  /// Bucket tip in the world [m].
  Eigen::Vector3d TipInWorld() const;
  /// Boxes approximating the machine's own body (chassis, boom, bucket) in the world, for the
  /// simulated sensors (semantic class kOwnLoader).
  std::vector<OrientedBox> OwnBodies() const;
  /// Changes the transport delay of an actuator at run time (fault injection: delay drift).
  void SetTransportDelay(int actuator, double delay);
  /// The pilot (EPPR) pressure of an actuator's valve now, as a fraction of the full pilot
  /// pressure signed by direction (extend > 0): lag_{T_p}(u(t − τ_p)), what a transducer on the
  /// pilot line reads (valve_command.h PilotSignal). Without a pilot stage: u(t − τ_p).
  double PilotSignal(int actuator) const;
  /// The pilot as the spool path sees it now: the CVODE pilot state π (PilotSignal τ_d later).
  /// Without a pilot stage there is none: the held spool reference is returned.
  double PilotState(int actuator) const;

 private:
  class System;
  void UpdateState();
  void UpdateResistance();
  void LoadSensing(const std::vector<double>& spool_reference, std::vector<double>& section_supply,
                   double& pump_pressure) const;
  std::vector<double> OpeningReference(const std::vector<double>& spool_reference,
                                       const std::vector<double>& pilot_input) const;

  const model::MachineDescription& machine_;
  const generated::MachineFunctions& functions_;
  World& world_;
  PlantOptions options_;
  std::unique_ptr<System> system_;
  std::unique_ptr<OdeIntegrator> integrator_;
  std::unique_ptr<BucketTerrain> bucket_terrain_;
  std::vector<DelayedValveCommand> valves_;        ///< per actuator
  std::vector<plant::PilotSignal> pilot_signals_;  ///< per actuator, for PilotSignal()
  std::vector<double> y_;
  MachineState state_;
  ResistanceState resistance_;
  PlantCounters counters_;
  core::ActuatorCommand command_;
  std::string phase_ = "idle";
  std::map<std::string, Energy> phase_energy_;
  EnergyAudit audit_;
  std::map<std::string, EnergyAudit> phase_audit_;
  std::vector<EnergyAuditSample> audit_trace_;
  double last_relax_time_ = 0;
  double load_sensing_margin_ = 0;
  std::vector<std::optional<ReeceTable>> reece_tables_;  ///< per material, built on first contact
  bool terrain_unsettled_ = true;
  bool dirty_ = true;
};

}  // namespace autoshovel::plant
