// Resistance of a granular material to a cutting tool: Reece's fundamental earthmoving equation
//
//   F = w (γ d² N_γ + c d N_c + q d N_q + c_a d N_a)                       (Reece 1964)
//
// (A. R. Reece, "The fundamental equation of earth-moving mechanics", Proc. Inst. Mech. Eng.
// 179(3F), 1964), with the dimensionless factors of a flat blade from the Coulomb wedge
// analysis in J. McKyes, "Soil Cutting and Tillage", Elsevier 1985, §4:
//
//   D      = cos(α + δ) + sin(α + δ) cot(β + φ)
//   N_γ    = (cot α + cot β) / (2 D)
//   N_c    = (1 + cot β cot(β + φ)) / D
//   N_q    = (cot α + cot β) / D
//   N_a    = (1 − cot α cot(β + φ)) / D
//
// w blade width, d cutting depth of the tip below the free surface, γ = ρ g the unit weight,
// c cohesion, q surcharge on the surface, c_a soil–steel adhesion, α the rake angle of the blade
// from the direction of travel, δ the soil–steel friction angle, φ the internal friction angle
// and β the failure-plane angle, the one that minimises the passive resistance (McKyes takes the
// minimising β of N_γ; the others are evaluated at the same β). The resultant acts at δ to the
// blade normal: along the travel direction H = F sin(α + δ), across it V = F cos(α + δ).
#pragma once

#include <vector>

namespace autoshovel::plant {

struct ReeceFactors {
  double n_gamma = 0, n_c = 0, n_q = 0, n_a = 0;
  double failure_angle = 0;  ///< β [rad]
};

/// McKyes' factors for rake angle α, internal friction φ, interface friction δ (all rad).
/// α is clamped to [10°, 90°] (the flat-blade analysis does not hold outside).
ReeceFactors ComputeReeceFactors(double rake_angle, double friction_angle,
                                 double interface_friction_angle);

/// McKyes' factors of one material (φ, δ) tabulated over the rake angle from 10° to 90° every
/// 0.5° and interpolated linearly (within 1e-3 of the direct search, a test checks it): the
/// search behind each entry costs about 10 µs, a lookup a few nanoseconds, and the plant needs
/// one per control tick in contact.
class ReeceTable {
 public:
  ReeceTable(double friction_angle, double interface_friction_angle);
  ReeceFactors At(double rake_angle) const;
  double friction_angle() const { return friction_angle_; }
  double interface_friction_angle() const { return interface_friction_angle_; }

 private:
  double friction_angle_, interface_friction_angle_;
  std::vector<ReeceFactors> entries_;
};

struct CuttingResistance {
  double along = 0;   ///< H: opposing the travel direction [N]
  double across = 0;  ///< V: perpendicular to travel, pressing the blade into the cut [N]
  double total = 0;   ///< F [N]
};

struct CuttingInput {
  double width = 0;            ///< w [m]
  double depth = 0;            ///< d ≥ 0 [m]
  double rake_angle = 0;       ///< α [rad]
  double density = 0;          ///< ρ [kg/m³]
  double cohesion = 0;         ///< c [Pa]
  double adhesion = 0;         ///< c_a [Pa]
  double surcharge = 0;        ///< q [Pa]
  double friction_angle = 0;   ///< φ [rad]
  double interface_angle = 0;  ///< δ [rad]
  /// Factors of this (φ, δ) tabulated; null: searched directly.
  const ReeceTable* table = nullptr;
};

/// Reece's equation with McKyes' factors.
CuttingResistance ComputeCuttingResistance(const CuttingInput& input);

}  // namespace autoshovel::plant
