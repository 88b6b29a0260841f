// Shoveling strategy selection, wheel-loader seed §6.2, Algorithm 3, as written:
//
//   3: while V1 > 0, Crowding do
//   7:   if V1 + V2 ≥ V_t then
//   8:     if γ ∈ 𝒴 then Scooping using the "Stairway" strategy
//  11:     else Scooping using the "Just in & out" strategy
//  13:   else if V1 > 0 and v ≈ 0 then
//  14:     Scooping using the "Stairway" strategy
//
// γ ∈ 𝒴 is model::Material::difficult (the material file's `difficulty: difficult`); v ≈ 0 is the
// stop detector (stop_detector.h). Algorithm 3 uses neither the pile's height nor its shape: a low
// pile that cannot fill the bucket shows up as the stop branch (line 13) once the machine stalls.
#pragma once

namespace autoshovel::control {

enum class ScoopDecision {
  kKeepCrowding,  ///< no scoop yet (V1 = 0, or short of V_t and moving)
  kJustInOut,
  kStairway,
};
const char* ToString(ScoopDecision decision);

struct SelectionInputs {
  double v1 = 0;             ///< current shoveled volume, Eq. (19) [m³]
  double v2 = 0;             ///< future volume V21 + V22 [m³]
  double target_volume = 0;  ///< V_t [m³]
  bool difficult = false;    ///< γ ∈ 𝒴
  bool stopped = false;      ///< v ≈ 0 (StopDetector)
};

/// One pass of Algorithm 3's loop body (lines 7–15); kKeepCrowding also when V1 ≤ 0 (line 3)
/// or a volume is NaN.
ScoopDecision SelectStrategy(const SelectionInputs& inputs);

}  // namespace autoshovel::control
