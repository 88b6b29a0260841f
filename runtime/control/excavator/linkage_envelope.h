// Points on the underside of the excavator's linkage (excavator seed §4.5, Fig. 15), placed by
// the forward kinematics and a simple straight-edged model of each link's shape. Each link is a
// polygon in its own frame (origin at its pivot, x along the link, z towards the link's upper
// side), extruded across the arm plane by its width:
//   boom    a bar around the foot-to-tip chord, 0.3 m past either pin, 0.4 m either side of it;
//           the real boom's belly bends up from the chord, so the bar's lower edge lies at or
//           below the real underside (conservative for the obstacle test);
//   stick   a bar from 1.0 m behind the boom-tip pin (the stick's tail carries the stick
//           cylinder's rod pin, 0.8 m behind, in the 25 t description) to 0.15 m past the bucket
//           pin, 0.35 m either side of the chord;
//   bucket  the convex hull of the description's bucket profile, the bucket's own width.
// Boom and stick widths (0.7 m, 0.55 m) and depths are estimates for a 25 t machine.
//
// For a joint state each polygon is placed in the arm plane (ExcavatorKinematics), its lower
// convex chain (the part seen from below: the leftmost to the rightmost vertex along the bottom)
// is sampled at no more than `max_spacing`, and every sample is repeated across the width at no
// more than `max_spacing` and turned by the swing into 3-D. Against a 2.5-D elevation map, where
// a cell is solid from below up to its height, the lower chain is the whole test: if any part of
// a convex link is lower than a cell inside the cell's column, so is its lower chain.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <string_view>
#include <vector>

#include "runtime/control/excavator/excavator_kinematics.h"
#include "runtime/model/description.h"

namespace autoshovel::control {

enum class LinkageLink { kBoom = 0, kStick = 1, kBucket = 2 };
std::string_view LinkName(LinkageLink link);

struct LinkShape {
  std::vector<Eigen::Vector2d> outline;  ///< polygon in the link frame [m] (its hull is used)
  double width = 0;                      ///< across the arm plane, centred on it [m]
};

struct EnvelopeConfig {
  std::array<LinkShape, 3> shapes;  ///< boom, stick, bucket
  double max_spacing = 0.25;        ///< between neighbouring points, along and across [m]
};

/// The shapes above for `machine` (link lengths, bucket profile and width from it). Throws
/// std::invalid_argument when the description lacks them.
EnvelopeConfig DefaultEnvelopeConfig(const model::MachineDescription& machine);

/// Throws std::invalid_argument naming the offending field.
void Validate(const EnvelopeConfig& config);

struct EnvelopePoint {
  Eigen::Vector3d p;  ///< in the frame asked for (base or world) [m]
  LinkageLink link;
};

class LinkageEnvelope {
 public:
  /// Copies both. Throws std::invalid_argument on an invalid config.
  LinkageEnvelope(const ExcavatorKinematics& kinematics, const EnvelopeConfig& config);

  /// Underside points for joint positions q, transformed by T_out_base (identity: base frame).
  /// `points` is cleared first; reusing it avoids allocation in the prediction loops.
  void Underside(const JointVector& q, const Eigen::Isometry3d& T_out_base,
                 std::vector<EnvelopePoint>& points) const;
  std::vector<EnvelopePoint> Underside(
      const JointVector& q,
      const Eigen::Isometry3d& T_out_base = Eigen::Isometry3d::Identity()) const;

  /// Appends the underside points of one link, placed by `pins`, at no more than `spacing`
  /// apart (Underside uses the config's spacing for all three links).
  void AppendLinkUnderside(const ArmPlanePins& pins, LinkageLink link, double spacing,
                           const Eigen::Isometry3d& T_out_base,
                           std::vector<EnvelopePoint>& points) const;

  /// The lower chain of link `link` in the arm plane [r, z] for q (for plots and tests).
  std::vector<Eigen::Vector2d> LowerChain(const JointVector& q, LinkageLink link) const;

  const ExcavatorKinematics& kinematics() const { return kinematics_; }
  const EnvelopeConfig& config() const { return config_; }

 private:
  void LowerChainFromPins(const ArmPlanePins& pins, int link,
                          std::vector<Eigen::Vector2d>& chain) const;

  ExcavatorKinematics kinematics_;
  EnvelopeConfig config_;
};

}  // namespace autoshovel::control
