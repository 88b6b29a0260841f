// Regularisation constants of the hydraulic–mechanical plant model. The code generator embeds
// them in the emitted right-hand sides and the interpreted reference model uses them directly, so
// both evaluate the same equations (see interpreted_model.h for the equations themselves).
#pragma once

namespace autoshovel::model::plant {

inline constexpr double kGravity = 9.80665;  ///< [m/s²]
/// Regularisation width of the spool opening [-]: the smooth split pos(x) = (x + sqrt(x² + ε²))/2
/// keeps the Jacobian finite at x = 0 and leaves a centred spool an opening of ε/2 per path,
/// an internal leakage of 0.05 % of rated flow per path (a boom valve: about 0.5 L/min at
/// holding pressure, the order of a real spool valve's leakage).
inline constexpr double kSpoolUnderlap = 1e-3;
/// Pressure drop below which orifice flow turns laminar [Pa]: Q ∝ Δp/(Δp² + Δp_t²)^¼ is
/// sign(Δp)·sqrt|Δp| above it and linear below (a two-regime orifice in the spirit of Ellman &
/// Piché 1999, smooth so that CVODE's Newton iteration sees a finite Jacobian).
inline constexpr double kOrificeTransitionPressure = 2e5;
/// Smoothing width of each valve section's load check valve [Pa]: a spool's path from the supply
/// passes flow only while the supply is above the chamber it feeds, f(p_S − p_c) with the drop
/// taken through a smooth positive part (x + sqrt(x² + w²))/2. Without it a chamber pushed
/// above its supply (soil on the bucket, a pump at its limit) drove oil back through the spool
/// into the supply line, and the arm gave way; real sections hold it with a check valve. At the
/// 15 bar margin the smoothing changes the flow by 1e-5.
inline constexpr double kCheckValveWidth = 1e4;
/// Pressure width of the relief and anti-cavitation valves' opening [Pa].
inline constexpr double kReliefPressureWidth = 1e5;
/// Overpressure at which a relief valve passes the valve's rated flow [Pa].
inline constexpr double kReliefFullFlowOverpressure = 1e6;
/// Cylinder end-of-stroke stop stiffness per cylinder [N/m] and its smoothing length [m].
inline constexpr double kEndStopStiffness = 2e8;
inline constexpr double kEndStopSmoothing = 1e-3;
/// End-of-stroke cushion damping per cylinder [N·s/m], acting only inside the stop (smooth
/// step of the same width): about critical for a few tonnes reflected to the cylinder, so that
/// an arm held against its stop does not ring (a real cylinder's cushion does the same).
inline constexpr double kEndStopDamping = 2e6;

}  // namespace autoshovel::model::plant
