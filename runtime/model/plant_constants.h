// Regularisation constants of the hydraulic–mechanical plant model. The code generator embeds
// them in the emitted right-hand sides and the interpreted reference model uses them directly, so
// both evaluate the same equations (see interpreted_model.h for the equations themselves).
#pragma once

namespace autoshovel::model::plant {

inline constexpr double kGravity = 9.80665;  ///< [m/s²]
/// Spool position at which the valve's underlap leakage equals a fully open path [-]: the
/// smooth split pos(x) = (x + sqrt(x² + ε²))/2 keeps the Jacobian finite at x = 0.
inline constexpr double kSpoolUnderlap = 0.01;
/// Pressure drop below which orifice flow turns laminar [Pa]: Q ∝ Δp/(Δp² + Δp_t²)^¼ is
/// sign(Δp)·sqrt|Δp| above it and linear below (a two-regime orifice in the spirit of Ellman &
/// Piché 1999, smooth so that CVODE's Newton iteration sees a finite Jacobian).
inline constexpr double kOrificeTransitionPressure = 2e5;
/// Pressure width of the relief and anti-cavitation valves' opening [Pa].
inline constexpr double kReliefPressureWidth = 1e5;
/// Overpressure at which a relief valve passes the valve's rated flow [Pa].
inline constexpr double kReliefFullFlowOverpressure = 1e6;
/// Cylinder end-of-stroke stop stiffness per cylinder [N/m] and its smoothing length [m].
inline constexpr double kEndStopStiffness = 2e8;
inline constexpr double kEndStopSmoothing = 1e-3;

}  // namespace autoshovel::model::plant
