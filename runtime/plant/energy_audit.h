// Where the energy a machine draws goes (issue 41): the travel drive's and the hydraulic pump's
// energy split into terms whose powers sum, at every instant, to the power drawn. The plant
// integrates the terms as CVODES quadratures (PlantOptions::energy_audit), so the audit never
// changes the trajectory it audits.
//
// Travel drive (energy drawn E_travel = ∫ P_drawn dt, wheel torque T, lumped wheel ω; P_drawn =
// T ω + P_loss(T, ω) for an electric drive's loss map, max(T ω, 0)/η for a diesel's flat η,
// power_losses.h):
//   T ω = I_w ω ω̇ + T_brake ω + r F_x ω                       (wheel, drive.h)
//   r F_x ω = F_x (ω r − v) + F_x v                            (tyre slip + traction on the body)
//   F_x v = m v v̇ + F_roll v − F_soil,x v                      (body)
// so P_drawn = drive loss + not recovered (motor braking) + brake + slip + rolling
//           + soil pushed by the drive + kinetic energy of the machine.
// An electric drive that credits regeneration books nothing as not recovered: braking with the
// motor makes T ω, and P_drawn with it, negative.
//
// Hydraulics (drawn E_hyd = ∫ p_pump Σ Q_in + P_loss(p_pump, Σ Q_in) dt, the pump's and its
// motor's loss map (power_losses.h); per valve section j its supply p_S,j, per
// chamber c fed from the supply at pressure p_c): with Q_in,c the spool's flow from the supply,
// Q_out,c its flow to tank and Q_rel,c the relief's (interpreted_model.h),
//   p_pump ΣQ⁺_in + P_loss = pump loss + Σ(p_pump − p_S)Q⁺_in [compensators] + Σ(p_S − p_c)Q⁺_in
//   [meter-in,
//                     the load-sensing margin] + Σ p_c (Q⁺_in − Q_in) [backflow] + Σ p_c Q_in
//   p_c Q_in = p_c Q_out [meter-out] + p_c Q_rel [relief] + p_c V_c/β ṗ_c [compression]
//              ± p_c A_c ṡ                                      (chamber continuity)
//   (p_A A_A − p_B A_B) ṡ = useful cylinder work
//     = q̇ᵀ(M q̈ + h) [arm kinetic] − Q_g·q̇ [lifting] + Σ b q̇² [friction] − τ_ext·q̇ [soil by the
//       arm] − F_end ṡ [end stops]                             (equations of motion)
// Every term is a power in W; the integrals are in J. Each identity holds exactly in the model,
// so the leaves add up to what was drawn to the integrator's accuracy: the tests check 1 %.
#pragma once

#include <array>
#include <string>

namespace autoshovel::plant {

enum class EnergyTerm : int {
  // The travel drive.
  kTravelDriveLoss,     ///< motor, inverter and drivetrain: P_loss(T, ω) or max(Tω,0)(1/η − 1)
  kTravelNotRecovered,  ///< motor braking (T ω < 0) not fed back: 0 when regeneration is
                        ///< credited, else what the battery would have received (flat: −Tω)
  kBrake,               ///< service brake T_brake ω
  kTyreSlip,            ///< F_x (ω r − v)
  kRolling,             ///< F_roll v
  kSoilByDrive,         ///< −F_soil,x v: the drive pushing the bucket into the pile
  kMachineKinetic,      ///< d/dt (½ m v² + ½ I_w ω²)
  // The hydraulic pump.
  kPumpLoss,     ///< pump and its electric motor: P_loss(p_pump, Σ Q_in), or p Q (1/η − 1)
  kCompensator,  ///< Σ (p_pump − p_S) Q⁺_in: sections fed below the highest load
  kMeterIn,      ///< Σ (p_S − p_c) Q⁺_in: the load-sensing margin across the spools
  kBackflow,     ///< Σ p_c (Q⁺_in − Q_in): a chamber above its supply pushing back
  kMeterOut,     ///< Σ p_c Q_out: return flow throttled to tank
  kRelief,       ///< Σ p_c Q_rel (anti-cavitation make-up counted negative)
  kCompression,  ///< Σ p_c V_c/β ṗ_c: stored in the oil's compliance
  kArmKinetic,   ///< q̇ᵀ(M q̈ + h) = d/dt kinetic energy of the arm and payload
  kLifting,      ///< −Q_g·q̇: potential energy of the arm and payload
  kArmFriction,  ///< Σ b q̇²
  kSoilByArm,    ///< −τ_ext·q̇: the arm cutting and lifting through the material
  kEndStops,     ///< −F_end ṡ: cylinders' end-of-stroke cushions
  kCount
};

inline constexpr int kEnergyTermCount = static_cast<int>(EnergyTerm::kCount);

/// A short name ("tyre slip", "meter-out throttling", …) for tables and legends.
const char* EnergyTermName(EnergyTerm term);
/// True for the terms of the travel drive, false for the hydraulics'.
bool IsTravelTerm(EnergyTerm term);
/// True for the terms that make up the useful cylinder work (arm kinetic … end stops).
bool IsCylinderWorkTerm(EnergyTerm term);

/// Energies per term [J] (or powers [W]: the same layout).
struct EnergyAudit {
  std::array<double, kEnergyTermCount> terms{};
  double& operator[](EnergyTerm t) { return terms[static_cast<int>(t)]; }
  double operator[](EnergyTerm t) const { return terms[static_cast<int>(t)]; }
  double travel() const;     ///< sum of the travel terms
  double hydraulic() const;  ///< sum of the hydraulic terms
  double total() const { return travel() + hydraulic(); }
  double cylinder_work() const;  ///< the useful cylinder work (sum of its terms)
  double soil() const;           ///< cutting and lifting through the material, drive and arm
  EnergyAudit& operator+=(const EnergyAudit& o);
  EnergyAudit operator-(const EnergyAudit& o) const;
};

/// The energy audit at the end of one control tick: cumulative since the plant started.
struct EnergyAuditSample {
  double time = 0;  ///< [s]
  std::string phase;
  EnergyAudit cumulative;  ///< [J]
};

}  // namespace autoshovel::plant
