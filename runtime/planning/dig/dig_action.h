// The refined dig planner's atomic action and what a forward model predicts for it (excavator
// seed §4.2, Fig. 13): "rather than searching for a bucket trajectory, the refined planner
// searches through compact task parameters ... a forward model simulates the result of choosing
// an action (in our case the starting location of the bucket)". The starting location is
// (swing, radius, entry_height); depth and drag length complete the one dig the force-based
// controller executes: penetrate to `depth` below the surface, drag toward the machine at that
// depth for `drag_length`, curl and lift out.
//
// Frame: the excavator base frame (origin on the swing axis at ground level, x forward, z up,
// swing ψ counter-clockwise, so +ψ is the operator's left, where the truck stands).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace autoshovel::planning {

struct DigAction {
  double swing = 0;         ///< ψ of the arm plane [rad]
  double radius = 0;        ///< where the tooth tip enters the surface, from the swing axis [m]
  double entry_height = 0;  ///< surface height there, base frame z [m] (the planner fills it)
  double depth = 0;         ///< penetration below the surface [m]
  double drag_length = 0;   ///< drag toward the machine at that depth before curling [m]
};

struct DigPrediction {    ///< what a forward model says executing the action gives
  bool executed = false;  ///< false: could not be executed (reason in `why`)
  std::string why;
  double volume = 0;                      ///< material in the bucket at the end [m^3]
  double energy = 0;                      ///< hydraulic energy [J]
  double duration = 0;                    ///< [s]
  std::vector<Eigen::Vector3d> tip_path;  ///< bucket tooth tip, base frame, over the dig [m]
};

/// The seed's forward model (Fig. 13). The app layer plugs in the plant (or a learned or
/// analytic model); the refined planner only calls Predict, at most its evaluation budget times
/// per plan. An exception thrown by Predict propagates out of the planner.
class DigForwardModel {
 public:
  virtual ~DigForwardModel() = default;
  virtual DigPrediction Predict(const DigAction& action) = 0;
};

/// True when every field of `action` is finite.
bool IsFinite(const DigAction& action);

/// Whether a prediction can be scored: executed, volume, energy and duration finite and not
/// negative, every tip-path point finite. Otherwise false, with the reason in `why` (NaN from a
/// forward model is never scored, so it can never be selected).
bool IsUsable(const DigPrediction& prediction, std::string& why);

}  // namespace autoshovel::planning
